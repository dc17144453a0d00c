"""The width of the predictions' smoothed Coulomb step, from the velocity estimate's noise.

The linear law's Coulomb torque steps with the sign of the velocity, ``Fc H(qd)``. A prediction
evaluates it at an *estimated* velocity ``qd_hat = qd + e``; where ``|qd|`` is comparable to the
estimate's noise (a joint held still or creeping, a slow reversal) the sign of ``qd_hat`` is a
coin toss, and the step predicts a full ``+-Fc`` that is as often wrong as right. With ``e``
normal of standard deviation ``s`` and no preference for either sign, the probability that the
velocity is positive given the estimate is ``(1 + erf(qd_hat / (sqrt(2) s))) / 2``;
:func:`robodyn.identification.preprocess.coulomb_smoothing` uses ``(1 + tanh(qd_hat / w)) / 2``.
``w = sqrt(pi / 2) s`` (:data:`WIDTH_PER_NOISE`: the same slope at zero) makes the two alike.
This lowers the expected squared error of the Coulomb torque wherever ``|qd|`` is within a few
``s``; in a run of brisk motion only the few samples that fall near a reversal are touched, and
a single run may come out either way (``benchmarks/bench_identification_coulomb.py``, simulated
runs).

**A joint held by its controller** (:func:`holds`: its estimated speed below
:data:`HOLD_SPEED` for at least :data:`HOLD_SECONDS`) creeps at speeds no noise estimate sees,
and below that speed its sign says little about its friction: there the width is at least
:data:`HOLD_SPEED` (:func:`held_widths`). A reversal in brisk motion passes below that speed for
milliseconds and keeps the width from the noise.

``s`` per joint (:func:`velocity_noise`): the positions' (or the measured velocities') white
noise, measured by their fourth divided differences at their own stamps (which any cubic in time
leaves at zero, so that the motion does not count as noise, on irregular stamps too), carried
through the prediction's own linear operator: the norm of the response of
:func:`robodyn.measure.filtering.differentiate` (or :func:`~robodyn.measure.filtering.lowpass`
for measured velocities) to a unit impulse at the middle sample, at the recording's stamps and
the prediction's cut-off. Pooled over the identification recordings in which the joint moves,
weighted by their samples (:func:`auto_coulomb_width`).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from robodyn.identification.preprocess import MOVING_RAD
from robodyn.measure.angles import unwrap_turns
from robodyn.measure.filtering import differentiate, lowpass

__all__ = ["HOLD_SECONDS", "HOLD_SPEED", "WIDTH_PER_NOISE", "auto_coulomb_width", "held_widths",
           "holds", "velocity_noise"]

#: ``w / s``: tanh(x / w) and erf(x / (sqrt(2) s)) have the same slope at 0 (module docstring).
WIDTH_PER_NOISE = float(np.sqrt(np.pi / 2.0))
#: A hold: a joint's estimated speed below this (rad/s, m/s; the textbook's dead band) ...
HOLD_SPEED = 1e-3
#: ... for at least this long, s (a reversal in brisk motion stays below it for milliseconds).
HOLD_SECONDS = 0.25
#: Fewest samples for a noise estimate of a recording.
_MIN_SAMPLES = 64
#: The five samples of a window of :func:`_white_std`.
_OFFSETS = np.arange(5)


def _white_std(t: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Standard deviation (n,) of the white noise of ``x`` (N, n) sampled at stamps ``t`` (N,).

    Each window of five consecutive samples gives the fourth divided difference at its own
    stamps, scaled to unit weight norm: it is zero for any cubic in time, so smooth motion
    leaves nothing in it, while white noise of variance ``s^2`` leaves variance ``s^2``."""
    k = len(_OFFSETS)
    win = np.lib.stride_tricks.sliding_window_view(t, k)  # (N - 4, 5) stamps of each window
    # divided-difference weights c_k = 1 / prod_{m != k} (t_k - t_m), made unit-norm
    diff = win[:, :, None] - win[:, None, :]
    diff[:, _OFFSETS, _OFFSETS] = 1.0
    c = 1.0 / np.prod(diff, axis=2)
    c /= np.linalg.norm(c, axis=1, keepdims=True)
    d = sum(c[:, i, None] * x[i:x.shape[0] - k + 1 + i] for i in _OFFSETS)  # (N - 4, n)
    return np.sqrt(np.mean(d**2, axis=0))


