"""The choices of a simulation other than the model, the initial state and the controller.

:func:`robodyn.simulate` takes them as keywords (and builds a :class:`SimulateOptions`) or as
``options=SimulateOptions(...)``; the trajectory keeps the set it ran with
(``traj.options``). The checks of each field live here, once.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from robodyn.robot.errors import InputError

__all__ = ["ADAPTIVE", "FIXED_STEP", "MAX_SAMPLES", "SimulateOptions", "positive_int"]

FIXED_STEP = ("rk4", "semi_implicit")
ADAPTIVE = ("RK45", "RK23", "DOP853", "Radau", "BDF", "LSODA")

#: Default largest number of output samples (rows of a :class:`Trajectory`): 1000 s at 1 ms,
#: about 250 MB of arrays for six joints. Longer runs need ``decimate`` or ``max_samples``.
MAX_SAMPLES = 1_000_000


@dataclass(frozen=True, eq=False)
class SimulateOptions:
    """The choices of :func:`robodyn.simulate` (keywords of the same names).

    Attributes
    ----------
    method : str
        "rk4" or "semi_implicit" (fixed step ``dt``, in the generated C), or a SciPy method
        ("RK45", "RK23", "DOP853", "Radau", "BDF", "LSODA": adaptive, sampled every ``dt``).
    tau_limit : float or (n,), optional
        Actuator limits, N m (N): the torque is clipped to +-tau_limit.
    rtol, atol : float
        Tolerances of the SciPy methods.
    control : {"sampled", "continuous"}
        The controller held over each step (a digital controller at the integration rate), or
        evaluated wherever the dynamics are (RK4 stages, SciPy).
    decimate : int
        Keep every ``decimate``-th step.
    max_samples : int or None
        Largest number of output samples (None: no limit).
    substeps : int
        Integration steps per controller sample (fixed step, sampled control).
    threads : int
        Threads of an ensemble (results do not depend on it).

    Raises
    ------
    InputError
        On construction: a value outside its choices or an inconsistent combination.
    """

    method: str = "rk4"
    tau_limit: Any = None
    rtol: float = 1e-9
    atol: float = 1e-12
    control: str = "sampled"
    decimate: int = 1
    max_samples: int | None = MAX_SAMPLES
    substeps: int = 1
    threads: int = 1

    def __post_init__(self) -> None:
        if self.method not in FIXED_STEP + ADAPTIVE:
            raise InputError(f"unknown method {self.method!r}; choose one of "
                             f"{', '.join(FIXED_STEP + ADAPTIVE)}")
        if self.control not in ("sampled", "continuous"):
            raise InputError(f"unknown control {self.control!r}; choose 'sampled' or 'continuous'")
        if self.control == "continuous" and self.method == "semi_implicit":
            raise InputError("control='continuous' needs method='rk4' or a SciPy method (semi-implicit "
                             "Euler evaluates the law once per step: use control='sampled')")
        if not positive_int(self.substeps):
            raise InputError(f"simulate: substeps must be a positive integer, got {self.substeps!r}")
        if self.substeps > 1 and (self.control != "sampled" or self.method not in FIXED_STEP):
            raise InputError("simulate: substeps needs a fixed-step method and control='sampled' (a "
                             "continuous law or a SciPy method already evaluates the law wherever it "
                             "evaluates the dynamics)")
        for name in ("rtol", "atol"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v) or v <= 0:
                raise InputError(f"simulate: {name} must be a positive number, got {v!r}")
        if self.max_samples is not None and not positive_int(self.max_samples):
            raise InputError(f"simulate: max_samples must be a positive integer or None, got "
                             f"{self.max_samples!r}")


def positive_int(v: Any) -> bool:
    """Whether ``v`` is an integer (not a bool) of at least 1."""
    return not isinstance(v, bool) and isinstance(v, int | np.integer) and v >= 1
