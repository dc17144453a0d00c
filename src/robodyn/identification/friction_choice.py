"""The friction law of ``rd.identify(..., friction="auto")``, chosen by time-block cross-validation.

With the identified rigid-body and rotor parameters fixed, what they leave of the (filtered)
target is friction: ``r = K H(y) - H(Y) p_nf``. Each law is fitted joint by joint on the time
blocks of all recordings but one (:data:`robodyn.identification.estimate.FOLDS` per recording) and
predicts the block left out: the linear law on its filtered columns (viscous, Coulomb +/-,
offset, as the linear fit has them), the Stribeck law as :func:`fit_friction_samples` fits it.
A joint is not scored on a fold whose training blocks hold (almost) none of a direction it
turns in the held-out block (:data:`MIN_SHARE`): there each law would extrapolate a Coulomb level
it was never fitted to, and the comparison would measure that guess, not the laws. The scores
are relative to the residual over the scored samples. The linear law is kept unless Stribeck's
held-out error is lower by more than one standard error of the paired block differences (the
rule of :mod:`robodyn.identification.choices`).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from robodyn.identification.estimate import FOLDS, paired_se
from robodyn.identification.friction import _fit_law, _law, _start, without_friction
from robodyn.identification.preprocess import Samples
from robodyn.symbolic.regressor import joint_columns

__all__ = ["LAWS", "choose_friction_law"]

#: Relative singular-value cut-off of the linear law's per-joint fit on a fold, its 4 columns
#: scaled to unit norm over all blocks: a column with less than about this share of its norm in
#: the training blocks is left out (the Coulomb column of a direction the joint turns only in
#: the held-out block: fitted to the filter's leakage alone, its coefficient would be arbitrary).
RCOND = 1e-2
#: Least held-out gain (fraction of the linear law's squared error) for another law to be kept:
#: on pure noise a smooth law can be ahead in every block by a few parts in 10^4.
MIN_GAIN = 0.01
#: Least share of a Coulomb column's norm in a fold's training blocks for the fold to score the
#: joint: below it the joint turns that way (almost) only in the held-out block, where every law
#: extrapolates a level it was never fitted to (the Kinova runs turn most joints back only in
#: their first fifth).
MIN_SHARE = 0.05
#: The laws compared, the first the plain one.
LAWS = ("linear", "stribeck")


def choose_friction_law(ident: Any, samples: Sequence[Samples], y_full: Sequence[np.ndarray]
                        ) -> tuple[str, dict[str, float]]:
    """The chosen law and each law's relative held-out error over the blocks.

    Parameters
    ----------
    ident : Identification
        The linear identification (its rigid-body and rotor parameters are kept).
    samples : sequence of Samples
        Processed, decimated samples with the filtered target ``y`` (N_k, n).
    y_full : sequence of numpy.ndarray, shape (N_k, n, 15 n)
        The fit's (filtered) regressor rows of the same samples.

    Returns
    -------
    (str, dict of str to float)
        The law, and each law's held-out error relative to the residual over the scored
        samples (NaN where no joint could be scored on any fold; the linear law is then kept).
    """
    p_nf = without_friction(ident.standard)
    qd = np.vstack([s.qd for s in samples])
    load = np.vstack([y @ p_nf for y in y_full])
    r = np.vstack([s.y for s in samples]) * ident.gains[None, :] - load  # r = K H y - H Y p_nf
    block = np.concatenate([np.arange(s.q.shape[0]) * FOLDS // s.q.shape[0] for s in samples])
    n = qd.shape[1]
    per_block = {law: np.zeros(FOLDS) for law in LAWS}
    energy = 0.0  # sum of r^2 over the scored held-out samples
    for j in range(n):
        first = joint_columns(j, "Fv").start
        cols = np.vstack([y[:, j, first:first + 4] for y in y_full])  # Fv, Fcp, Fcn, Fo columns
        norms = np.linalg.norm(cols, axis=0)
        scale = np.where(norms > 0, norms, 1.0)
        x0, bounds = _start("stribeck", ident.standard[first:first + 4])
        x0 = np.clip(x0, bounds[0] + 1e-12, bounds[1] - 1e-12)
        for k in range(FOLDS):
            train, test = block != k, block == k
            if not test.any() or not train.any():
                continue
            seen = np.linalg.norm(cols[train, 1:3], axis=0)
            if np.any((norms[1:3] > 0) & (seen < MIN_SHARE * norms[1:3])):
                continue  # a direction turned (almost) only in the held-out block: no law is tested
            # linear law: least squares on the filtered columns, scaled by their norms over all
            # blocks; directions below RCOND of the largest left out (module constant)
            c = np.linalg.lstsq(cols[train] / scale, r[train, j], rcond=RCOND)[0] / scale
            per_block["linear"][k] += float(np.sum((r[test, j] - cols[test] @ c) ** 2))
            energy += float(np.sum(r[test, j] ** 2))
            if np.ptp(qd[train, j]) == 0.0:
                pred = np.full(int(test.sum()), float(np.mean(r[train, j])))
            else:
                x = _fit_law("stribeck", x0, bounds, qd[train, j], load[train, j], r[train, j])
                pred = _law("stribeck", x, qd[test, j], load[test, j])
            per_block["stribeck"][k] += float(np.sum((r[test, j] - pred) ** 2))
    scores = {law: float(np.sqrt(e.sum() / energy)) if energy > 0 else float("nan")
              for law, e in per_block.items()}
    d = per_block["stribeck"] - per_block["linear"]
    # better by more than one standard error, and by more than MIN_GAIN of the linear error
    chosen = "stribeck" if d.sum() < -max(paired_se(d), MIN_GAIN * per_block["linear"].sum()) else "linear"
    return chosen, scores
