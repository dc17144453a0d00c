"""Synchronising a tracker stream with the joint stream by cross-correlating tool speed.

The tool speed is independent of the frame the tracker measures in, so the joint side needs only
forward kinematics: ``v_fk(t) = |d/dt p_fk(q(t))|`` with ``p_fk`` the translation of
``model.forward_kinematics(q)``, against ``v_tr(t) = |d/dt p_tracker(t)|``. Both speeds come
from the zero-phase differentiator (:mod:`robodyn.measure.filtering`) at one shared cut-off, are
put on grids of the joint period, and the lag of the largest cross-correlation (refined to a
fraction of a sample by a parabola through the peak and its neighbours) is the offset ``d``:
the tracker stamp of an event is ``d`` later than its joint stamp.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from scipy import signal

from robodyn.measure.filtering import bandwidth_cutoff, differentiate
from robodyn.measure.recording import Recording
from robodyn.robot.errors import RecordingError

__all__ = ["Synchronisation", "synchronise", "tool_speed"]


@dataclass(frozen=True, eq=False)
class Synchronisation:
    """Result of :func:`synchronise`.

    Attributes
    ----------
    offset : float
        d, s: tracker stamps are late by d (``tool_t - d`` is on the joint clock).
    correlation : float
        Normalised cross-correlation of the two speeds at the offset (1 = identical shape).
    recording : Recording
        The input recording with ``tool_t`` shifted by ``-offset``.
    """

    offset: float
    correlation: float
    recording: Recording


def tool_speed(t: np.ndarray, points: np.ndarray, cutoff: float | None = None) -> np.ndarray:
    """Speed of a point, m/s: ``|dp/dt|`` by zero-phase differentiation.

    Parameters
    ----------
    t : (M,) ndarray
        Times, s.
    points : (M, 3) ndarray
        Positions, m.
    cutoff : float, optional
        Filter cut-off, Hz (the bandwidth rule when None).

    Returns
    -------
    (M,) ndarray
    """
    _, v, _ = differentiate(t, points, cutoff)
    return np.linalg.norm(v, axis=1)


def _on_grid(t: np.ndarray, x: np.ndarray, h: float) -> tuple[float, np.ndarray]:
    grid = t[0] + h * np.arange(int(np.floor((t[-1] - t[0]) / h)) + 1)
    return float(t[0]), np.interp(grid, t, x)


def synchronise(rec: Recording, model: Any, max_offset: float | None = None,
                cutoff: float | None = None) -> Synchronisation:
    """Find the tracker's time offset against the joints and return the shifted recording.

    Parameters
    ----------
    rec : Recording
        With ``tool_t`` and ``tool_points``.
    model : Model
        Compiled model of the arm (``forward_kinematics(q)`` -> (N, 4, 4)).
    max_offset : float, optional
        Largest |offset| searched, s (default: a quarter of the shorter stream).
    cutoff : float, optional
        Filter cut-off for both speeds, Hz; default: the bandwidth rule on the tracker points,
        capped at 0.4 x the tracker's sampling rate.

    Returns
    -------
    Synchronisation
    """
    if rec.tool_t is None:
        raise RecordingError(f"{rec.source or 'Recording'}: tool_t: no tracker samples to synchronise")
    p_fk = np.asarray(model.forward_kinematics(rec.q))[:, :3, 3]
    if cutoff is None:
        cutoff = bandwidth_cutoff(rec.tool_t, rec.tool_points)
    # the same filter on both sides, so neither speed is delayed or attenuated differently
    v_fk = tool_speed(rec.t, p_fk, cutoff)
    v_tr = tool_speed(rec.tool_t, rec.tool_points, cutoff)
    h = rec.dt
    t0a, a = _on_grid(rec.t, v_fk, h)
    t0b, b = _on_grid(rec.tool_t, v_tr, h)
    # Pearson correlation over the overlap at every lag (a global mean subtraction biases the
    # peak toward zero lag for signals that are not zero-mean, e.g. speeds)
    lags = signal.correlation_lags(b.size, a.size, mode="full")
    sab = signal.correlate(b, a, mode="full", method="fft")  # sum_n b[n + lag] a[n]
    ia, ib = np.maximum(0, -lags), np.maximum(0, lags)
    m = np.minimum(a.size - ia, b.size - ib)
    ca, cb = np.concatenate(([0.0], np.cumsum(a))), np.concatenate(([0.0], np.cumsum(b)))
    ca2, cb2 = np.concatenate(([0.0], np.cumsum(a * a))), np.concatenate(([0.0], np.cumsum(b * b)))
    sa, sb = ca[ia + m] - ca[ia], cb[ib + m] - cb[ib]
    va = np.maximum(ca2[ia + m] - ca2[ia] - sa * sa / m, 0.0)
    vb = np.maximum(cb2[ib + m] - cb2[ib] - sb * sb / m, 0.0)
    # r = (sum ab - sum a sum b / m) / sqrt(var_a var_b)
    r = (sab - sa * sb / m) / (np.sqrt(va * vb) + 1e-300)
    offsets = t0b - t0a + lags * h
    limit = 0.25 * min(a.size, b.size) * h if max_offset is None else float(max_offset)
    c = np.where(np.abs(offsets) <= limit, r, -np.inf)
    k = int(np.argmax(c))
    frac = 0.0
    if 0 < k < c.size - 1 and np.isfinite(c[k - 1]) and np.isfinite(c[k + 1]):
        # parabola through the peak and its neighbours: vertex at k + frac
        den = c[k - 1] - 2 * c[k] + c[k + 1]
        frac = 0.5 * (c[k - 1] - c[k + 1]) / den if den < 0 else 0.0
    offset = float(offsets[k] + frac * h)
    rho = float(r[k])
    shifted = replace(rec, tool_t=rec.tool_t - offset)
    return Synchronisation(offset=offset, correlation=rho, recording=shifted)
