"""The friction law of ``rd.identify(..., friction="auto")``, chosen by time-block cross-validation.

With the identified rigid-body and rotor parameters fixed, what they leave of the (filtered)
target is friction: ``r = K H(y) - H(Y) p_nf``. Each law is fitted joint by joint on the time
blocks of all recordings but one (:data:`robodyn.identification.estimate.FOLDS` per recording) and
predicts the block left out: the linear law on its filtered columns (viscous, Coulomb +/-,
offset, as the linear fit has them), the Stribeck law as :func:`fit_friction_samples` fits it.
The linear law is kept unless Stribeck's held-out error is lower by more than one standard
error of the paired block differences (the rule of :mod:`robodyn.identification.choices`).
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

#: Relative singular-value cut-off of the linear law's per-joint fit (4 columns).
RCOND = 1e-6
#: Least held-out gain (fraction of the linear law's squared error) for another law to be kept:
#: on pure noise a smooth law can be ahead in every block by a few parts in 10^4.
MIN_GAIN = 0.01
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
    """
    p_nf = without_friction(ident.standard)
    qd = np.vstack([s.qd for s in samples])
    load = np.vstack([y @ p_nf for y in y_full])
    r = np.vstack([s.y for s in samples]) * ident.gains[None, :] - load  # r = K H y - H Y p_nf
    block = np.concatenate([np.arange(s.q.shape[0]) * FOLDS // s.q.shape[0] for s in samples])
    n = qd.shape[1]
    per_block = {law: np.zeros(FOLDS) for law in LAWS}
    for j in range(n):
        first = joint_columns(j, "Fv").start
        cols = np.vstack([y[:, j, first:first + 4] for y in y_full])  # Fv, Fcp, Fcn, Fo columns
        x0, bounds = _start("stribeck", ident.standard[first:first + 4])
        x0 = np.clip(x0, bounds[0] + 1e-12, bounds[1] - 1e-12)
        for k in range(FOLDS):
            train, test = block != k, block == k
            if not test.any() or not train.any():
                continue
            # linear law: least squares on the filtered columns
            # directions below RCOND of the largest left out: a joint that hardly ever turns one
            # way makes its Coulomb columns nearly collinear with the offset in a fold
            c = np.linalg.lstsq(cols[train], r[train, j], rcond=RCOND)[0]
            per_block["linear"][k] += float(np.sum((r[test, j] - cols[test] @ c) ** 2))
            if np.ptp(qd[train, j]) == 0.0:
                pred = np.full(int(test.sum()), float(np.mean(r[train, j])))
            else:
                x = _fit_law("stribeck", x0, bounds, qd[train, j], load[train, j], r[train, j])
                pred = _law("stribeck", x, qd[test, j], load[test, j])
            per_block["stribeck"][k] += float(np.sum((r[test, j] - pred) ** 2))
    total = max(float(np.sum(r**2)), 1e-300)
    scores = {law: float(np.sqrt(e.sum() / total)) for law, e in per_block.items()}
    d = per_block["stribeck"] - per_block["linear"]
    # better by more than one standard error, and by more than MIN_GAIN of the linear error
    chosen = "stribeck" if d.sum() < -max(paired_se(d), MIN_GAIN * per_block["linear"].sum()) else "linear"
    return chosen, scores
