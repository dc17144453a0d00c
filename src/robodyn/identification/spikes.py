"""Isolated corrupt rows in a recording: one-sample spikes found before identification.

A logger's glitch (an encoder reading off by a fraction of a turn for one sample, a torque or
current spike, a row of zeros) is a sample far from the line through its two neighbours while
the neighbours agree with each other. Differentiated and filtered, one such sample becomes a
bump of velocity and acceleration a filter's length wide, which the least squares then fit
(on a simulated PUMA log, five corrupt rows of 6000 made the held-out error 15 times the clean
fit's). For every column of the positions and of the target, with stamps ``t``::

    d_k = x_k - (x_{k-1} + (x_{k+1} - x_{k-1}) (t_k - t_{k-1}) / (t_{k+1} - t_{k-1}))

is the sample's distance from its neighbours' line. Sample ``k`` is a spike when ``|d_k|`` exceeds
``THRESHOLD`` robust standard deviations of ``d`` (1.4826 times its median absolute deviation, at
least ``QUANTA`` steps of the column's resolution, so that printed values are not spikes) and is
more than ``SHAPE`` times both neighbours' ``|d|`` (a spike gives -s/2, s, -s/2; a step, such as
Coulomb friction reversing, gives h/2, -h/2 and is kept). Spikes are removed (their rows
dropped, the stamps kept irregular) and counted; a second pass finds one of two adjacent ones.

A burst of ``L`` corrupt rows (3 to :data:`MAX_BURST`; a sensor reading a constant or zero for a
few cycles) has neighbours' distances as large as its own, so the rule above keeps it. Rows
``k .. k + L - 1`` are a burst when each lies on the same side of the line through the rows
bracketing it (``k - 1`` and ``k + L``), the nearest of them beyond the threshold in robust
standard deviations of the ``L``-row distances (the middle row's, over all windows: a smooth
signal's curvature over ``L + 1`` steps is part of that scale), and more than ``SHAPE`` times
the bracketing rows' own difference (a step, such as a Coulomb reversal, moves the bracket as
far as the rows inside it and is kept). Bursts are looked for at :data:`GROSS_THRESHOLD` in
either mode: at the 12 deviations of ``spikes="drop"`` a few consecutive rows off the line are,
on the real runs here, as often a transient of the signal (the Kinova runs' currents: 4-31 more
rows per run at 12, none at 100). Measured before this rule (2026-12-07, PUMA 560 at
100 Hz, 3000 rows, exact motion, 0.05 N m noise): three rows of 1e4 N m on one joint's torque
made the held-out error 0.27 against the clean fit's 0.0026.
"""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np

from robodyn.measure.angles import unwrap_turns
from robodyn.robot.errors import RecordingWarning

__all__ = ["GROSS_THRESHOLD", "MAX_BURST", "QUANTA", "SHAPE", "THRESHOLD", "burst_rows",
           "drop_spikes", "spike_rows", "without_spikes"]

#: Robust standard deviations beyond which a sample's distance from its neighbours' line is a spike
#: (``spikes="drop"``).
THRESHOLD = 12.0
#: The same for a gross glitch only (``spikes="auto"``, the default): an encoder sample off by a
#: fraction of a turn, a row of zeros. Real logs, pre-filtered or quantised, have narrow
#: distributions of ``d`` with long tails, where 12 flags 0.5-3 % of ordinary samples; 100 flags
#: none to nine rows of the 1,359-6,535 of each real run here.
GROSS_THRESHOLD = 100.0
#: A spike's distance is more than this many times each neighbour's.
SHAPE = 1.5
#: The scale is at least this many steps of the column's resolution (its smallest nonzero change).
QUANTA = 4.0
#: Passes (each can drop one of two adjacent corrupt rows).
PASSES = 2
#: Longest burst of corrupt rows looked for (module docstring).
MAX_BURST = 5


