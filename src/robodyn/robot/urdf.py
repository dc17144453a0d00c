"""Read a URDF file whose moving joints form a serial chain into a :class:`~robodyn.robot.model.Robot`.

The file is parsed by the maintained URDF parser `yourdfpy`_ (the ``urdf`` extra,
``pip install 'robodyn[urdf]'``; meshes and scene graphs are not loaded); this module only maps
its model onto robodyn's convention::

    T_i(q_i) = origin_i @ motion(axis_i, q_i)          (pre = origin, post = I)

URDF joint ``i``'s ``<origin xyz rpy>`` places the joint frame, which is the child link's frame,
in the parent link's frame; ``<axis>`` is expressed in the joint frame. ``continuous`` joints
are revolute joints without position limits.

Files as ROS-Industrial and robot makers publish them load: blank lines before the XML
declaration are ignored, and the links may form a tree as long as every moving joint lies on one
path from the root link (a ``world`` root, the REP-103 ``base`` frame, ``flange``, ``tool0``,
``ee_link`` and sensor frames hang off that path on fixed joints). The chain is the path from
the root to the *tool link*: ``tool=`` names it; by default it is the end of the unbranched run
of fixed joints after the last moving joint, or the last moving link itself when that run
branches (``ee_link`` and ``tool0`` both fixed to the last link). Fixed joints on the chain are
merged by :func:`robodyn.robot.chain.assemble` (the child's mass is added to its parent, or
carried by the ground before the first moving joint; the fixed transforms after the last moving
joint become the tool frame). Fixed side branches add their mass and inertia to the chain link
they are welded to; frames without ``<inertial>`` add nothing.

Movable trees (two moving joints on different branches, e.g. gripper fingers), ``floating`` and
``planar`` joints and ``<mimic>`` joints raise :class:`~robodyn.robot.errors.DescriptionError`,
unless ``locked=`` holds the extra joints still: a locked joint becomes a fixed joint at the given
position (``origin @ motion(axis, value)``, as Pinocchio's ``buildReducedModel`` does), and a
``<mimic>`` joint of a locked joint is locked with it at ``multiplier x value + offset``.
A link without ``<inertial>`` has zero mass; when that leaves a moving joint that moves no
inertia (a singular mass matrix), a :class:`~robodyn.robot.errors.DescriptionWarning` names the
joint and the links (an error under ``strict=True``).

Numbers are kept as the file gives them: each becomes ``sympy.Float(x)`` (full double
precision), except exact zeros and exact ``+-1``, which become SymPy integers so the symbolic
equations fold. Inertial data: ``<inertial><origin xyz rpy>`` places the centre-of-mass frame in
the link frame, and ``<inertia>`` is about the centre of mass in that frame's axes, so the
link-frame inertia is ``R @ I @ R.T`` with ``R = rpy_to_matrix(rpy)`` and ``com = xyz``. A link
without ``<inertial>`` has zero mass. ``<dynamics damping friction>`` becomes
``Friction(viscous=damping, coulomb_positive=friction, coulomb_negative=friction)``.

.. _yourdfpy: https://github.com/clemense/yourdfpy
"""

from __future__ import annotations

import io
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import sympy as sp
from lxml import etree

from robodyn import spatial as S
from robodyn.robot import placement, validation
from robodyn.robot.chain import ChainElement, assemble, combine_links
from robodyn.robot.errors import DescriptionError
from robodyn.robot.model import Friction, Link, Robot
from robodyn.robot.optional import require

if TYPE_CHECKING:
    import yourdfpy

__all__ = ["load_urdf", "number"]

_SUPPORTED = ("revolute", "continuous", "prismatic", "fixed")
_NOT_YET = ("floating", "planar")
_Z_AXIS = sp.ImmutableMatrix([0, 0, 1])


def number(x: float | str, *, where: str) -> sp.Expr:
    """A URDF number as SymPy: ``Integer`` for exact ``0`` and ``+-1``, else ``Float(x)``.

    Parameters
    ----------
    x : float or str
        The value as read (a string is converted with :func:`float`).
    where : str
        File and field used in the error message.

    Returns
    -------
    sympy.Expr

    Raises
    ------
    DescriptionError
        If the value is not a finite number.
    """
    try:
        v = float(x)
    except (TypeError, ValueError):
        raise DescriptionError(f"{where}: expected a number, got {x!r}") from None
    if not math.isfinite(v):
        raise DescriptionError(f"{where}: expected a finite number, got {x!r}")
    if v == 0.0:
        return sp.Integer(0)
    if v in (1.0, -1.0):
        return sp.Integer(int(v))
    return sp.Float(v)


