"""Bounds on the sizes a user's options can ask for, checked before anything is allocated.

A time grid of ``duration / dt`` samples is built by several commands (excitation, test
programs, the underwater studies); ``dt = 1e-12`` or a duration of ``1e9`` s would ask for
terabytes and fail deep inside NumPy. :func:`time_grid_steps` refuses such a grid with the
option names and the count, and the limit can be raised for a deliberate long run.
"""

from __future__ import annotations

import math
import os

from robodyn.robot.errors import InputError

__all__ = ["MAX_GRID_SAMPLES", "env_limit", "max_grid_samples", "time_grid_steps"]

#: Default largest time grid, samples (``$ROBODYN_MAX_GRID_SAMPLES`` raises it): 10^7 samples of a
#: 7-joint arm's q, qd, qdd are 1.7 GB.
MAX_GRID_SAMPLES = 10_000_000


def env_limit(name: str, default: int, scale: int = 1) -> int:
    """A size limit: the environment variable ``name`` times ``scale`` when set (a positive
    number; an integer when ``scale`` is 1), else ``default``; ValueError naming the variable."""
    text = os.environ.get(name, "").strip()
    if not text:
        return default
    try:
        value = float(text) if scale != 1 else int(text)
    except ValueError:
        value = -1
    if not 0 < value < float("inf"):
        kind = "a positive integer" if scale == 1 else "a positive number"
        raise InputError(f"{name}={text!r}: expected {kind}")
    return int(value * scale)


def max_grid_samples() -> int:
    """The grid limit: ``$ROBODYN_MAX_GRID_SAMPLES`` when set, else :data:`MAX_GRID_SAMPLES`."""
    return env_limit("ROBODYN_MAX_GRID_SAMPLES", MAX_GRID_SAMPLES)


def time_grid_steps(duration: float, dt: float, where: str, *, duration_name: str = "duration",
                    dt_name: str = "dt") -> int:
    """Steps ``round(duration / dt)`` of a time grid, after checking both and the count.

    Parameters
    ----------
    duration, dt : float
        Seconds; both finite and positive.
    where : str
        The function or command, for the message.
    duration_name, dt_name : str
        The option names the user gave, for the message.

    Returns
    -------
    int

    Raises
    ------
    ValueError
        A non-finite or non-positive value, or more than :func:`max_grid_samples` samples.
    """
    for name, value in ((duration_name, duration), (dt_name, dt)):
        if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value) \
                or value <= 0:
            raise InputError(f"{where}: {name} must be a positive number of seconds, got {value!r}")
    steps = duration / dt
    limit = max_grid_samples()
    if steps + 1 > limit:
        raise InputError(f"{where}: {duration_name} {duration:g} s at {dt_name} {dt:g} s is "
                         f"{steps + 1:.3g} samples, more than {limit:g} (a larger {dt_name} or a "
                         "shorter run; or set ROBODYN_MAX_GRID_SAMPLES)")
    return int(round(steps))
