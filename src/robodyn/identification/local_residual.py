"""A local correction of the prediction: what the model repeatably misses where the data were.

A rigid-body model with its friction and drive terms leaves a residual that is partly noise and
partly systematic: effects the model cannot express (cable forces, a joint's position-dependent
friction, sensor cross-talk) that repeat wherever the arm passes through the same state again.
A recording that repeats states of the identification data (a periodic excitation run over
several periods and validated on a later one, a task repeated) is predicted better with that
part added; a recording elsewhere in the state space should get the model alone, since the
model's physics, not an interpolation of residuals, is what carries a prediction to new motion.

So the correction is a kernel ridge regression of the residual ``r = y - p`` (the measured raw
target less :meth:`Identification.predict <robodyn.identification.result.Identification.predict>`
on the identification recordings) on the processed states ``x = (q, qd, qdd)`` (each column
standardised by the identification data's mean and standard deviation), with a Gaussian kernel
of length ``ell`` (in standard deviations) and a zero prior mean: far from the data (every
kernel value small) it vanishes, and the prediction is the model's. The semi-parametric model of
Nguyen-Tuong and Peters, "Using model knowledge for learning inverse dynamics" (ICRA 2010), with
the physical model as the mean. For cost it is a Nystrom approximation on ``m`` states evenly
spaced in time (:data:`INDUCING`), fitted on at most :data:`MAX_ROWS` rows in all, evenly spaced::

    r(x) = k(x, U) a,   a = (K_nm^T K_nm + rho N K_mm)^-1 K_nm^T R

``ell`` and ``rho`` come from a grid (:data:`LENGTH_GRID`, :data:`RIDGE_GRID`), chosen by
time-block cross-validation on the identification recordings (:data:`FOLDS
<robodyn.identification.estimate.FOLDS>` contiguous blocks per recording, each predicted by a fit
on the others); ``local="auto"`` (the default of :func:`robodyn.identify`) keeps the correction
only when it predicts the held-out blocks better than none by more than one standard error of
the paired block differences (the rule of :mod:`robodyn.identification.choices`). Lengths are at
most 2 standard deviations: a longer kernel reaches states the data never visited, which is the
model's business (on the KUKA LWR4+ runs in ``../shared``, fitted on run 1 and predicting run 3,
another trajectory, a length of 4 costs 0.082 against 0.048 without a correction).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from robodyn.identification.estimate import FOLDS, paired_se
from robodyn.identification.preprocess import target_signal

__all__ = ["INDUCING", "LENGTH_GRID", "MAX_ROWS", "RIDGE_GRID", "LocalResidualFit",
           "fit_local_residual", "local_features", "model_residuals", "with_local_residual"]

#: Kernel lengths tried, in standard deviations of the identification data's states.
LENGTH_GRID = (1.0, 1.5, 2.0)
#: Ridge weights tried, ``rho`` (per sample).
RIDGE_GRID = (1e-5, 1e-4, 1e-3)
#: Nystrom states (at most).
INDUCING = 400
#: Identification rows the correction is fitted on, all recordings together (at most; each
#: recording's share evenly spaced).
MAX_ROWS = 10000
#: Rows of the kernel evaluated at a time (bounds the memory of a long prediction).
CHUNK = 8192


def local_features(q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> np.ndarray:
    """The states the correction is a function of, ``[q, qd, qdd]``, (N, 3 n)."""
    return np.hstack([np.asarray(q, float), np.asarray(qd, float), np.asarray(qdd, float)])


def _kernel(a: np.ndarray, b: np.ndarray, ell: float) -> np.ndarray:
    """Gaussian kernel ``exp(-|a_i - b_j|^2 / (2 ell^2))`` of standardised states, (N_a, N_b)."""
    k = a @ b.T  # in place from here: the (N_a, N_b) array is the only large one
    k *= -2.0
    k += (a * a).sum(axis=1)[:, None]
    k += (b * b).sum(axis=1)[None, :]
    np.maximum(k, 0.0, out=k)  # |a - b|^2, rounding below 0 clipped
    k *= -0.5 / (ell * ell)
    return np.exp(k, out=k)


@dataclass(frozen=True, eq=False)
class LocalResidualFit:
    """The fitted correction (module docstring).

    Attributes
    ----------
    mean, scale : numpy.ndarray, shape (3 n,)
        Standardisation of the states (identification data's mean and standard deviation; a
        column that did not vary has scale 1e-12, so any motion of it is far from the data).
    inducing : numpy.ndarray, shape (m, 3 n)
        Nystrom states, standardised.
    weights : numpy.ndarray, shape (m, n)
        ``a``: the kernel weights, in the target's unit.
    length : float
        Kernel length, standard deviations.
    ridge : float
        ``rho``.
    """

    mean: np.ndarray
    scale: np.ndarray
    inducing: np.ndarray
    weights: np.ndarray
    length: float
    ridge: float

    def correction(self, x: np.ndarray) -> np.ndarray:
        """The correction at states ``x`` (N, 3 n) (:func:`local_features`), (N, n), in the
        target's unit."""
        z = (np.asarray(x, float) - self.mean) / self.scale
        out = np.empty((len(z), self.weights.shape[1]))
        for a in range(0, len(z), CHUNK):
            out[a:a + CHUNK] = _kernel(z[a:a + CHUNK], self.inducing, self.length) @ self.weights
        return out