def load_urdf(path: str | Path, *, strict: bool = False, tool: str | None = None,
              locked: Mapping[str, float] | None = None) -> Robot:
    """Load a URDF file whose moving joints form a serial chain.

    Parameters
    ----------
    path : str or Path
        The ``.urdf`` file.
    strict : bool
        Turn physical-plausibility warnings (implausible inertia, singular mass matrix) into
        :class:`DescriptionError`.
    tool : str, optional
        Name of the link whose frame is the end effector (``Robot.tool``, the pose
        ``model.forward_kinematics`` returns), e.g. ``"tool0"`` or ``"flange"``; it must lie
        beyond the last moving joint. By default: the end of the unbranched run of fixed joints
        after the last moving joint, or the last moving link itself when that run branches
        (e.g. ``ee_link`` and ``tool0`` both fixed to the last link).
    locked : mapping of str to float, optional
        Moving joints held still at the given position (rad for ``revolute`` and ``continuous``,
        m for ``prismatic``) and treated as fixed, e.g. a gripper's fingers; the robot's joints
        are the others. A ``<mimic>`` joint that follows a locked joint is locked with it.

    Returns
    -------
    Robot
        Named after ``<robot name>``; ``source`` is ``str(path)``; default gravity
        ``(0, 0, -9.81)`` m/s^2; no named parameters.

    Raises
    ------
    DescriptionError
        The file is not well-formed XML or not a URDF, a number is missing or not finite, a
        joint refers to an undefined link, the links do not form one tree (several roots, a
        loop), the moving joints do not lie on one path from the root (a branching movable
        tree), a joint is ``floating``, ``planar`` or a ``<mimic>`` joint, a moving joint has a
        zero axis, there is no moving joint, ``tool`` is not a link beyond the last moving
        joint, or a ``locked`` joint is not a moving joint of the file or its position is not a
        finite number within the joint's limits. Every message starts with the file name and
        names the joint or link at fault.
    FileNotFoundError
        If ``path`` does not exist.

    Warns
    -----
    DescriptionWarning
        A link's inertia is implausible, or the mass matrix is singular because a moving
        joint moves no inertia (e.g. the links it carries have no ``<inertial>``); the
        message names the joint and the links.
    """
    path = Path(path)
    name = str(path)
    # blank lines before the XML declaration are common in pasted and generated files
    data = path.read_bytes().lstrip(b" \t\r\n")
    root = _parse_xml(data, name)
    urdf_parser = require("yourdfpy", f"reading the URDF file {name}")
    try:
        model = urdf_parser.URDF.load(
            io.BytesIO(data),
            load_meshes=False,
            build_scene_graph=False,
            build_collision_scene_graph=False,
            load_collision_meshes=False,
        ).robot
    except Exception as exc:  # yourdfpy raises bare KeyError/AttributeError/ValueError
        reason = f"{type(exc).__name__}: {exc}"
        raise DescriptionError(f"{name}: not a readable URDF file: {reason}") from None

    joint_xml = {j.get("name"): j for j in root.findall("joint")}
    link_xml = {lk.get("name"): lk for lk in root.findall("link")}
    _check_names(model, name)
    lock = _locked_positions(model, locked or {}, name)
    chain, side = _serial_chain(model, name, tool, lock)
    bodies: dict[str, Link] = {}
    for lk in model.links:
        where = f"{name}: links.{lk.name}"
        bodies[lk.name] = _link(lk, link_xml[lk.name], where)
        validation.check_link(bodies[lk.name], where=where, strict=strict, defaults={})
    chain_links = {chain[0].parent} | {j.child for j in chain}
    bodies = _merge_side_branches(bodies, side, chain_links, joint_xml, name, lock)
    elements = [_element(j, joint_xml[j.name], bodies[j.child], name, lock.get(j.name))
                for j in chain]
    try:
        robot = assemble(model.name, elements, source=name)
    except ValueError as exc:
        raise DescriptionError(str(exc)) from None
    validation.check_mass_matrix(robot, where=name, strict=strict, missing=_no_inertial(model))
    return robot


def _no_inertial(model: yourdfpy.Robot) -> frozenset[str]:
    """Names of the links without an ``<inertial>`` element."""
    return frozenset(lk.name for lk in model.links if lk.inertial is None)


