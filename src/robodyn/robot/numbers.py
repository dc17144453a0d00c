"""A robot's description in numbers: what kinematic calibration needs, without SymPy.

A :class:`~robodyn.robot.model.Robot` holds SymPy expressions (named parameters, exact
fractions), which the equations of motion need. Kinematic calibration needs only numbers: the
constant transforms and axes of the chain, the joint limits and gear ratios, the links' masses
and centres of mass (for compliance), gravity and the joint-reading corrections, all at the
description's parameter defaults. :class:`RobotNumbers` holds those; :func:`robot_numbers`
evaluates them from a ``Robot``, and :mod:`robodyn.robot.numbers_cache` keeps them on disk by
the description file's hash, so that ``robodyn calibrate`` on a robot it has seen before reaches
its solver without importing SymPy. :func:`full_robot` gives back the ``Robot`` (loading it
where the numbers came from the cache) for what needs expressions: the calibrated description.

This module imports neither SymPy nor :mod:`robodyn.robot.model` at run time.
"""

from __future__ import annotations

import weakref
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from robodyn.robot.corrections import JointCorrections

if TYPE_CHECKING:
    from robodyn.robot.model import Robot

__all__ = ["RobotNumbers", "full_robot", "robot_numbers"]


@dataclass(frozen=True, eq=False)
class RobotNumbers:
    """A serial robot's constant kinematic and mass data as floats, at its parameter defaults.

    Attributes
    ----------
    name : str
    source : str
        Where the description came from (file path or ``builtin:NAME``).
    joint_names, joint_types : tuple of str, length n
    base : numpy.ndarray, shape (4, 4)
        Pose of the chain's base frame in the world frame.
    pres, posts : numpy.ndarray, shape (n, 4, 4)
        Each joint's constant transforms before and after its motion
        (:class:`~robodyn.robot.model.Joint`).
    axes : numpy.ndarray, shape (n, 3)
        Each joint's axis in its motion frame, as described (not normalised).
    tool : numpy.ndarray, shape (4, 4)
        Pose of the end effector in the last link frame.
    lower, upper : numpy.ndarray, shape (n,)
        Position limits, rad (m); NaN where the description gives none.
    gear_ratios : numpy.ndarray, shape (n,)
        Motor turns per joint turn (1 without a drive).
    masses : numpy.ndarray, shape (n,)
        Link masses, kg.
    coms : numpy.ndarray, shape (n, 3)
        Centres of mass in the link frames, m.
    gravity : numpy.ndarray, shape (3,)
        Gravitational acceleration in the world frame, m/s^2.
    corrections : JointCorrections or None
        The description's joint-reading corrections.
    description_hash : str
        ``Robot.description_hash`` of the description these numbers were evaluated from.
    """

    name: str
    source: str
    joint_names: tuple[str, ...]
    joint_types: tuple[str, ...]
    base: np.ndarray
    pres: np.ndarray
    axes: np.ndarray
    posts: np.ndarray
    tool: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    gear_ratios: np.ndarray
    masses: np.ndarray
    coms: np.ndarray
    gravity: np.ndarray
    corrections: JointCorrections | None
    description_hash: str
    #: how to get the ``Robot`` back (:func:`full_robot`); not part of the data
    loader: Callable[[], Robot] | None = field(default=None, repr=False)

    def __post_init__(self) -> None:
        for name in ("base", "pres", "axes", "posts", "tool", "lower", "upper", "gear_ratios",
                     "masses", "coms", "gravity"):
            a = np.array(getattr(self, name), dtype=float)
            a.setflags(write=False)
            object.__setattr__(self, name, a)
        n = len(self.joint_names)
        shapes = {"pres": (n, 4, 4), "posts": (n, 4, 4), "axes": (n, 3), "base": (4, 4), "tool": (4, 4),
                  "lower": (n,), "upper": (n,), "gear_ratios": (n,), "masses": (n,), "coms": (n, 3),
                  "gravity": (3,)}
        for name, shape in shapes.items():
            if getattr(self, name).shape != shape:
                raise ValueError(f"{self.source}: RobotNumbers.{name} has shape "
                                 f"{getattr(self, name).shape}, expected {shape}")

    @property
    def dof(self) -> int:
        """Number of actuated joints."""
        return len(self.joint_names)


#: numbers already evaluated, by the id of the Robot they came from (a Robot is immutable, and
#: not hashable: its parameters are a mapping), with a weak reference that drops the entry
_EVALUATED: dict[int, tuple[weakref.ref, RobotNumbers]] = {}


def robot_numbers(robot: Robot | RobotNumbers) -> RobotNumbers:
    """The numbers of ``robot`` at its parameter defaults (``robot`` itself if already numbers).

    Evaluated once per ``Robot`` object (SymPy's ``evalf`` after substituting the defaults).
    """
    if isinstance(robot, RobotNumbers):
        return robot
    found = _EVALUATED.get(id(robot))
    if found is not None and found[0]() is robot:
        return found[1]
    subs = robot.defaults()

    def num(expr) -> np.ndarray:
        return np.array(expr.xreplace(subs).evalf(), dtype=float)

    def limit(expr) -> float:
        return float("nan") if expr is None else float(expr.xreplace(subs))

    joints, links = robot.joints, robot.links
    out = RobotNumbers(
        name=robot.name, source=robot.source, joint_names=robot.joint_names,
        joint_types=tuple(j.type for j in joints), base=num(robot.base),
        pres=[num(j.pre) for j in joints], axes=[num(j.axis).ravel() for j in joints],
        posts=[num(j.post) for j in joints], tool=num(robot.tool),
        lower=[limit(j.lower) for j in joints], upper=[limit(j.upper) for j in joints],
        gear_ratios=[float(j.drive.gear_ratio.xreplace(subs)) for j in joints],
        masses=[float(link.mass.xreplace(subs)) for link in links],
        coms=[num(link.com).ravel() for link in links], gravity=num(robot.gravity).ravel(),
        corrections=robot.corrections, description_hash=robot.description_hash,
        loader=weakref.ref(robot))
    key = id(robot)
    _EVALUATED[key] = (weakref.ref(robot, lambda _, key=key: _EVALUATED.pop(key, None)), out)
    return out


def full_robot(robot: Robot | RobotNumbers) -> Robot:
    """The :class:`~robodyn.robot.model.Robot` behind ``robot`` (loaded again where the numbers
    came from the cache; that load imports SymPy).

    Raises
    ------
    ValueError
        The numbers were made in memory and their robot is gone, or the description file changed
        since the numbers were read (its ``description_hash`` differs).
    """
    if not isinstance(robot, RobotNumbers):
        return robot
    full = robot.loader() if robot.loader is not None else None
    if full is None:
        raise ValueError(f"{robot.source}: the robot {robot.name!r} these numbers were evaluated "
                         "from is no longer available; pass the Robot itself")
    if full.description_hash != robot.description_hash:
        raise ValueError(f"{robot.source}: the description changed since robot {robot.name!r} was "
                         "loaded (its hash differs); load it again")
    return full
