"""Sensor conversions: encoder counters, current transducers, torque from current, sample period.

Each function takes raw (N, n) columns and per-joint (n,) constants and returns new arrays (the
input is never modified).
"""

from __future__ import annotations

import numpy as np

from robodyn.measure.recording import PLAUSIBLE
from robodyn.robot.errors import InputError

__all__ = ["counts_to_angle", "current_to_torque", "estimate_period", "unwrap_counter",
           "volts_to_current"]


def unwrap_counter(counts: np.ndarray, bits: int) -> np.ndarray:
    """Undo the wrap-around of an unsigned ``bits``-bit counter.

    Parameters
    ----------
    counts : (N,) or (N, n) ndarray
        Raw counter readings in ``[0, 2**bits)``.
    bits : int
        Counter width (e.g. 24).

    Returns
    -------
    (N,) or (N, n) ndarray
        Continuous counts: a step larger than half the range between two samples is taken as a
        wrap (the counter must move less than ``2**(bits-1)`` counts per sample).
    """
    c = np.asarray(counts, dtype=float)
    span = float(2**bits)
    step = np.diff(c, axis=0)
    # each jump beyond half the range is a wrap: subtract the nearest whole number of spans
    step -= span * np.round(step / span)
    return np.concatenate([c[:1], c[:1] + np.cumsum(step, axis=0)], axis=0)


def counts_to_angle(counts: np.ndarray, counts_per_rev: np.ndarray, gear_ratio: np.ndarray
                    ) -> np.ndarray:
    """Joint angle, rad, from motor-encoder counts: ``2 pi counts / (counts_per_rev gear_ratio)``.

    Parameters
    ----------
    counts : (N, n) ndarray
        (Unwrapped) motor counts.
    counts_per_rev, gear_ratio : (n,) ndarray
        Counts per motor revolution; motor turns per joint turn.
    """
    return 2.0 * np.pi * np.asarray(counts, dtype=float) / (counts_per_rev * gear_ratio)


def volts_to_current(volts: np.ndarray, offset: np.ndarray, gain: np.ndarray) -> np.ndarray:
    """Motor current, A, from a Hall-effect transducer: ``I = (V - offset) / gain``.

    Parameters
    ----------
    volts : (N, n) ndarray
        Transducer output, V.
    offset : (n,) ndarray
        Output at zero current, V.
    gain : (n,) ndarray
        Transducer gain, V/A.
    """
    return (np.asarray(volts, dtype=float) - offset) / gain


def current_to_torque(current: np.ndarray, gear_ratio: np.ndarray, torque_constant: np.ndarray
                      ) -> np.ndarray:
    """Joint torque, N m, from motor current: ``tau = gear_ratio k_t I`` (losses not included).

    Parameters
    ----------
    current : (N, n) ndarray
        Motor current, A.
    gear_ratio : (n,) ndarray
        Motor turns per joint turn.
    torque_constant : (n,) ndarray
        Motor torque constant k_t, N m/A.
    """
    return np.asarray(current, dtype=float) * (gear_ratio * torque_constant)


#: Steps whose residual exceeds this many robust standard deviations are left out of the
#: period estimate.
PERIOD_OUTLIER = 10000.0


def estimate_period(q: np.ndarray, qd: np.ndarray) -> float:
    """Sample period, s, of a log whose time column is only a sample index.

    The positions must advance by the measured velocity times the period; the least-squares
    period over all joints and samples is
    ``T = sum(dq_k vbar_k) / sum(vbar_k^2)`` with ``dq_k = q_{k+1} - q_k`` and ``vbar_k`` the
    mean of the velocities at both ends of the step (trapezoidal rule).

    Parameters
    ----------
    q : (N, n) ndarray
        Positions, rad.
    qd : (N, n) ndarray
        Measured velocities, rad/s.

    The least squares are taken over the steps that agree with the median ratio
    ``median(dq / vbar)`` (on steps with a clear velocity) to within ``PERIOD_OUTLIER`` robust
    standard deviations, so that one corrupt cell (a position of 1e308, a velocity spike) cannot
    set the period: it is left to the checks of the values themselves.

    Returns
    -------
    float
        T, s; raises ValueError when the arm did not move.
    """
    with np.errstate(over="ignore", invalid="ignore"):
        dq = np.diff(q, axis=0).ravel()
        vbar = (0.5 * (qd[1:] + qd[:-1])).ravel()  # trapezoidal rule: dq = T (v_k + v_k+1) / 2
    # implausible cells (checked and named when the recording is built) set nothing here
    ok = (np.isfinite(dq) & np.isfinite(vbar) & (np.abs(vbar) <= PLAUSIBLE["qd"][0])
          & (np.abs(dq) <= PLAUSIBLE["q"][0]))
    dq, vbar = dq[ok], vbar[ok]
    if not np.any(vbar != 0.0):
        raise InputError("cannot estimate the sample period: the measured velocity is zero throughout")
    clear = np.abs(vbar) >= 0.1 * np.max(np.abs(vbar))
    ratio = dq[clear] / vbar[clear]
    t0 = float(np.median(ratio))
    # residuals of dq = T vbar at the median ratio, and their robust scale (MAD)
    r = dq - t0 * vbar
    scale = 1.4826 * float(np.median(np.abs(r - np.median(r)))) or float(np.max(np.abs(r))) or 1.0
    keep = np.abs(r) <= PERIOD_OUTLIER * scale
    den = float(np.sum(vbar[keep] ** 2))
    return float(np.sum(dq[keep] * vbar[keep])) / den if den > 0 else t0