def _parse_xml(data: bytes, name: str) -> Any:
    """Parse the file strictly (no recovery, no entities, no network); the root element."""
    parser = etree.XMLParser(resolve_entities=False, no_network=True, remove_blank_text=True)
    try:
        root = etree.fromstring(data, parser=parser)
    except etree.XMLSyntaxError as exc:
        raise DescriptionError(f"{name}: not a parseable URDF (XML) file: {exc}") from None
    if root.getroottree().docinfo.internalDTD is not None:
        raise DescriptionError(
            f"{name}: DTD and entity declarations are not supported in URDF files"
        )
    if root.tag != "robot":
        raise DescriptionError(
            f"{name}: not a URDF file: the root element is <{root.tag}>, not <robot>"
        )
    if not root.get("name"):
        raise DescriptionError(f"{name}: the <robot> element has no 'name' attribute")
    for tag in ("link", "joint"):
        for k, elem in enumerate(root.findall(tag)):
            if not elem.get("name"):
                raise DescriptionError(f"{name}: <{tag}> number {k + 1} has no 'name' attribute")
    for elem in root.findall("joint"):
        for role in ("parent", "child"):
            ref = elem.find(role)
            if ref is None or not ref.get("link"):
                raise DescriptionError(
                    f"{name}: joint {elem.get('name')!r} has no <{role} link=...> element"
                )
    return root


def _check_names(model: yourdfpy.Robot, name: str) -> None:
    """Reject duplicate link or joint names and joints that refer to undefined links."""
    links: dict[str, yourdfpy.Link] = {}
    for lk in model.links:
        if lk.name in links:
            raise DescriptionError(f"{name}: link {lk.name!r} is defined twice")
        links[lk.name] = lk
    seen: set[str] = set()
    for j in model.joints:
        if j.name in seen:
            raise DescriptionError(f"{name}: joint {j.name!r} is defined twice")
        seen.add(j.name)
        for role, ref in (("parent", j.parent), ("child", j.child)):
            if ref not in links:
                raise DescriptionError(
                    f"{name}: joint {j.name!r}: {role} link {ref!r} is not defined"
                )


def _check_joint_types(model: yourdfpy.Robot, name: str, lock: Mapping[str, sp.Expr]) -> None:
    """Reject unknown, floating, planar and ``<mimic>`` joints (unless locked), naming the joint."""
    if not model.joints:
        raise DescriptionError(
            f"{name}: robot {model.name!r} has no joints (a serial chain needs at least one)"
        )
    for j in model.joints:
        if j.type in _NOT_YET:
            raise DescriptionError(
                f"{name}: joint {j.name!r}: joint type {j.type!r} is not supported yet "
                f"(supported: {', '.join(_SUPPORTED)})"
            )
        if j.type not in _SUPPORTED:
            raise DescriptionError(
                f"{name}: joint {j.name!r}: unknown joint type {j.type!r} "
                f"(supported: {', '.join(_SUPPORTED)})"
            )
        if j.mimic is not None and j.name not in lock:
            raise DescriptionError(
                f"{name}: joint {j.name!r}: <mimic> joints (coupled to joint {j.mimic.joint!r}) "
                "are not supported yet (a gripper's: hold it or the joint it mimics still, "
                "rd.load(..., locked=...) or --lock)"
            )


def _tree(model: yourdfpy.Robot, name: str) -> tuple[str, dict[str, yourdfpy.Joint],
                                                     dict[str, list[yourdfpy.Joint]]]:
    """The root link, each link's parent joint and each link's child joints (file order).

    Raises unless the links form one tree: a link that is the child of two joints, several
    root links, or a loop.
    """
    parent_joint: dict[str, yourdfpy.Joint] = {}
    children: dict[str, list[yourdfpy.Joint]] = {}
    for j in model.joints:
        if j.child in parent_joint:
            raise DescriptionError(
                f"{name}: link {j.child!r} is the child of two joints "
                f"({parent_joint[j.child].name!r} and {j.name!r}); not a tree"
            )
        parent_joint[j.child] = j
        children.setdefault(j.parent, []).append(j)
    roots = [lk.name for lk in model.links if lk.name not in parent_joint]
    if len(roots) != 1:
        what = "no root link (the joints form a loop)" if not roots else f"{len(roots)} root links"
        listed = f" ({', '.join(map(repr, roots))})" if roots else ""
        raise DescriptionError(f"{name}: {what}{listed}; a serial chain has exactly one root link")
    reached = {roots[0]}
    stack = [roots[0]]
    while stack:
        for j in children.get(stack.pop(), []):
            reached.add(j.child)
            stack.append(j.child)
    if len(reached) != len(model.links):
        missing = sorted({j.name for j in model.joints if j.child not in reached})
        raise DescriptionError(
            f"{name}: joints {missing} are not connected to the tree from root link "
            f"{roots[0]!r} (they form a loop)"
        )
    return roots[0], parent_joint, children


