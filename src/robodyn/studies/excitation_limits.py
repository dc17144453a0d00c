"""Joint limits of an excitation design: positions, speeds and accelerations, from the description
or given, with defaults where it has none."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from robodyn.robot.errors import InputError
from robodyn.robot.model import Robot
from robodyn.simulation.trajectory import finite_vector

__all__ = ["DEFAULT_ACCELERATION", "DEFAULT_RANGE", "DEFAULT_VELOCITY", "ExcitationLimits",
           "excitation_limits"]

#: Default joint speed and acceleration limits where the description gives none (rad/s, rad/s^2;
#: m/s, m/s^2 for prismatic joints): moderate values that an industrial arm reaches safely.
DEFAULT_VELOCITY = 1.0


DEFAULT_ACCELERATION = 3.0


#: Range assumed for a revolute joint without position limits (rad), about the zero position.
DEFAULT_RANGE = np.pi


# ----------------------------------------------------------------------------------------------
# limits
# ----------------------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class ExcitationLimits:
    """Box limits on joint position, speed and acceleration, (n,) arrays each.

    Attributes
    ----------
    lower, upper : (n,) ndarray
        Position limits, rad (m).
    velocity, acceleration : (n,) ndarray
        Symmetric limits ``|qd| <= velocity`` (rad/s, m/s), ``|qdd| <= acceleration`` (rad/s^2,
        m/s^2); positive.
    """

    lower: np.ndarray
    upper: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray

    @property
    def dof(self) -> int:
        """Number of joints n."""
        return self.lower.size

    def violation(self, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> float:
        """Largest excess over any limit of the samples ``(N, n)`` (<= 0 when all are respected)."""
        return float(max(np.max(q - self.upper), np.max(self.lower - q),
                         np.max(np.abs(qd) - self.velocity), np.max(np.abs(qdd) - self.acceleration)))


def excitation_limits(robot: Robot, *, lower: Sequence[float] | None = None,
                      upper: Sequence[float] | None = None,
                      velocity: float | Sequence[float] | None = None,
                      acceleration: float | Sequence[float] | None = None,
                      margin: float = 0.05) -> ExcitationLimits:
    """Limits for :func:`excitation` from the robot's description, with overrides.

    Parameters
    ----------
    robot : Robot
    lower, upper : (n,) array_like, optional
        Position limits, rad (m). Default: the joint limits shrunk by ``margin`` of their range
        at each end; ``-+DEFAULT_RANGE`` where a joint has none.
    velocity : float or (n,) array_like, optional
        Default: each joint's ``velocity_limit`` times ``1 - margin``, ``DEFAULT_VELOCITY`` where
        none is given.
    acceleration : float or (n,) array_like, optional
        Default ``DEFAULT_ACCELERATION`` (descriptions carry no acceleration limits).
    margin : float
        Fraction in [0, 0.5) kept free at each end of a description's limits.

    Returns
    -------
    ExcitationLimits
    """
    n = robot.dof
    if not 0.0 <= margin < 0.5:
        raise InputError(f"excitation_limits: margin must be in [0, 0.5), got {margin!r}")
    lo = np.array([-DEFAULT_RANGE if j.lower is None else float(j.lower) for j in robot.joints])
    hi = np.array([DEFAULT_RANGE if j.upper is None else float(j.upper) for j in robot.joints])
    span = hi - lo
    lo, hi = lo + margin * span, hi - margin * span
    if lower is not None:
        lo = finite_vector(lower, n, "excitation_limits: lower")
    if upper is not None:
        hi = finite_vector(upper, n, "excitation_limits: upper")
    if np.any(hi <= lo):
        bad = int(np.argmax(hi <= lo))
        raise InputError(f"excitation_limits: joint {robot.joint_names[bad]!r}: upper limit "
                         f"{hi[bad]:g} is not above lower limit {lo[bad]:g}")
    vel = np.array([DEFAULT_VELOCITY if j.velocity_limit is None
                    else (1.0 - margin) * float(j.velocity_limit) for j in robot.joints])
    if velocity is not None:
        vel = _positive_vector(velocity, n, "velocity")
    acc = np.full(n, DEFAULT_ACCELERATION)
    if acceleration is not None:
        acc = _positive_vector(acceleration, n, "acceleration")
    return ExcitationLimits(*(_frozen(v) for v in (lo, hi, vel, acc)))


# --- helpers -----------------------------------------------------------------------------------
def _frozen(a: np.ndarray) -> np.ndarray:
    a = np.array(a, dtype=float)
    a.flags.writeable = False
    return a



def _positive_vector(v: float | Sequence[float], n: int, name: str) -> np.ndarray:
    arr = np.asarray(v, dtype=float)
    if arr.ndim == 0:
        arr = np.full(n, float(arr))
    if arr.shape != (n,) or not np.all(np.isfinite(arr)) or np.any(arr <= 0):
        raise InputError(f"excitation_limits: {name} must be positive: a scalar or a ({n},) array, got {v!r}")
    return arr
