"""Logged angles that wrap around: a continuous joint reported within ``[-pi, pi)`` or ``[0, 2 pi)``.

A logger that reports a joint's angle modulo a turn makes it step by about ``2 pi`` wherever the
joint passes the boundary. No arm turns half a revolution between two samples, so such a step is
undone before anything differentiates or filters the positions (velocity estimates, the
identification's preprocessing, validation); sines and cosines of the angle do not change.
The recording itself keeps the positions as logged.
"""

from __future__ import annotations

import numpy as np

__all__ = ["WRAP_TOLERANCE", "unwrap_turns", "wrap_steps"]


#: A step of a logged position is a wrap when it exceeds pi and lies within this of a whole
#: number of turns (rad): what is left is the motion between the two samples.
WRAP_TOLERANCE = 0.5


def _wraps(q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The whole turns of each step (N - 1, ...) and where a step is a wrap (same shape)."""
    d = np.diff(q, axis=0)
    turns = np.round(d / (2.0 * np.pi))
    return turns, (np.abs(d) > np.pi) & (np.abs(d - 2.0 * np.pi * turns) < WRAP_TOLERANCE)


def wrap_steps(q: np.ndarray) -> np.ndarray:
    """How many wrap-around steps :func:`unwrap_turns` undoes in each column of ``q`` (N, n).

    Returns
    -------
    numpy.ndarray of int, shape (n,)
    """
    return np.sum(_wraps(np.asarray(q, dtype=float))[1], axis=0)


def unwrap_turns(q: np.ndarray) -> np.ndarray:
    """Positions with each wrap-around step undone (a copy; ``q`` itself when there is none).

    Parameters
    ----------
    q : numpy.ndarray, shape (N, n)
        Logged positions, rad (m for prismatic joints, which never step by a turn).

    Returns
    -------
    numpy.ndarray, shape (N, n)
        ``q`` less ``2 pi k`` after every step ``dq`` with ``|dq| > pi`` and
        ``|dq - 2 pi k| < WRAP_TOLERANCE``, ``k = round(dq / 2 pi)``.
    """
    q = np.asarray(q, dtype=float)
    turns, wrap = _wraps(q)
    if not np.any(wrap):
        return q
    # q_k - 2 pi (turns wrapped up to k)
    shift = np.cumsum(np.where(wrap, 2.0 * np.pi * turns, 0.0), axis=0)
    return np.concatenate([q[:1], q[1:] - shift], axis=0)