def _path(link: str, parent_joint: Mapping[str, yourdfpy.Joint]) -> list[yourdfpy.Joint]:
    """The joints from the root link to ``link``, root first."""
    out: list[yourdfpy.Joint] = []
    while link in parent_joint:
        out.append(parent_joint[link])
        link = out[-1].parent
    return out[::-1]


def _serial_chain(
    model: yourdfpy.Robot, name: str, tool: str | None, lock: Mapping[str, sp.Expr]
) -> tuple[list[yourdfpy.Joint], list[yourdfpy.Joint]]:
    """The joints from the root link to the tool link, and the fixed joints off that path.

    The moving joints must all lie on one path from the root; fixed side branches (``base``,
    ``tool0``, sensor frames) may hang anywhere. The tool link is ``tool`` when given (it must
    lie beyond the last moving joint), else the end of the unbranched run of fixed joints after
    the last moving joint (the last moving link itself when that run branches).
    """
    _check_joint_types(model, name, lock)
    root, parent_joint, children = _tree(model, name)
    moving = [j for j in model.joints if j.type != "fixed" and j.name not in lock]
    if not moving:
        raise DescriptionError(f"{name}: robot {model.name!r} has no moving joint")
    paths = {j.name: _path(j.child, parent_joint) for j in moving}
    last = max(moving, key=lambda j: len(paths[j.name]))
    on_path = {j.name for j in paths[last.name]}
    for j in moving:
        if j.name not in on_path:
            _raise_branching(name, paths[j.name], paths[last.name], children, j, last)
    if tool is None:
        end = last.child
        while len(children.get(end, [])) == 1:
            end = children[end][0].child
    else:
        end = _tool_link(model, name, tool, last, parent_joint)
    chain = _path(end, parent_joint)
    chain_names = {j.name for j in chain}
    side = [j for j in model.joints if j.name not in chain_names]
    return chain, side


def _raise_branching(name: str, a: list[yourdfpy.Joint], b: list[yourdfpy.Joint],
                     children: Mapping[str, list[yourdfpy.Joint]],
                     ja: yourdfpy.Joint, jb: yourdfpy.Joint) -> None:
    """Name the link where the paths to moving joints ``ja`` and ``jb`` part."""
    k = 0
    while k < min(len(a), len(b)) and a[k].name == b[k].name:
        k += 1
    link = a[k].parent
    branches = [c.name for c in children[link]]
    raise DescriptionError(
        f"{name}: link {link!r} has {len(branches)} child joints "
        f"({', '.join(map(repr, branches))}) leading to the moving joints {ja.name!r} and "
        f"{jb.name!r}: branching trees are not supported, only serial chains (fixed side "
        "branches are; hold the extra joints still: rd.load(..., locked=...) or --lock, e.g. a "
        "gripper's fingers)"
    )


def _tool_link(model: yourdfpy.Robot, name: str, tool: str, last: yourdfpy.Joint,
               parent_joint: Mapping[str, yourdfpy.Joint]) -> str:
    """Check that link ``tool`` exists and lies beyond the last moving joint ``last``."""
    beyond = sorted(lk.name for lk in model.links
                    if last.name in {j.name for j in _path(lk.name, parent_joint)})
    if tool not in {lk.name for lk in model.links}:
        raise DescriptionError(
            f"{name}: tool link {tool!r} is not a link of the file (links beyond the last "
            f"moving joint {last.name!r}: {', '.join(map(repr, beyond))})"
        )
    if tool not in beyond:
        raise DescriptionError(
            f"{name}: tool link {tool!r} is not beyond the last moving joint {last.name!r} "
            f"(choose one of {', '.join(map(repr, beyond))})"
        )
    return tool


def _fixed_transform(elem: Any, where: str, j: yourdfpy.Joint | None = None,
                     value: sp.Expr | None = None) -> sp.ImmutableMatrix:
    """The transform of a fixed joint (its ``<origin>``), or of joint ``j`` locked at ``value``
    (``origin @ motion(axis, value)``), shape (4, 4)."""
    xyz, rpy = _origin(elem.find("origin"), where)
    if value is None:
        pre, _, post = placement.from_origin(xyz, rpy, (0, 0, 1))
        return sp.ImmutableMatrix(pre * post)
    pre, unit, post = placement.from_origin(xyz, rpy, _axis(j, where))
    motion = S.trans(*(unit * value)) if j.type == "prismatic" else S.rot_h(S.axis_angle(unit, value))
    return sp.ImmutableMatrix(pre * motion * post)


