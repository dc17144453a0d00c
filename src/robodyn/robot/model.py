"""Immutable robot description: joints, links, drives, friction.

Every numeric field is a SymPy expression: a number, or an expression over the named parameters
the description declares (``Robot.parameters`` holds their default values). Loaders build these
objects; algorithms only read them.

Kinematic convention (one for every description format). The frame of link ``i`` is placed in
the frame of link ``i-1`` (the base frame for ``i = 0``) by::

    T_i(q_i) = pre_i @ motion(axis_i, q_i) @ post_i

where ``pre_i`` and ``post_i`` are constant 4x4 homogeneous transforms and ``motion`` is a rotation
by ``q_i`` about ``axis_i`` (revolute) or a translation by ``q_i`` along it (prismatic); ``axis_i``
is a unit 3-vector in the frame reached after ``pre_i``. Standard DH gives ``pre = I``, ``axis = z``,
``post = Rz(theta0) Tz(d) Tx(a) Rx(alpha)`` (revolute); modified DH gives
``pre = Rx(alpha) Tx(a) Rz(theta0) Tz(d)``, ``post = I``; a URDF joint gives ``pre = origin``,
``post = I``. Each link's inertial data is expressed in its own link frame ``i``.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import TYPE_CHECKING, Any, Literal

import sympy as sp

from robodyn.robot.corrections import JointCorrections
from robodyn.robot.errors import InputError

if TYPE_CHECKING:  # parsed by robodyn.robot.hydro, which reads this module's Robot
    from robodyn.robot.hydro import Fluid, LinkHydro

JointType = Literal["revolute", "prismatic"]

#: The identity transform, shared.
IDENTITY4 = sp.ImmutableMatrix(sp.eye(4))


@dataclass(frozen=True)
class Drive:
    """Actuator drive of one joint.

    Attributes
    ----------
    gear_ratio : sympy.Expr
        Motor angle / joint angle (dimensionless; the sign is kept, only its square or absolute
        value enters the dynamics).
    rotor_inertia : sympy.Expr
        Rotor (motor side) inertia about its axis, kg m^2. Reflected to the joint as
        ``gear_ratio**2 * rotor_inertia``.
    torque_constant : sympy.Expr
        Motor torque per ampere, N m / A (used by later identification stages).
    """

    gear_ratio: sp.Expr = sp.Integer(1)
    rotor_inertia: sp.Expr = sp.Integer(0)
    torque_constant: sp.Expr = sp.Integer(1)


@dataclass(frozen=True)
class Friction:
    """Joint friction, referred to the joint side (loaders reflect motor-side values).

    The friction torque added to the inverse dynamics of joint ``j`` is::

        tau_f = viscous * qd + coulomb_positive * H(qd) - coulomb_negative * H(-qd) + offset

    with ``H`` the Heaviside step (``H(0) = 0``). Both Coulomb levels are non-negative magnitudes.

    Attributes
    ----------
    viscous : sympy.Expr
        N m s / rad (N s / m for prismatic joints).
    coulomb_positive, coulomb_negative : sympy.Expr
        Coulomb friction magnitude when moving in the positive / negative direction, N m (N).
    offset : sympy.Expr
        Constant torque offset, N m (N).
    """

    viscous: sp.Expr = sp.Integer(0)
    coulomb_positive: sp.Expr = sp.Integer(0)
    coulomb_negative: sp.Expr = sp.Integer(0)
    offset: sp.Expr = sp.Integer(0)

    @property
    def is_zero(self) -> bool:
        """True when every coefficient is exactly zero."""
        return all(
            sp.S(v) == 0
            for v in (self.viscous, self.coulomb_positive, self.coulomb_negative, self.offset)
        )


@dataclass(frozen=True)
class Link:
    """Rigid link attached to the child side of a joint.

    Attributes
    ----------
    name : str
    mass : sympy.Expr
        kg.
    com : sympy.ImmutableMatrix, shape (3, 1)
        Centre of mass in the link frame, m.
    inertia : sympy.ImmutableMatrix, shape (3, 3)
        Inertia tensor about the centre of mass, in the link frame axes, kg m^2.
    hydro : LinkHydro or None
        The link's hydrodynamic data (cylinders, coefficients, buoyancy), read from its ``hydro``
        block by :func:`robodyn.robot.hydro.parse_hydro`; None for a dry link.
    """

    name: str
    mass: sp.Expr
    com: sp.ImmutableMatrix
    inertia: sp.ImmutableMatrix
    hydro: LinkHydro | None = None

    @property
    def first_moment(self) -> sp.ImmutableMatrix:
        """``mass * com``, shape (3, 1), kg m."""
        return sp.ImmutableMatrix(self.mass * self.com)

    @property
    def inertia_at_origin(self) -> sp.ImmutableMatrix:
        """Inertia about the link frame origin (parallel axis theorem), shape (3, 3)."""
        c = self.com
        shift = (c.T * c)[0, 0] * sp.eye(3) - c * c.T
        return sp.ImmutableMatrix(self.inertia + self.mass * shift)


@dataclass(frozen=True)
class Joint:
    """One actuated joint and the constant transforms around its motion.

    Attributes
    ----------
    name : str
    type : {"revolute", "prismatic"}
    pre : sympy.ImmutableMatrix, shape (4, 4)
        Constant transform from the parent link frame to the joint's motion frame.
    axis : sympy.ImmutableMatrix, shape (3, 1)
        Unit joint axis in the motion frame.
    post : sympy.ImmutableMatrix, shape (4, 4)
        Constant transform from the moved motion frame to the child link frame.
    lower, upper : sympy.Expr or None
        Position limits, rad (m).
    velocity_limit, effort_limit : sympy.Expr or None
        rad/s (m/s) and N m (N).
    drive : Drive
    friction : Friction
    convention : str
        How the description placed the joint: "dh", "mdh" or "origin".
    source_params : Mapping[str, sympy.Expr]
        The placement numbers as the user gave them (DH a, alpha, d, theta; or xyz/rpy), for display.
    """

    name: str
    type: JointType
    pre: sp.ImmutableMatrix
    axis: sp.ImmutableMatrix
    post: sp.ImmutableMatrix
    lower: sp.Expr | None = None
    upper: sp.Expr | None = None
    velocity_limit: sp.Expr | None = None
    effort_limit: sp.Expr | None = None
    drive: Drive = field(default_factory=Drive)
    friction: Friction = field(default_factory=Friction)
    convention: str = "origin"
    source_params: Mapping[str, sp.Expr] = field(default_factory=lambda: MappingProxyType({}))


@dataclass(frozen=True)
class Robot:
    """A serial manipulator: immutable data, built by :func:`robodyn.load`.

    Attributes
    ----------
    name : str
    joints : tuple of Joint, length n
        Actuated joints from the base outwards (fixed joints are merged at load time).
    links : tuple of Link, length n
        ``links[i]`` moves with ``joints[i]``.
    base : sympy.ImmutableMatrix, shape (4, 4)
        Pose of the chain's base frame in the world frame.
    tool : sympy.ImmutableMatrix, shape (4, 4)
        Pose of the end effector in the last link frame.
    gravity : sympy.ImmutableMatrix, shape (3, 1)
        Gravitational acceleration in the world frame, m/s^2.
    parameters : Mapping[str, float]
        Default values of the named symbolic parameters the description declares.
    source : str
        Where the description came from (file path or ``builtin:NAME``).
    fluid : Fluid or None
        The description's ``fluid`` block (density, current) read by
        :func:`robodyn.robot.hydro.parse_fluid`; None without one (a robot with wet links then
        works in still fresh water: :func:`robodyn.robot.hydro.fluid_of`).
    corrections : JointCorrections or None
        Joint-reading corrections of a kinematic calibration (compliance, transmission errors),
        honoured by forward kinematics (:mod:`robodyn.robot.corrections`); None for a rigid,
        exactly transmitted arm.
    description_hash : str
        SHA-256 of everything above (not an argument: always computed from the content, so a
        copy made with :func:`dataclasses.replace` has its own); compiled models are cached by
        it.
    """

    name: str
    joints: tuple[Joint, ...]
    links: tuple[Link, ...]
    base: sp.ImmutableMatrix = IDENTITY4
    tool: sp.ImmutableMatrix = IDENTITY4
    gravity: sp.ImmutableMatrix = sp.ImmutableMatrix([0, 0, sp.Rational(-981, 100)])
    parameters: Mapping[str, float] = field(default_factory=lambda: MappingProxyType({}))
    source: str = "<memory>"
    fluid: Fluid | None = None
    corrections: JointCorrections | None = None
    description_hash: str = field(init=False, default="")

    def __post_init__(self) -> None:
        if len(self.joints) != len(self.links):
            raise InputError(
                f"{self.source}: robot {self.name!r} has {len(self.joints)} joints but "
                f"{len(self.links)} links; every joint moves exactly one link"
            )
        if self.corrections is not None and len(self.corrections.table) != len(self.joints):
            raise InputError(f"{self.source}: corrections for {len(self.corrections.table)} joints, "
                             f"robot {self.name!r} has {len(self.joints)}")
        if not isinstance(self.parameters, MappingProxyType):
            object.__setattr__(self, "parameters", MappingProxyType(dict(self.parameters)))
        # always from the content: a copy made by dataclasses.replace gets its own hash, so that
        # no cache keyed by it can hand back the model of the robot it was copied from
        digest = hashlib.sha256(_canonical_text(self).encode()).hexdigest()
        object.__setattr__(self, "description_hash", digest)

    @property
    def dof(self) -> int:
        """Number of actuated joints."""
        return len(self.joints)

    @property
    def joint_names(self) -> tuple[str, ...]:
        """Joint names, base outwards."""
        return tuple(j.name for j in self.joints)

    @property
    def symbols(self) -> dict[str, sp.Symbol]:
        """The SymPy symbols of the named parameters, by name."""
        return {name: sp.Symbol(name, real=True) for name in self.parameters}

    def defaults(self) -> dict[sp.Symbol, float]:
        """Substitution map ``{symbol: default value}`` for the named parameters."""
        return {sp.Symbol(k, real=True): float(v) for k, v in self.parameters.items()}


def _canonical_text(robot: Robot) -> str:
    """A deterministic text of everything that defines the robot (for hashing).

    JSON with sorted keys; expressions and matrices enter as their SymPy text, the hydro and
    fluid data field by field.
    """
    joints = [
        {"name": j.name, "type": j.type, "pre": str(j.pre), "axis": str(j.axis),
         "post": str(j.post), "drive": str(j.drive), "friction": str(j.friction),
         "limits": str((j.lower, j.upper))}
        for j in robot.joints
    ]
    links = [
        {"name": link.name, "mass": str(link.mass), "com": str(link.com),
         "inertia": str(link.inertia), "hydro": _plain(link.hydro)}
        for link in robot.links
    ]
    data = {
        "name": robot.name, "base": str(robot.base), "tool": str(robot.tool),
        "gravity": str(robot.gravity),
        "parameters": {k: repr(v) for k, v in robot.parameters.items()},
        "joints": joints, "links": links,
    }
    if robot.fluid is not None:  # only then: hashes of robots without one stay as they were
        data["fluid"] = _plain(robot.fluid)
    if robot.corrections is not None:  # likewise
        data["corrections"] = robot.corrections.as_plain(robot.joint_names)
    return json.dumps(data, sort_keys=True, default=_json_default)


def _plain(value: Any) -> Any:
    """Hydro and fluid data as JSON-ready values: dataclasses field by field, lists for
    sequences, expressions as text (:func:`_json_default`)."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {f.name: _plain(getattr(value, f.name)) for f in dataclasses.fields(value)}
    if isinstance(value, Mapping):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_plain(v) for v in value]
    return value


def _json_default(value: Any) -> str:
    """JSON stand-in for values outside JSON (SymPy numbers, arrays): type and text."""
    return f"{type(value).__name__}:{value!s}"