def velocity_noise(rec: Any, settings: Any) -> np.ndarray:
    """Standard deviation (n,) of the noise of a recording's processed velocity, rad/s (m/s).

    Parameters
    ----------
    rec : Recording
        ``t`` (N,) s, ``q`` (N, n) rad (m), optional measured ``qd`` (N, n).
    settings : Preprocess
        The processing of the prediction (``cutoff`` Hz or None, ``order``, ``velocity``).

    Returns
    -------
    numpy.ndarray, shape (n,)
        0 for joints held still (their processed velocity is exactly 0) and for recordings too
        short to tell (fewer than 64 samples), and without a filter (``cutoff`` None: the
        recording's own velocities are taken as they are).
    """
    t = np.asarray(rec.t, float)
    q = unwrap_turns(rec.q)  # a wrapped angle's steps are no velocity noise
    n = q.shape[1]
    if settings.cutoff is None or t.size < _MIN_SAMPLES:
        return np.zeros(n)
    impulse = np.zeros(t.size)
    impulse[t.size // 2] = 1.0
    measured = (settings.velocity == "measured" and rec.qd is not None
                and "qd" not in getattr(rec, "estimated", frozenset()))
    if measured:
        source = np.asarray(rec.qd, float)
        gain = np.linalg.norm(lowpass(t, impulse, settings.cutoff, order=settings.order))
    else:
        source = q
        gain = np.linalg.norm(differentiate(t, impulse, settings.cutoff, order=settings.order)[1])
    s = _white_std(t, source) * gain  # white noise through the prediction's linear operator
    s[np.ptp(q, axis=0) < MOVING_RAD] = 0.0  # held still: processed velocity exactly 0
    return s


def auto_coulomb_width(recordings: Sequence[Any], settings: Any) -> np.ndarray:
    """Width (n,) of the Coulomb step, rad/s (m/s): ``WIDTH_PER_NOISE`` times the velocity noise of the
    recordings (:func:`velocity_noise`), pooled per joint over those in which it moves,
    weighted by their samples; 0 for a joint that never moves."""
    var = np.zeros(np.asarray(recordings[0].q).shape[1])
    count = np.zeros_like(var)
    for rec in recordings:
        s = velocity_noise(rec, settings)
        moving = s > 0
        var[moving] += rec.t.size * s[moving] ** 2
        count[moving] += rec.t.size
    return WIDTH_PER_NOISE * np.sqrt(np.divide(var, count, out=np.zeros_like(var), where=count > 0))


def holds(t: np.ndarray, qd: np.ndarray, speed: float = HOLD_SPEED,
          seconds: float = HOLD_SECONDS) -> np.ndarray:
    """Where each joint is held (N, n): its estimated speed ``|qd|`` stays below ``speed``
    (rad/s, m/s) for at least ``seconds`` without a break.

    Parameters
    ----------
    t : numpy.ndarray, shape (N,)
        Stamps, s, increasing (any spacing).
    qd : numpy.ndarray, shape (N, n)
        Processed velocities, rad/s (m/s).

    Returns
    -------
    numpy.ndarray of bool, shape (N, n)
    """
    slow = (np.abs(qd) < speed).astype(np.int8)
    out = np.zeros(qd.shape, dtype=bool)
    for j in range(qd.shape[1]):
        # runs of slow samples: starts where the mask rises, ends (exclusive) where it falls
        edges = np.diff(np.concatenate([[0], slow[:, j], [0]]))
        starts, ends = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
        long = t[ends - 1] - t[starts] >= seconds
        # +1 at each long run's start, -1 past its end: the running sum marks the run
        mark = np.zeros(t.size + 1, dtype=np.int64)
        np.add.at(mark, starts[long], 1)
        np.add.at(mark, ends[long], -1)
        out[:, j] = np.cumsum(mark[:-1]) > 0
    return out


def held_widths(t: np.ndarray, qd: np.ndarray, width: float | np.ndarray) -> np.ndarray:
    """Per-sample widths (N, n), rad/s (m/s): ``width`` (scalar or (n,)) where the joint moves,
    at least :data:`HOLD_SPEED` where it is held (:func:`holds`); a joint whose width is 0 keeps
    the step everywhere."""
    w = np.broadcast_to(np.asarray(width, float), qd.shape)
    if not np.any(w > 0):
        return w  # the step everywhere: no hold to look for
    return np.where(holds(t, qd) & (w > 0), np.maximum(w, HOLD_SPEED), w)