def _axis(j: yourdfpy.Joint, where: str) -> list[sp.Expr]:
    """A moving joint's ``<axis>`` (an error for the zero vector)."""
    axis = _vector(j.axis, f"{where}: axis")
    if all(a == 0 for a in axis):
        raise DescriptionError(f"{where}: the axis is the zero vector")
    return axis


def _locked_positions(model: yourdfpy.Robot, locked: Mapping[str, float], name: str
                      ) -> dict[str, sp.Expr]:
    """The positions of the locked joints (the user's, and those of the ``<mimic>`` joints that
    follow one: ``multiplier x value + offset``), checked against the file and its limits."""
    joints = {j.name: j for j in model.joints}
    moving = [j.name for j in model.joints if j.type != "fixed"]
    out: dict[str, sp.Expr] = {}
    for key, value in locked.items():
        where = f"{name}: locked[{key!r}]"
        if key not in joints:
            raise DescriptionError(f"{where}: not a joint of the file (moving joints: "
                                   f"{', '.join(map(repr, moving))})")
        if joints[key].type == "fixed":
            raise DescriptionError(f"{where}: the joint is already fixed")
        if isinstance(value, bool) or not isinstance(value, int | float | np.floating | np.integer):
            raise DescriptionError(f"{where}: the position must be a number, got {value!r}")
        out[key] = number(value, where=where)
    followers = [j for j in model.joints if j.mimic is not None and j.name not in out]
    while True:  # a mimic joint follows the joint it mimics (that may itself be a mimic joint)
        ready = [j for j in followers if j.name not in out and j.mimic.joint in out]
        if not ready:
            break
        for j in ready:
            mult = 1.0 if j.mimic.multiplier is None else j.mimic.multiplier
            offset = 0.0 if j.mimic.offset is None else j.mimic.offset
            out[j.name] = number(mult * float(out[j.mimic.joint]) + offset,
                                 where=f"{name}: joint {j.name!r}: mimic")
    for key, value in out.items():
        lim, where = joints[key].limit, f"{name}: locked[{key!r}]"
        if joints[key].type != "continuous" and lim is not None and lim.lower is not None \
                and lim.upper is not None and not lim.lower <= float(value) <= lim.upper:
            raise DescriptionError(f"{where}: position {float(value):g} is outside the joint's "
                                   f"limits [{lim.lower:g}, {lim.upper:g}]")
    return out


def _merge_side_branches(
    bodies: dict[str, Link], side: Sequence[yourdfpy.Joint], chain_links: set[str],
    joint_xml: Mapping[str, Any], name: str, lock: Mapping[str, sp.Expr],
) -> dict[str, Link]:
    """Chain links with the mass of every fixed side branch welded to them (inputs unchanged).

    A side link that has neither mass nor inertia (a frame such as ``tool0`` or ``base``)
    changes nothing and is skipped.
    """
    out = dict(bodies)
    by_parent: dict[str, list[yourdfpy.Joint]] = {}
    for j in side:
        by_parent.setdefault(j.parent, []).append(j)
    for anchor in chain_links:
        # depth-first over the fixed subtrees hanging off this chain link
        stack = [(j, sp.ImmutableMatrix(sp.eye(4))) for j in by_parent.get(anchor, [])]
        while stack:
            j, t_parent = stack.pop()
            t = sp.ImmutableMatrix(t_parent * _fixed_transform(
                joint_xml[j.name], f"{name}: joint {j.name!r}", j, lock.get(j.name)))
            link = bodies[j.child]
            if link.mass != 0 or link.inertia != sp.zeros(3):
                out[anchor] = combine_links(out[anchor], link, t)
            stack.extend((c, t) for c in by_parent.get(j.child, []))
    return out


def _origin(elem: Any, where: str) -> tuple[list[sp.Expr], list[sp.Expr]]:
    """``xyz`` (m) and ``rpy`` (rad) of an ``<origin>`` element (zeros when absent)."""
    out = []
    for key in ("xyz", "rpy"):
        text = "0 0 0" if elem is None else elem.get(key, "0 0 0")
        parts = text.split()
        if len(parts) != 3:
            raise DescriptionError(f"{where}: origin {key}={text!r} must have 3 numbers")
        out.append([number(p, where=f"{where}: origin {key}") for p in parts])
    return out[0], out[1]