def _distances(t: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``d`` of every interior sample (rows 1 .. N-2), shape (N - 2, columns)."""
    w = ((t[1:-1] - t[:-2]) / (t[2:] - t[:-2]))[:, None]
    return x[1:-1] - (x[:-2] + (x[2:] - x[:-2]) * w)


def _scale(d: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Per column: the robust standard deviation of ``d``, at least ``QUANTA`` resolution steps."""
    mad = 1.4826 * np.median(np.abs(d - np.median(d, axis=0)), axis=0)
    steps = np.abs(np.diff(x, axis=0))
    steps = np.where(steps > 0, steps, np.inf)
    quantum = np.min(steps, axis=0)
    quantum = np.where(np.isfinite(quantum), quantum, 0.0)
    return np.maximum(mad, QUANTA * quantum)


def _burst_distances(t: np.ndarray, x: np.ndarray, length: int) -> np.ndarray:
    """Distances of rows ``k + i`` (``i < length``) from the line through rows ``k - 1`` and
    ``k + length``, for every window: shape (length, N - length - 1, columns)."""
    n = t.size
    ta, tb, a, b = t[:n - length - 1], t[length + 1:], x[:n - length - 1], x[length + 1:]
    out = []
    for i in range(length):
        ti, xi = t[1 + i:n - length + i], x[1 + i:n - length + i]
        out.append(xi - (a + (b - a) * ((ti - ta) / (tb - ta))[:, None]))  # off the bracket's line
    return np.stack(out)


def burst_rows(t: np.ndarray, x: np.ndarray, threshold: float) -> np.ndarray:
    """Rows (N,) in a burst of 3 to :data:`MAX_BURST` corrupt rows of some column of ``x`` (N, c)
    (module docstring), beyond ``threshold`` robust standard deviations."""
    out = np.zeros(t.size, dtype=bool)
    for length in range(3, MAX_BURST + 1):
        if t.size < length + 4:
            break
        d = _burst_distances(t, x, length)
        mid = d[length // 2]
        scale = _scale(mid, x)
        near = np.min(np.abs(d), axis=0)
        bracket = np.abs(x[length + 1:] - x[:t.size - length - 1])
        same_side = np.all(np.sign(d) == np.sign(d[0]), axis=0)
        hit = np.any(same_side & (near > threshold * np.where(scale > 0, scale, np.inf))
                     & (near > SHAPE * bracket), axis=1)
        for k in np.flatnonzero(hit):
            out[k + 1:k + 1 + length] = True  # rows k+1 .. k+length of the window starting at k
    return out


def spike_rows(t: np.ndarray, *signals: np.ndarray, threshold: float = THRESHOLD) -> np.ndarray:
    """Rows (N,) that are a one-sample spike in some column of ``signals`` (each (N, n)), beyond
    ``threshold`` robust standard deviations; NaN columns (no sensor) are skipped."""
    t = np.asarray(t, dtype=float)
    out = np.zeros(t.size, dtype=bool)
    if t.size < 5:
        return out
    for x in signals:
        x = np.asarray(x, dtype=float)
        x = x[:, np.all(np.isfinite(x), axis=0)]
        if x.shape[1] == 0:
            continue
        d = np.abs(_distances(t, x))
        scale = _scale(d, x)
        big = d > threshold * np.where(scale > 0, scale, np.inf)
        padded = np.pad(d, ((1, 1), (0, 0)))
        shaped = (d > SHAPE * padded[:-2]) & (d > SHAPE * padded[2:])
        out[1:-1] |= np.any(big & shaped, axis=1)
        out |= burst_rows(t, x, max(threshold, GROSS_THRESHOLD))  # bursts: gross ones only
    return out


def drop_spikes(rec: Any, target: str, threshold: float = THRESHOLD) -> tuple[Any, int]:
    """``rec`` without the rows that are spikes in ``q`` or in ``target`` (beyond ``threshold``
    robust standard deviations), and how many were dropped (``rec`` itself when none)."""
    dropped = 0
    if not callable(getattr(rec, "rows", None)):
        return rec, 0  # not a Recording: left as given
    for _ in range(PASSES):
        y = getattr(rec, target, None)
        rows = spike_rows(rec.t, unwrap_turns(rec.q), *([] if y is None else [y]), threshold=threshold)
        if not rows.any():
            break
        with warnings.catch_warnings():  # the dropped rows are the only 'gaps' this adds
            warnings.simplefilter("ignore", RecordingWarning)
            rec = rec.rows(~rows)
        dropped += int(rows.sum())
    return rec, dropped


def without_spikes(recordings: list[Any], target: str, mode: str) -> list[Any]:
    """The identification recordings as ``spikes=mode`` wants them: as given (``"keep"``),
    without every spike (``"drop"``: :data:`THRESHOLD`), or without the gross glitches only
    (``"auto"``: :data:`GROSS_THRESHOLD`, with a warning naming each recording and its count)."""
    if mode == "keep":
        return list(recordings)
    threshold = THRESHOLD if mode == "drop" else GROSS_THRESHOLD
    out = []
    for rec in recordings:
        kept, dropped = drop_spikes(rec, target, threshold)
        if dropped and mode == "auto":
            warnings.warn(f"{getattr(rec, 'source', 'recording')}: {dropped} row(s) dropped as "
                          f"glitches (one-sample spikes or bursts of up to {MAX_BURST} rows, more "
                          f"than {GROSS_THRESHOLD:g} robust standard deviations off their "
                          "neighbours' line; spikes='keep' keeps them)",
                          RecordingWarning, stacklevel=3)
        out.append(kept)
    return out