def _rows(count: int, total: int) -> np.ndarray:
    """Indices of a recording of ``count`` rows, evenly spaced: all of them when the recordings
    hold ``total <= MAX_ROWS`` rows together, else its share of MAX_ROWS."""
    if total <= MAX_ROWS:
        return np.arange(count)
    share = max(1, int(round(MAX_ROWS * count / total)))
    return np.unique(np.linspace(0, count - 1, share).round().astype(int))


def fit_local_residual(features: Sequence[np.ndarray], residuals: Sequence[np.ndarray],
                       keep: bool | str) -> tuple[LocalResidualFit | None, dict[str, float]]:
    """Choose and fit the correction on the identification recordings (module docstring).

    Parameters
    ----------
    features : sequence of numpy.ndarray, each (N_k, 3 n)
        Each recording's processed states (:func:`local_features`).
    residuals : sequence of numpy.ndarray, each (N_k, n)
        Each recording's measured target less the prediction, in the target's unit (a missing
        value, NaN, counts as 0: no correction learnt from it).
    keep : True or "auto"
        The best setting of the grid, or only one better than none by one standard error.

    Returns
    -------
    (LocalResidualFit or None, dict of str to float)
        The correction (None: not kept) and the held-out error relative to none's: ``"none"``
        (1) and ``"local"`` (the best setting's), over the held-out time blocks of all joints.
    """
    xs, rs, bs = [], [], []
    total = sum(len(x) for x in features)
    for k, (x, r) in enumerate(zip(features, residuals, strict=True)):
        idx = _rows(len(x), total)
        ok = np.all(np.isfinite(x[idx]), axis=1)
        xs.append(x[idx][ok])
        rs.append(np.nan_to_num(np.asarray(r, float)[idx][ok], nan=0.0, posinf=0.0, neginf=0.0))
        bs.append((idx[ok] * FOLDS // max(len(x), 1)) + FOLDS * k)  # contiguous blocks per recording
    x, r, blocks = np.vstack(xs), np.vstack(rs), np.concatenate(bs)
    if len(x) < 2 * FOLDS:
        return None, {"none": 1.0}
    _, blocks = np.unique(blocks, return_inverse=True)
    mean = x.mean(axis=0)
    scale = x.std(axis=0)
    scale = np.where(scale > 0.0, scale, 1e-12)
    z = (x - mean) / scale
    u = z[np.linspace(0, len(z) - 1, min(INDUCING, len(z))).round().astype(int)]
    none = np.bincount(blocks, weights=(r * r).sum(axis=1))  # held-out error without a correction
    best = (np.inf, None, None)
    for ell in LENGTH_GRID:
        phi, _ = _whitened(z, u, ell)
        err = _cv_errors(phi, r, blocks)  # (ridges, K)
        for i, rho in enumerate(RIDGE_GRID):
            if err[i].sum() < best[0]:
                best = (float(err[i].sum()), (ell, rho), err[i])
    least, setting, err = best
    scores = {"none": 1.0, "local": float(np.sqrt(least / max(none.sum(), 1e-300)))}
    d = err - none
    if setting is None or (keep == "auto" and not d.sum() < -paired_se(d)):
        return None, scores
    ell, rho = setting
    phi, back = _whitened(z, u, ell)
    w, v = np.linalg.eigh(phi.T @ phi)
    beta = v @ ((v.T @ (phi.T @ r)) / (np.maximum(w, 0.0) + rho * len(z))[:, None])
    return LocalResidualFit(mean, scale, u, back @ beta, float(ell), float(rho)), scores


def _whitened(z: np.ndarray, u: np.ndarray, ell: float) -> tuple[np.ndarray, np.ndarray]:
    """Nystrom features ``phi = K_nm B`` (N, m') with ``B = Q L^-1/2`` from ``K_mm = Q L Q^T``
    (eigenvalues below 1e-10 of the largest dropped), and ``B`` (m, m'): the ridge problem in
    ``phi`` is the module's in ``a = B beta``."""
    lam, q = np.linalg.eigh(_kernel(u, u, ell))
    keep = lam > 1e-10 * float(lam[-1])
    back = q[:, keep] / np.sqrt(lam[keep])[None, :]
    return _kernel(z, u, ell) @ back, back


def _cv_errors(phi: np.ndarray, r: np.ndarray, blocks: np.ndarray) -> np.ndarray:
    """Held-out squared error of each block for each ridge weight, (len(RIDGE_GRID), K): ridge
    regression of ``r`` on ``phi`` fitted on the other blocks (weight ``rho`` x their rows)."""
    count = int(blocks.max()) + 1
    gram, rhs = phi.T @ phi, phi.T @ r
    out = np.zeros((len(RIDGE_GRID), count))
    for b in range(count):
        rows_b = blocks == b
        pb, rb = phi[rows_b], r[rows_b]
        w, v = np.linalg.eigh(gram - pb.T @ pb)  # the other blocks' normal equations
        c = v.T @ (rhs - pb.T @ rb)
        pv = pb @ v
        others = len(phi) - int(rows_b.sum())
        for i, rho in enumerate(RIDGE_GRID):
            beta = c / (np.maximum(w, 0.0) + rho * others)[:, None]
            out[i, b] = float(((rb - pv @ beta) ** 2).sum())
    return out


def model_residuals(ident: Any, recordings: Sequence[Any], payloads: Sequence[Any] | None,
                    target: str) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """Each recording's states (:func:`local_features`, (N_k, 3 n)) and the raw target less the
    prediction without a local correction ((N_k, n), NaN where the target is), as
    :meth:`Identification.predict` processes it."""
    pays = list(payloads) if payloads is not None else [None] * len(recordings)
    features, residuals = [], []
    for rec, pay in zip(recordings, pays, strict=True):
        s = ident.prediction_samples(rec)  # the states predict() processes, processed once
        features.append(local_features(s.q, s.qd, s.qdd))
        residuals.append(np.asarray(target_signal(rec, target), float)
                         - ident._model_prediction(rec, s, pay))
    return features, residuals


def with_local_residual(ident: Any, recordings: Sequence[Any], payloads: Sequence[Any] | None,
                        target: str, option: bool | str,
                        residuals: tuple[list[np.ndarray], list[np.ndarray]] | None = None) -> Any:
    """``ident`` with the correction of ``option`` (False, True or "auto") fitted and recorded.

    Parameters
    ----------
    ident : Identification
        Every other term fitted (its :meth:`predict` is what the correction adds to).
    recordings : sequence of Recording
        The identification recordings, raw.
    payloads : sequence of Payload or None, optional
    target : {"tau", "current"}
    option : bool or "auto"
    residuals : (list, list), optional
        :func:`model_residuals` of these arguments, when the caller has them already.
    """
    if option is False:
        return ident
    features, res = residuals or model_residuals(ident, recordings, payloads, target)
    fit, scores = fit_local_residual(features, res, option)
    setting = () if fit is None else ((fit.length, fit.ridge),)
    choices = (replace(ident.choices, local=fit is not None, local_scores=tuple(scores.items()),
                       local_setting=setting) if ident.choices is not None else None)
    return replace(ident, local_fit=fit, choices=choices)
