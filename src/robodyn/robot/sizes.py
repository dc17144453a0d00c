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

__all__ = ["MAX_GRID_SAMPLES", "MAX_GRID_VALUES", "env_limit", "max_grid_samples", "time_grid_steps"]

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


#: Default largest number of values (samples x values per sample) of a time grid that a command
#: evaluates and writes as CSV (``robodyn excite``, ``robodyn testprog``): about 20 bytes and 1 us
#: a value, so 3 x 10^7 values (1.36 x 10^6 samples of t, q, qd, qdd of a 7-joint arm, 4.3 x 10^6
#: of a 2-joint arm) stay under 1 GB and about 30 s. ``$ROBODYN_MAX_GRID_SAMPLES`` replaces this
#: bound too when set.
MAX_GRID_VALUES = 30_000_000


def max_grid_samples(values_per_sample: int = 0) -> int:
    """The grid limit: ``$ROBODYN_MAX_GRID_SAMPLES`` when set, else :data:`MAX_GRID_SAMPLES`, or
    for ``values_per_sample`` > 0 the smaller :data:`MAX_GRID_VALUES` / ``values_per_sample``."""
    limit = env_limit("ROBODYN_MAX_GRID_SAMPLES", 0)
    if limit:
        return limit
    if values_per_sample > 0:
        return min(MAX_GRID_SAMPLES, MAX_GRID_VALUES // values_per_sample)
    return MAX_GRID_SAMPLES


def time_grid_steps(duration: float, dt: float, where: str, *, duration_name: str = "duration",
                    dt_name: str = "dt", values_per_sample: int = 0) -> int:
    """Steps ``round(duration / dt)`` of a time grid, after checking both and the count.

    Parameters
    ----------
    duration, dt : float
        Seconds; both finite and positive.
    where : str
        The function or command, for the message.
    duration_name, dt_name : str
        The option names the user gave, for the message.
    values_per_sample : int
        Values a sample of the grid holds where the caller evaluates and writes them all (e.g.
        ``1 + 3 n`` for t, q, qd, qdd of n joints): bounds the samples by :data:`MAX_GRID_VALUES`
        too (:func:`max_grid_samples`).

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
    limit = max_grid_samples(values_per_sample)
    if steps + 1 > limit:
        raise InputError(f"{where}: {duration_name} {duration:g} s at {dt_name} {dt:g} s is "
                         f"{steps + 1:.3g} samples, more than {limit:.3g} (a larger {dt_name} or a "
                         "shorter run; or set ROBODYN_MAX_GRID_SAMPLES)")
    return int(round(steps))
