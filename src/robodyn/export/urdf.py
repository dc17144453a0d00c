"""Write a :class:`~robodyn.robot.model.Robot` as a URDF file.

Kinematics. A robodyn joint places its link frame by ``T_i(q) = pre_i @ motion(axis_i, q) @ post_i``
(see :mod:`robodyn.robot.model`), a URDF joint by ``origin_i @ motion(axis_i, q)``: the URDF link
frame is the joint frame, and a revolute URDF joint turns about an axis through the origin of its
child link frame. A robodyn link frame that is offset from its joint axis (standard DH: ``post_i``
holds ``Tx(a) Rx(alpha)``) therefore has no URDF joint of its own. The writer moves each
non-identity ``post_i`` outwards, as :mod:`robodyn.robot.yaml_writer` does:

* into the next joint's origin, ``origin_{i+1} = post_i @ pre_{i+1}``, or into the tool joint
  after the last joint, ``post_n @ tool``;
* into link ``i``'s inertial data, re-expressed in the URDF link frame ``pre_i @ motion_i`` (the
  frame before ``post_i``): ``com' = R c + p``, ``inertia' = R I R^T`` with ``(R, p)`` of
  ``post_i``.

So URDF link ``i`` is robodyn's frame ``T_{i-1} @ pre_i @ motion_i(q)``, which is robodyn's link
frame ``i`` exactly when ``post_i`` is the identity (origin-form and modified-DH descriptions) and
``link_i @ inv(post_i)`` otherwise; every mass, centre of mass and inertia is the same in world
terms, and so are the tool frame and the joint-space dynamics. Loading the file with
:func:`robodyn.load` gives a robot with ``post = I`` and these frames as link frames.

Document layout (names made unique by appending ``_`` where a robot link is called so)::

    world --(fixed: robot.base)--> base --(joint 1)--> link 1 ... --(joint n)--> link n
          --(fixed: post_n @ robot.tool)--> tool (massless)

robodyn's URDF loader folds the leading fixed joint into ``Robot.base`` and the trailing fixed
joint with its massless link into ``Robot.tool``.

What URDF cannot hold is dropped with a :class:`~robodyn.robot.errors.DescriptionWarning`:
gravity other than ``(0, 0, -9.81)`` m/s^2 (URDF has no gravity; readers assume that one), drive
data (gear ratio, rotor inertia: the reflected rotor inertia ``G^2 J_m`` leaves the mass matrix;
torque constant), Coulomb friction with different levels in the two directions, friction offsets,
a position limit on one side only, and link ``hydro`` data. Viscous friction becomes
``<dynamics damping>``, symmetric Coulomb friction ``<dynamics friction>``. ``<limit>`` carries
``lower``/``upper`` when both are known (a revolute joint without them is ``continuous``) and
always ``effort`` and ``velocity``, which URDF requires: ``0`` where the robot gives none.
Symbolic parameters are replaced by their values; the values used are listed in a comment.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import sympy as sp
from lxml import etree

from robodyn.export import numeric as nm
from robodyn.robot.errors import DescriptionWarning
from robodyn.robot.model import Joint, Link, Robot

__all__ = ["URDF_GRAVITY", "to_urdf"]

#: The gravity URDF readers assume (URDF cannot state one), m/s^2, world frame.
URDF_GRAVITY = (0.0, 0.0, -9.81)

#: Last line of the header comment.
_NOTE = "Joint origins and link frames: see robodyn.export.urdf."


def to_urdf(
    robot: Robot,
    path: str | Path | None = None,
    *,
    parameters: Mapping[str, float] | None = None,
) -> str:
    """The URDF document of ``robot``; written to ``path`` too when one is given.

    Parameters
    ----------
    robot : Robot
        Any robot (built in, from YAML or from URDF).
    path : str or Path, optional
        File to write (UTF-8, overwritten).
    parameters : Mapping[str, float], optional
        Values (SI units) for some of ``robot.parameters``; the others keep their defaults.

    Returns
    -------
    str
        The URDF (XML) text. :func:`robodyn.load` of it gives the same joint-space dynamics
        (mass matrix without rotor inertia, gravity, rigid-body inverse dynamics, viscous and
        symmetric Coulomb friction), the same tool pose and the same pose of every joint frame
        (module docstring).

    Raises
    ------
    TypeError
        If ``robot`` is not a :class:`Robot`.
    ValueError
        An unknown parameter name, a value that is not a finite number (or depends on an
        undeclared symbol), or duplicate joint or link names.
    OSError
        If ``path`` cannot be written; the message names the file.

    Warns
    -----
    DescriptionWarning
        Once per kind of data URDF cannot hold, naming the joints or links it is dropped from.
    """
    values = nm.values_of(robot, parameters)
    nm.check_names(robot)
    dropped = _Dropped()
    taken = {lk.name for lk in robot.links}
    world, base, tool = (nm.unique_name(n, taken) for n in ("world", "base", "tool"))
    joint_names = set(robot.joint_names)
    base_joint, tool_joint = (nm.unique_name(n, joint_names) for n in ("base_joint", "tool_joint"))

    root = etree.Element("robot", name=robot.name)
    root.append(etree.Comment(nm.header_comment(robot, values, _NOTE)))
    _link_element(root, world)
    _fixed_joint(root, base_joint, world, base, nm.array(robot.base, values, "base"))
    _link_element(root, base)
    carry = sp.eye(4)  # post of the previous joint, not written yet (30-digit numbers)
    parent = base
    for k, (joint, link) in enumerate(zip(robot.joints, robot.links, strict=True)):
        where = f"{robot.source}: joints[{k}] ({joint.name})"
        origin = carry * nm.exact(joint.pre, values, f"{where}.pre")
        post = nm.exact(joint.post, values, f"{where}.post")
        _joint_element(root, joint, parent, link.name, origin, values, where, dropped)
        _link_element(root, link.name, _inertial(link, post, values, f"{where}.link"))
        if link.hydro:
            dropped.add("hydro", link.name)
        carry = post
        parent = link.name
    tool_pose = carry * nm.exact(robot.tool, values, "tool")
    _fixed_joint(root, tool_joint, parent, tool, _floats(tool_pose))
    _link_element(root, tool)

    gravity = nm.array(robot.gravity, values, "gravity").ravel()
    if not np.array_equal(gravity, np.array(URDF_GRAVITY)):
        dropped.notes.append(
            f"gravity {nm.vector_text(gravity)} m/s^2 is not written (URDF has no gravity; "
            f"readers assume {nm.vector_text(URDF_GRAVITY)})"
        )
    if robot.corrections is not None:
        note = ("joint-reading corrections (compliance, transmission errors of a calibration) are "
                "not written: URDF has no element for them, so this file's forward kinematics are "
                "those of the geometry alone; the robodyn YAML description keeps them")
        dropped.notes.append(note)
        root.insert(1, etree.Comment(" " + note + " "))
    dropped.warn(robot)
    document = etree.tostring(root, pretty_print=True, xml_declaration=True, encoding="UTF-8").decode()
    if path is not None:
        nm.write(document, path, "URDF")
    return document


# ----------------------------------------------------------------------------------------------
# Elements


def _floats(m: sp.MatrixBase) -> np.ndarray:
    """A numeric SymPy matrix as a float array of the same shape."""
    return np.array(sp.Matrix(m).tolist(), dtype=float)


def _origin(parent: Any, pose: np.ndarray) -> None:
    """``<origin xyz rpy>`` of a homogeneous transform, shape (4, 4)."""
    etree.SubElement(parent, "origin", xyz=nm.vector_text(pose[:3, 3]),
                     rpy=nm.vector_text(nm.rpy(pose[:3, :3])))


def _link_element(root: Any, name: str, inertial: tuple[float, np.ndarray, np.ndarray] | None = None) -> None:
    """``<link>``, with ``<inertial>`` (COM frame axes = link frame axes) when given."""
    link = etree.SubElement(root, "link", name=name)
    if inertial is None:
        return
    mass, com, inertia = inertial
    element = etree.SubElement(link, "inertial")
    etree.SubElement(element, "origin", xyz=nm.vector_text(com), rpy="0 0 0")
    etree.SubElement(element, "mass", value=nm.text(mass))
    keys = {"ixx": (0, 0), "ixy": (0, 1), "ixz": (0, 2), "iyy": (1, 1), "iyz": (1, 2), "izz": (2, 2)}
    etree.SubElement(element, "inertia", {k: nm.text(inertia[rc]) for k, rc in keys.items()})


def _fixed_joint(root: Any, name: str, parent: str, child: str, pose: np.ndarray) -> None:
    """A fixed ``<joint>`` placing ``child`` at ``pose`` in ``parent``."""
    joint = etree.SubElement(root, "joint", name=name, type="fixed")
    _origin(joint, pose)
    etree.SubElement(joint, "parent", link=parent)
    etree.SubElement(joint, "child", link=child)


def _inertial(
    link: Link, post: sp.Matrix, values: nm.Values, where: str
) -> tuple[float, np.ndarray, np.ndarray] | None:
    """Mass, COM and inertia about the COM in the URDF link frame (before ``post``); None if empty."""
    mass = nm.exact(link.mass, values, f"{where}.mass")
    com = nm.exact(link.com, values, f"{where}.com")
    inertia = nm.exact(link.inertia, values, f"{where}.inertia")
    r, p = post[:3, :3], post[:3, 3]
    # com' = R c + p,  I' = R I R^T: the same body seen from the frame before post
    com, inertia = r * com + p, r * inertia * r.T
    inertia_f = _floats(inertia)
    inertia_f = np.triu(inertia_f) + np.triu(inertia_f, 1).T  # symmetric: the upper triangle
    if float(mass) == 0.0 and not inertia_f.any():
        return None
    return float(mass), _floats(com).ravel(), inertia_f


def _joint_element(
    root: Any,
    joint: Joint,
    parent: str,
    child: str,
    origin: sp.Matrix,
    values: nm.Values,
    where: str,
    dropped: _Dropped,
) -> None:
    """One moving ``<joint>``: origin, axis, limits, dynamics."""
    bound = {key: (None if getattr(joint, key) is None
                   else nm.number(getattr(joint, key), values, f"{where}.{key}"))
             for key in ("lower", "upper", "velocity_limit", "effort_limit")}
    has_range = bound["lower"] is not None and bound["upper"] is not None
    if (bound["lower"] is None) != (bound["upper"] is None):
        dropped.add("one-sided limit", joint.name)
    kind = joint.type if joint.type == "prismatic" or has_range else "continuous"
    element = etree.SubElement(root, "joint", name=joint.name, type=kind)
    _origin(element, _floats(origin))
    etree.SubElement(element, "parent", link=parent)
    etree.SubElement(element, "child", link=child)
    axis = nm.array(joint.axis, values, f"{where}.axis").ravel()
    etree.SubElement(element, "axis", xyz=nm.vector_text(axis))
    if kind != "continuous" or bound["velocity_limit"] is not None or bound["effort_limit"] is not None:
        limit = etree.SubElement(element, "limit")
        if has_range:
            limit.set("lower", nm.text(bound["lower"]))
            limit.set("upper", nm.text(bound["upper"]))
        limit.set("effort", nm.text(bound["effort_limit"] or 0.0))
        limit.set("velocity", nm.text(bound["velocity_limit"] or 0.0))
    _dynamics(element, joint, values, where, dropped)


def _dynamics(element: Any, joint: Joint, values: nm.Values, where: str, dropped: _Dropped) -> None:
    """``<dynamics damping friction>`` for what maps exactly; the rest is noted as dropped."""
    f, d = joint.friction, joint.drive
    viscous = nm.number(f.viscous, values, f"{where}.friction.viscous")
    c_pos = nm.number(f.coulomb_positive, values, f"{where}.friction.coulomb_positive")
    c_neg = nm.number(f.coulomb_negative, values, f"{where}.friction.coulomb_negative")
    offset = nm.number(f.offset, values, f"{where}.friction.offset")
    coulomb = c_pos if c_pos == c_neg else 0.0
    if c_pos != c_neg:
        dropped.add("asymmetric Coulomb friction", f"{joint.name} (+{nm.text(c_pos)}/-{nm.text(c_neg)})")
    if offset != 0.0:
        dropped.add("friction offset", f"{joint.name} ({nm.text(offset)})")
    if viscous != 0.0 or coulomb != 0.0:
        etree.SubElement(element, "dynamics", damping=nm.text(viscous), friction=nm.text(coulomb))
    drive = [nm.number(v, values, f"{where}.drive")
             for v in (d.gear_ratio, d.rotor_inertia, d.torque_constant)]
    if drive != [1.0, 0.0, 1.0]:
        g, jm, kt = (nm.text(v) for v in drive)
        dropped.add("drive", f"{joint.name} (gear_ratio={g}, rotor_inertia={jm}, torque_constant={kt})")


class _Dropped:
    """Collects what the document cannot hold, for one warning per kind."""

    _WHY = {
        "drive": "drive data is dropped (URDF has no element for it; the reflected rotor inertia "
                 "G^2 Jm no longer adds to the mass matrix)",
        "asymmetric Coulomb friction": "Coulomb friction with different levels per direction is "
                                       "dropped (<dynamics friction> is one symmetric level)",
        "friction offset": "friction offsets are dropped (URDF has no element for them)",
        "one-sided limit": "one-sided position limits are dropped (URDF needs both lower and upper)",
        "hydro": "hydrodynamic link data is dropped (URDF has no element for it)",
    }

    def __init__(self) -> None:
        self.items: dict[str, list[str]] = {}
        self.notes: list[str] = []

    def add(self, kind: str, what: str) -> None:
        self.items.setdefault(kind, []).append(what)

    def warn(self, robot: Robot) -> None:
        for kind, whats in self.items.items():
            self.notes.append(f"{self._WHY[kind]}: {', '.join(whats)}")
        for note in self.notes:
            warnings.warn(f"{robot.source}: URDF export of {robot.name!r}: {note}",
                          DescriptionWarning, stacklevel=3)
