"""Drive resonance: the part of the measured effort that a lightly damped mode adds to the model's.

A rigid-body model predicts the effort that the measured motion needs. A real drive is not rigid:
joint and gear elasticity and the current or torque loop form a lightly damped mode, and near it
the measured effort is the model's amplified (on the Kinova Gen3 runs in ``../shared``, 5-10 Hz:
about three times the model's, repeating from run to run with correlation 0.8-0.9, per
``benchmarks/bench_identification_bands.py``). Each joint ``j`` gets one such mode, a causal
second-order response of unit static gain::

    H_j(s) = w_j^2 / (s^2 + 2 zeta_j w_j s + w_j^2),    w_j = 2 pi f_j

and the prediction becomes ``p_j + b_j (H_j p_j - p_j)``: the identified model's effort ``p_j``,
plus ``b_j >= 0`` times what the mode adds to it (zero at rest and at low frequency, so the
rigid-body parameters keep their meaning). ``p`` is evaluated on states low-passed at the widest
prediction band of :mod:`robodyn.identification.bandwidth` (``min(4 f_c, 0.2 x rate)``), since the
mode lies above the fit's cut-off ``f_c``. ``H`` is discretised by the bilinear transform at the
median sampling step, on a uniform grid (irregular stamps are interpolated onto it and back).

The frequency and damping of each joint come from a grid (:data:`F0_GRID`, :data:`ZETA_GRID`,
frequencies kept below 0.4 x the slowest recording's Nyquist frequency), ``b_j`` by least squares
on the model's residual (at least 0: a negative share would remove the model's own content near
the mode, which no mode does); both are chosen by time-block cross-validation on the identification
recordings (:data:`~robodyn.identification.estimate.FOLDS` contiguous blocks per recording, each
predicted by a fit on the others). ``resonance="auto"`` (the default of :func:`robodyn.identify`)
keeps a joint's mode only when it predicts the held-out blocks of that joint's target better than
the plain prediction and better than the model at the band without a mode, each by more than one
standard error of the paired block differences (the rule of
:mod:`robodyn.identification.choices`); ``True`` keeps every joint's best mode. The result's
``resonance_fit`` holds the modes; ``ident.choices.resonance`` and ``resonance_scores`` record the
choice. The written description does not carry them.

What it changes in the figures: the prediction now holds content above the 2.5 Hz reference
filter of every "against filtered" figure (:mod:`robodyn.validation.heldout`), so where a mode is
kept the error against the raw target falls and the one against the filtered target rises (the
quality table of ``docs/identification.md`` gives both).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import scipy.signal as ss

from robodyn.identification.bandwidth import prediction_candidates
from robodyn.identification.estimate import FOLDS, paired_se
from robodyn.identification.preprocess import preprocess, slowest_rate, target_signal
from robodyn.identification.thermal import temperatures

__all__ = ["F0_GRID", "ZETA_GRID", "ResonanceFit", "fit_resonance", "mode_response",
           "with_resonance"]

#: Natural frequencies tried, Hz.
F0_GRID = (3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 10.0, 12.0, 15.0)
#: Damping ratios tried.
ZETA_GRID = (0.1, 0.2, 0.35, 0.5)


def mode_response(t: np.ndarray, x: np.ndarray, f0: float, zeta: float) -> np.ndarray:
    """``H x`` for the module's second-order mode, causal, unit static gain.

    Parameters
    ----------
    t : numpy.ndarray, shape (N,)
        Sample times, s (increasing; may be irregular).
    x : numpy.ndarray, shape (N, k)
        Signals.
    f0 : float
        Natural frequency, Hz.
    zeta : float
        Damping ratio.

    Returns
    -------
    numpy.ndarray, shape (N, k)
    """
    t = np.asarray(t, dtype=float)
    x = np.asarray(x, dtype=float)
    steps = np.diff(t)
    dt = float(np.median(steps))
    regular = bool(np.all(np.abs(steps - dt) <= 1e-6 * dt))
    tu = t if regular else t[0] + dt * np.arange(int(round((t[-1] - t[0]) / dt)) + 1)
    uniform = x if regular else np.column_stack([np.interp(tu, t, x[:, k]) for k in range(x.shape[1])])
    w = 2.0 * np.pi * f0
    # H(s) = w^2 / (s^2 + 2 zeta w s + w^2), bilinear at the median step, started at rest on x[0]
    b, a = ss.bilinear([w * w], [1.0, 2.0 * zeta * w, w * w], fs=1.0 / dt)
    zi = ss.lfilter_zi(b, a)[:, None] * uniform[0][None, :]
    out, _ = ss.lfilter(b, a, uniform, axis=0, zi=zi)
    return out if regular else np.column_stack([np.interp(t, tu, out[:, k]) for k in range(x.shape[1])])


@dataclass(frozen=True, eq=False)
class ResonanceFit:
    """One mode per joint (module docstring); a joint without one has ``gain`` 0.

    Attributes
    ----------
    f0 : numpy.ndarray, shape (n,)
        Natural frequency, Hz (NaN: no mode).
    zeta : numpy.ndarray, shape (n,)
        Damping ratio (NaN: no mode).
    gain : numpy.ndarray, shape (n,)
        ``b_j``: the share of the mode's addition in the measured effort.
    band : float
        Cut-off of the states the model's effort is evaluated on, Hz.
    """

    f0: np.ndarray
    zeta: np.ndarray
    gain: np.ndarray
    band: float

    @property
    def kept(self) -> np.ndarray:
        """Joints with a mode, (n,) bool."""
        return self.gain != 0.0

    def combine(self, t: np.ndarray, wide: np.ndarray, plain: np.ndarray) -> np.ndarray:
        """The prediction (N, n): ``p_j + b_j (H_j p_j - p_j)`` with ``p`` the model's effort
        at the band (``wide``) on a joint with a mode, ``plain`` (the model at the prediction
        cut-off) on the others; ``t`` (N,) s."""
        out = np.array(plain, dtype=float)
        for j in np.flatnonzero(self.kept):
            col = wide[:, j:j + 1]
            out[:, j] = (col + self.gain[j] * (mode_response(t, col, self.f0[j], self.zeta[j]) - col))[:, 0]
        return out


def _grid(rate: float) -> list[tuple[float, float]]:
    """(f0, zeta) pairs, frequencies below 0.4 x the Nyquist frequency of ``rate``."""
    return [(f, z) for f in F0_GRID if f < 0.2 * rate for z in ZETA_GRID]


def fit_resonance(times: Sequence[np.ndarray], efforts: Sequence[np.ndarray],
                  targets: Sequence[np.ndarray], plain: Sequence[np.ndarray], band: float,
                  keep: bool | str) -> tuple[ResonanceFit | None, dict[str, float]]:
    """Choose and fit each joint's mode on the identification recordings (module docstring).

    Parameters
    ----------
    times : sequence of numpy.ndarray, each (N_k,)
        Sample times of each recording, s.
    efforts : sequence of numpy.ndarray, each (N_k, n)
        The identified model's effort at those samples (states low-passed at ``band``).
    targets : sequence of numpy.ndarray, each (N_k, n)
        The measured (raw) target, same unit.
    plain : sequence of numpy.ndarray, each (N_k, n)
        The prediction without modes (the model at the prediction cut-off): what a mode must
        beat.
    band : float
        Hz, stored in the result.
    keep : True or "auto"
        Every joint's best mode, or only those better than none by one standard error.

    Returns
    -------
    (ResonanceFit or None, dict of str to float)
        The modes (None: no joint kept), and the held-out error of the target relative to that
        of the plain prediction: 1 without modes (``"none"``) and with the modes kept
        (``"resonance"``), over the held-out time blocks of all joints.
    """
    rate = min(1.0 / float(np.median(np.diff(t))) for t in times)
    grid = _grid(rate)
    n = efforts[0].shape[1]
    blocks = [np.arange(len(t)) * FOLDS // max(len(t), 1) for t in times]
    resid = [np.asarray(y, float) - np.asarray(p, float) for y, p in zip(targets, efforts, strict=True)]
    # without modes: the plain prediction's squared error per block and joint (K, n)
    none = np.vstack([_block_sums((y - p) ** 2, b) for y, p, b in zip(targets, plain, blocks, strict=True)])
    best_err, best = np.full(none.shape, np.inf), [None] * n
    # the best mode's addition per recording and joint, kept as it is found (not recomputed)
    best_add = [np.zeros_like(p, dtype=float) for p in efforts]
    for f0, zeta in grid:
        adds = [mode_response(t, p, f0, zeta) - p for t, p in zip(times, efforts, strict=True)]
        err = _cv_errors(adds, resid, blocks)  # (K, n)
        for j in range(n):
            if err[:, j].sum() < best_err[:, j].sum():
                best_err[:, j], best[j] = err[:, j], (f0, zeta)
                for keep_add, a in zip(best_add, adds, strict=True):
                    keep_add[:, j] = a[:, j]
    # the model at the band alone, no mode: a mode must beat it as well, so that what is kept
    # is a mode, not only the wider band (that is the prediction cut-off's choice)
    wide = np.vstack([_block_sums(r * r, b) for r, b in zip(resid, blocks, strict=True)])
    f0s, zetas, gains = np.full(n, np.nan), np.full(n, np.nan), np.zeros(n)
    for j in range(n):
        # paired block differences against the plain prediction and against the band alone
        d, dw = best_err[:, j] - none[:, j], best_err[:, j] - wide[:, j]
        if best[j] is None or (keep == "auto" and not (d.sum() < -paired_se(d)
                                                       and dw.sum() < -paired_se(dw))):
            best_err[:, j] = none[:, j]
            continue
        f0s[j], zetas[j] = best[j]
        a = np.concatenate([x[:, j] for x in best_add])
        r = np.concatenate([x[:, j] for x in resid])
        gains[j] = max(float(a @ r / max(float(a @ a), 1e-300)), 0.0)  # least squares b_j >= 0
        if gains[j] == 0.0:
            f0s[j] = zetas[j] = np.nan
            best_err[:, j] = none[:, j]
    scores = {"none": 1.0, "resonance": float(np.sqrt(best_err.sum() / max(none.sum(), 1e-300)))}
    if not np.any(gains != 0.0):
        return None, scores
    return ResonanceFit(f0s, zetas, gains, float(band)), scores


def _block_sums(x: np.ndarray, blocks: np.ndarray) -> np.ndarray:
    """Column sums of ``x`` (N, n) over each of the FOLDS contiguous blocks, (FOLDS, n)."""
    starts = np.searchsorted(blocks, np.arange(FOLDS))
    out = np.add.reduceat(x, np.minimum(starts, len(x) - 1), axis=0)
    out[np.bincount(blocks, minlength=FOLDS) == 0] = 0.0  # an empty block (a very short run)
    return out


def _cv_errors(adds: Sequence[np.ndarray], resid: Sequence[np.ndarray],
               blocks: Sequence[np.ndarray]) -> np.ndarray:
    """Held-out squared error of each block (K = FOLDS x R) and joint of ``r ~ b a`` (K, n)."""
    aa = np.vstack([_block_sums(a * a, b) for a, b in zip(adds, blocks, strict=True)])
    ar = np.vstack([_block_sums(a * r, b) for a, r, b in zip(adds, resid, blocks, strict=True)])
    rr = np.vstack([_block_sums(r * r, b) for r, b in zip(resid, blocks, strict=True)])
    # b of the other blocks: sum(a r) / sum(a a), at least 0; held-out error sum (r - b a)^2
    gain = np.maximum((ar.sum(axis=0)[None, :] - ar) / np.maximum(aa.sum(axis=0)[None, :] - aa, 1e-300),
                      0.0)
    return rr - 2.0 * gain * ar + gain**2 * aa


def with_resonance(ident: Any, recordings: Sequence[Any], payloads: Sequence[Any] | None,
                   target: str, option: bool | str) -> Any:
    """``ident`` with the modes of ``option`` (False, True or "auto") fitted and recorded.

    Parameters
    ----------
    ident : Identification
    recordings : sequence of Recording
        The identification recordings, raw.
    payloads : sequence of Payload or None, optional
    target : {"tau", "current"}
    option : bool or "auto"
    """
    fit_cut = ident.preprocess.cutoff
    if option is False or fit_cut is None:
        return ident
    band = prediction_candidates(fit_cut, slowest_rate(recordings))[-1]
    settings = replace(ident.preprocess, cutoff=band)
    pays = list(payloads) if payloads is not None else [None] * len(recordings)
    times, efforts, targets, plain = [], [], [], []
    for rec, pay in zip(recordings, pays, strict=True):
        s = preprocess(rec, settings, None)
        temp = temperatures(rec, 0, ident.robot.dof) if ident.thermal_fit is not None else None
        times.append(np.asarray(s.t, float))
        efforts.append(ident.effort(s, temp, pay))
        targets.append(np.asarray(target_signal(rec, target), float))
        plain.append(ident.effort(preprocess(rec, ident.prediction_settings, None), temp, pay))
    fit, scores = fit_resonance(times, efforts, targets, plain, band, option)
    modes = () if fit is None else tuple(
        (ident.robot.joint_names[j], float(fit.f0[j]), float(fit.zeta[j]), float(fit.gain[j]))
        for j in np.flatnonzero(fit.kept))
    choices = replace(ident.choices, resonance=fit is not None, resonance_scores=tuple(scores.items()),
                      resonance_modes=modes) if ident.choices is not None else None
    return replace(ident, resonance_fit=fit, choices=choices)
