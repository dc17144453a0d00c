"""Write a :class:`~robodyn.robot.model.Robot` as a MuJoCo MJCF model.

Kinematics are exact, link frame for link frame: each link is a ``<body>`` placed in its parent
body at ``q = 0`` by ``pre_i @ post_i`` (``pos``, ``quat``), and its joint turns about (slides
along) the line through ``pos = -R^T p`` with direction ``axis = R^T a`` in the body frame, where
``(R, p)`` is ``post_i`` and ``a`` the robodyn axis. This is the MJCF form of
``pre_i @ motion(a, q) @ post_i = (pre_i @ post_i) @ motion about that line`` (MJCF joints have a
position, URDF joints do not). ``Robot.base`` is a static body ``base`` in the world, the tool
frame a ``<site name="tool">`` in the last body, ``Robot.gravity`` the ``<option gravity>``.
Bodies carry the link names (a link called ``world``, MuJoCo's world body, becomes ``world_``;
the base body is ``base``, or ``base_`` when a link has that name).

Dynamics: ``<inertial pos mass fullinertia>`` holds each link's mass, centre of mass and inertia
about the centre of mass in the body frame; ``armature`` the reflected rotor inertia
``gear_ratio^2 * rotor_inertia``; ``damping`` the viscous friction; ``frictionloss`` the Coulomb
friction when it is the same in both directions (MuJoCo's frictionloss is a constraint with that
force bound, which acts like robodyn's ``c * sign(qd)`` while moving). Each joint has a
``<motor gear="1">``, so the control is the joint torque (force), limited to the effort limit
when there is one; position limits become ``range`` with ``limited="true"``. Contacts are
disabled (``<flag contact="disable"/>``): this is a dynamics model without geometry.

MuJoCo rejects massless moving bodies, zero principal moments and inertias that violate the
triangle inequality; :mod:`robodyn.export.inertia` repairs them (floors of 1e-9 kg and 1e-12
kg m^2; a tensor only seen about one axis is replaced by an equivalent one), and
:func:`mjcf_robot` returns the robot the file describes, so it can be compared with MuJoCo.

Dropped, with a :class:`~robodyn.robot.errors.DescriptionWarning`: Coulomb friction with
different levels per direction, friction offsets, one-sided position limits, hydrodynamic link
data, and inertia repairs that change the joint-space dynamics. Dropped silently (no MuJoCo
equivalent, no effect on the dynamics): velocity limits and motor torque constants.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import sympy as sp
from lxml import etree

from robodyn.export import numeric as nm
from robodyn.export.inertia import engine_inertial, rotation_axes
from robodyn.robot.chain import with_parameters
from robodyn.robot.errors import DescriptionWarning, InputError
from robodyn.robot.model import Friction, Joint, Link, Robot

__all__ = ["INTEGRATORS", "mjcf_robot", "to_mjcf"]

#: MJCF ``<option integrator>`` values.
INTEGRATORS = ("Euler", "RK4", "implicit", "implicitfast")

#: Last line of the header comment.
_NOTE = "Bodies are robodyn's link frames; masses and inertias as robodyn.export.mjcf_robot."


def mjcf_robot(robot: Robot, *, parameters: Mapping[str, float] | None = None) -> Robot:
    """The robot :func:`to_mjcf` writes: parameters set, unsupported data dropped, inertias repaired.

    Parameters
    ----------
    robot : Robot
    parameters : Mapping[str, float], optional
        Values (SI units) for some of ``robot.parameters``.

    Returns
    -------
    Robot
        ``robot`` with ``parameters`` as its defaults, every link's mass and inertia as written
        (:mod:`robodyn.export.inertia`; changed links get numeric values), friction as written
        (viscous, and Coulomb only when symmetric), no hydro data and no one-sided limits. Its
        equations of motion are what MuJoCo computes from the file.

    Raises
    ------
    TypeError, ValueError
        As :func:`to_mjcf`.

    Warns
    -----
    DescriptionWarning
        As :func:`to_mjcf`.
    """
    out, notes = _prepare(robot, parameters)
    _warn(robot, notes)
    return out


def to_mjcf(
    robot: Robot,
    path: str | Path | None = None,
    *,
    parameters: Mapping[str, float] | None = None,
    timestep: float = 0.001,
    integrator: str = "RK4",
) -> str:
    """The MuJoCo MJCF document of ``robot``; written to ``path`` too when one is given.

    Parameters
    ----------
    robot : Robot
    path : str or Path, optional
        File to write (UTF-8, overwritten).
    parameters : Mapping[str, float], optional
        Values (SI units) for some of ``robot.parameters``; the others keep their defaults.
    timestep : float
        ``<option timestep>``, s; positive.
    integrator : {"Euler", "RK4", "implicit", "implicitfast"}
        ``<option integrator>``.

    Returns
    -------
    str
        The MJCF (XML) text. MuJoCo's ``mj_fullM``, ``qfrc_bias`` and ``mj_inverse`` on it equal
        robodyn's ``M`` (rotor inertia included), ``g`` and ``tau`` (rigid body, rotor inertia,
        viscous friction) of :func:`mjcf_robot`.

    Raises
    ------
    TypeError
        If ``robot`` is not a :class:`Robot`.
    ValueError
        An unknown parameter, integrator or a non-positive time step, a value that is not a
        finite number, a negative mass, or duplicate joint or link names.
    OSError
        If ``path`` cannot be written; the message names the file.

    Warns
    -----
    DescriptionWarning
        Once per kind of data MJCF cannot hold, and for every inertia repair that changes the
        joint-space dynamics, naming the joints or links.
    """
    if integrator not in INTEGRATORS:
        raise InputError(f"unknown integrator {integrator!r}; choose one of {', '.join(INTEGRATORS)}")
    try:
        step = float(timestep)
    except (TypeError, ValueError):
        raise InputError(f"timestep must be a positive number of seconds, got {timestep!r}") from None
    if not (math.isfinite(step) and step > 0):
        raise InputError(f"timestep must be a positive number of seconds, got {timestep!r}")
    model, notes = _prepare(robot, parameters)
    values = nm.values_of(model)
    root = etree.Element("mujoco", model=robot.name)
    root.append(etree.Comment(nm.header_comment(robot, values, _NOTE)))
    etree.SubElement(root, "compiler", angle="radian", autolimits="true", inertiafromgeom="false")
    option = etree.SubElement(root, "option", timestep=nm.text(step), integrator=integrator,
                              gravity=nm.vector_text(nm.array(model.gravity, values, "gravity")))
    etree.SubElement(option, "flag", contact="disable")
    world = etree.SubElement(root, "worldbody")
    # "world" is MuJoCo's world body: a link of that name becomes body "world_"
    taken = {"world", *(lk.name for lk in model.links)}
    names = [nm.unique_name(lk.name, taken) if lk.name == "world" else lk.name for lk in model.links]
    body = etree.SubElement(world, "body", name=nm.unique_name("base", taken))
    _place(body, nm.array(model.base, values, "base"))
    for k, (joint, link) in enumerate(zip(model.joints, model.links, strict=True)):
        body = _body(body, names[k], joint, link, values, f"{robot.source}: joints[{k}] ({joint.name})")
    site = etree.SubElement(body, "site", name="tool")
    _place(site, nm.array(model.tool, values, "tool"))
    actuators = etree.SubElement(root, "actuator")
    for k, joint in enumerate(model.joints):
        motor = etree.SubElement(actuators, "motor", name=joint.name, joint=joint.name, gear="1")
        if joint.effort_limit is not None:
            effort = abs(nm.number(joint.effort_limit, values, f"{robot.source}: joints[{k}].effort_limit"))
            motor.set("ctrllimited", "true")
            motor.set("ctrlrange", nm.vector_text([-effort, effort]))
    _warn(robot, notes)
    document = etree.tostring(root, pretty_print=True, xml_declaration=True, encoding="UTF-8").decode()
    if path is not None:
        nm.write(document, path, "MJCF")
    return document


# ----------------------------------------------------------------------------------------------
# The robot as written


def _prepare(robot: Robot, parameters: Mapping[str, float] | None) -> tuple[Robot, list[str]]:
    """:func:`mjcf_robot` and the notes on what was dropped or changed."""
    nm.values_of(robot, parameters)  # type and parameter checks, with the robot's names
    nm.check_names(robot)
    if parameters:
        robot = with_parameters(robot, parameters)
    values = nm.values_of(robot)
    dropped: dict[str, list[str]] = {}
    axes = rotation_axes(robot, values)
    joints: list[Joint] = []
    links: list[Link] = []
    for k, (joint, link, axis) in enumerate(zip(robot.joints, robot.links, axes, strict=True)):
        where = f"{robot.source}: joints[{k}] ({joint.name})"
        joints.append(_joint(joint, values, where, dropped))
        links.append(_link(link, axis, values, f"{where}.link", dropped))
    out = replace(robot, joints=tuple(joints), links=tuple(links))
    notes = [f"{_WHY[kind]}: {', '.join(whats)}" for kind, whats in dropped.items()]
    return out, notes


_WHY = {
    "asymmetric Coulomb friction": "Coulomb friction with different levels per direction is dropped "
                                   "(frictionloss is one symmetric level)",
    "friction offset": "friction offsets are dropped (MJCF has no element for them)",
    "one-sided limit": "one-sided position limits are dropped (range needs both bounds)",
    "hydro": "hydrodynamic link data is dropped (not modelled in the MJCF)",
    "inertia": "inertias outside what MuJoCo accepts were changed, which changes the joint-space "
               "dynamics (principal moments before -> after, kg m^2)",
}


def _joint(joint: Joint, values: nm.Values, where: str, dropped: dict[str, list[str]]) -> Joint:
    """The joint with friction and limits as written."""
    f = joint.friction
    c_pos = nm.number(f.coulomb_positive, values, f"{where}.friction.coulomb_positive")
    c_neg = nm.number(f.coulomb_negative, values, f"{where}.friction.coulomb_negative")
    offset = nm.number(f.offset, values, f"{where}.friction.offset")
    fields: dict[str, Any] = {}
    if c_pos != c_neg:
        dropped.setdefault("asymmetric Coulomb friction", []).append(
            f"{joint.name} (+{nm.text(c_pos)}/-{nm.text(c_neg)})")
    if offset != 0.0:
        dropped.setdefault("friction offset", []).append(f"{joint.name} ({nm.text(offset)})")
    if c_pos != c_neg or offset != 0.0:
        coulomb = f.coulomb_positive if c_pos == c_neg else sp.Integer(0)
        fields["friction"] = Friction(viscous=f.viscous, coulomb_positive=coulomb, coulomb_negative=coulomb)
    if (joint.lower is None) != (joint.upper is None):
        dropped.setdefault("one-sided limit", []).append(joint.name)
        fields.update(lower=None, upper=None)
    return replace(joint, **fields) if fields else joint


def _link(link: Link, axis: np.ndarray | None, values: nm.Values, where: str,
          dropped: dict[str, list[str]]) -> Link:
    """The link with a mass and inertia MuJoCo accepts, and without hydro data."""
    mass = nm.number(link.mass, values, f"{where}.mass")
    if mass < 0:
        raise InputError(f"{where}.mass: negative mass {nm.text(mass)} kg")
    fixed = engine_inertial(mass, nm.array(link.inertia, values, f"{where}.inertia"), axis)
    if link.hydro:
        dropped.setdefault("hydro", []).append(link.name)
        link = replace(link, hydro=None)
    if not fixed.changed:
        return link
    if not fixed.equivalent:
        before, after = (nm.vector_text(np.round(m, 12)) for m in (fixed.moments_before, fixed.moments_after))
        dropped.setdefault("inertia", []).append(f"{link.name} ({before} -> {after})")
    inertia = sp.ImmutableMatrix(3, 3, [sp.Float(v) if v != 0 else sp.Integer(0)
                                        for v in fixed.inertia.ravel()])
    new_mass = link.mass if fixed.mass == mass else sp.Float(fixed.mass)
    return replace(link, mass=new_mass, inertia=inertia)


def _warn(robot: Robot, notes: list[str]) -> None:
    for note in notes:
        warnings.warn(f"{robot.source}: MJCF export of {robot.name!r}: {note}", DescriptionWarning,
                      stacklevel=3)


# ----------------------------------------------------------------------------------------------
# Elements


def _place(element: Any, pose: np.ndarray) -> None:
    """``pos`` and ``quat`` (w, x, y, z) of a homogeneous transform, shape (4, 4)."""
    element.set("pos", nm.vector_text(pose[:3, 3]))
    element.set("quat", nm.vector_text(nm.quaternion(pose[:3, :3])))


def _body(parent: Any, name: str, joint: Joint, link: Link, values: nm.Values, where: str) -> Any:
    """One link's ``<body name>`` with its ``<joint>`` and ``<inertial>``, inside ``parent``."""
    pre = nm.exact(joint.pre, values, f"{where}.pre")
    post = nm.exact(joint.post, values, f"{where}.post")
    body = etree.SubElement(parent, "body", name=name)
    _place(body, np.array((pre * post).tolist(), dtype=float))
    r, p = post[:3, :3], post[:3, 3]
    axis = nm.exact(joint.axis, values, f"{where}.axis")
    # pre motion(a, q) post = (pre post) motion(R^T a, q) about the line through -R^T p
    element = etree.SubElement(body, "joint", name=joint.name,
                               type="hinge" if joint.type == "revolute" else "slide")
    if joint.type == "revolute":
        element.set("pos", nm.vector_text(np.array((-r.T * p).tolist(), dtype=float)))
    element.set("axis", nm.vector_text(np.array((r.T * axis).tolist(), dtype=float)))
    if joint.lower is not None and joint.upper is not None:
        element.set("limited", "true")
        element.set("range", nm.vector_text([nm.number(joint.lower, values, f"{where}.lower"),
                                             nm.number(joint.upper, values, f"{where}.upper")]))
    d, f = joint.drive, joint.friction
    armature = nm.number(d.gear_ratio**2 * d.rotor_inertia, values, f"{where}.drive")
    for key, value in (("armature", armature),
                       ("damping", nm.number(f.viscous, values, f"{where}.friction.viscous")),
                       ("frictionloss", nm.number(f.coulomb_positive, values, f"{where}.friction"))):
        if value != 0.0:
            element.set(key, nm.text(value))
    inertia = nm.array(link.inertia, values, f"{where}.link.inertia")
    etree.SubElement(
        body, "inertial",
        pos=nm.vector_text(nm.array(link.com, values, f"{where}.link.com")),
        mass=nm.text(nm.number(link.mass, values, f"{where}.link.mass")),
        fullinertia=nm.vector_text([inertia[0, 0], inertia[1, 1], inertia[2, 2],
                                    inertia[0, 1], inertia[0, 2], inertia[1, 2]]),
    )
    return body