def _vector(values: Sequence[float] | np.ndarray, where: str) -> list[sp.Expr]:
    """A 3-vector of URDF numbers."""
    vals = list(values)
    if len(vals) != 3:
        raise DescriptionError(f"{where}: expected 3 numbers, got {len(vals)}")
    return [number(v, where=where) for v in vals]


def _link(lk: yourdfpy.Link, elem: Any, where: str) -> Link:
    """A robodyn :class:`Link` (inertial data in the link frame) from a URDF link."""
    if lk.inertial is None:
        zero3 = sp.ImmutableMatrix(sp.zeros(3, 1))
        return Link(lk.name, sp.Integer(0), zero3, sp.ImmutableMatrix(sp.zeros(3)))
    inertial = lk.inertial
    if inertial.mass is None:
        raise DescriptionError(f"{where}: <inertial> has no <mass>")
    if inertial.inertia is None:
        raise DescriptionError(f"{where}: <inertial> has no <inertia>")
    mass = number(inertial.mass, where=f"{where}: mass")
    i_com = sp.Matrix(3, 3, lambda r, c: number(inertial.inertia[r, c], where=f"{where}: inertia"))
    xyz, rpy = _origin(elem.find("inertial").find("origin"), f"{where}: inertial")
    rot = S.rpy_to_matrix(*rpy)
    # inertia about the COM, re-expressed from COM-frame axes to link-frame axes: R I R^T
    i_link = rot * i_com * rot.T
    i_link = (i_link + i_link.T) / 2  # exact symmetry despite rounding
    return Link(lk.name, mass, sp.ImmutableMatrix(xyz), sp.ImmutableMatrix(i_link))


def _element(j: yourdfpy.Joint, elem: Any, link: Link, name: str,
             locked: sp.Expr | None = None) -> ChainElement:
    """One :class:`ChainElement` (joint + the link it carries) from a URDF joint (a fixed one
    where the joint is ``locked`` at that position)."""
    where = f"{name}: joint {j.name!r}"
    xyz, rpy = _origin(elem.find("origin"), where)
    source_params = dict(zip(("x", "y", "z", "roll", "pitch", "yaw"), (*xyz, *rpy), strict=True))
    if j.type == "fixed" or locked is not None:
        pre = _fixed_transform(elem, where, j, locked)
        return ChainElement(j.name, "fixed", pre, _Z_AXIS, sp.ImmutableMatrix(sp.eye(4)), link)
    pre, unit, post = placement.from_origin(xyz, rpy, _axis(j, where))
    fields: dict[str, Any] = {"convention": "origin", "source_params": source_params}
    fields.update(_limits(j, where))
    if j.dynamics is not None:
        fields["friction"] = _friction(j.dynamics, where)
    jtype = "prismatic" if j.type == "prismatic" else "revolute"
    return ChainElement(j.name, jtype, pre, unit, post, link, fields)


def _limits(j: yourdfpy.Joint, where: str) -> Mapping[str, sp.Expr]:
    """``lower``/``upper`` (not for continuous joints), ``velocity_limit``, ``effort_limit``."""
    out: dict[str, sp.Expr] = {}
    lim = j.limit
    if lim is None:
        return out
    pairs = [("velocity_limit", lim.velocity), ("effort_limit", lim.effort)]
    if j.type != "continuous":
        pairs += [("lower", lim.lower), ("upper", lim.upper)]
    for key, value in pairs:
        if value is not None:
            out[key] = number(value, where=f"{where}: limit {key}")
    if "lower" in out and "upper" in out and out["lower"] > out["upper"]:
        raise DescriptionError(f"{where}: limit lower={lim.lower} is above upper={lim.upper}")
    return out


def _friction(dyn: yourdfpy.Dynamics, where: str) -> Friction:
    """Joint friction from ``<dynamics damping friction>`` (missing values are zero)."""
    values: dict[str, sp.Expr] = {}
    for label in ("damping", "friction"):
        raw = getattr(dyn, label)
        v = sp.Integer(0) if raw is None else number(raw, where=f"{where}: dynamics {label}")
        if v < 0:
            raise DescriptionError(f"{where}: dynamics {label}={raw} is negative")
        values[label] = v
    coulomb = values["friction"]
    return Friction(viscous=values["damping"], coulomb_positive=coulomb, coulomb_negative=coulomb)
