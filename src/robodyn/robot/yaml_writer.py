"""Write a :class:`~robodyn.robot.model.Robot` as a robodyn YAML description.

Every joint is written with the ``origin`` placement (``xyz`` in m, ``rpy`` in rad, URDF
fixed-axis roll-pitch-yaw) and its ``axis``, that is ``T_i(q) = origin_i @ motion(axis_i, q)``.
A robot joint's own placement is ``pre_i @ motion(axis_i, q) @ post_i`` (see
:mod:`robodyn.robot.model`); a non-identity ``post_i`` (standard DH) has no field of its own in
the ``origin`` form, so it is moved:

* into the next joint's origin: ``origin_{i+1} = post_i @ pre_{i+1}``, or into the tool frame
  after the last joint: ``tool' = post_n @ tool``;
* into link ``i``'s inertial data, which is re-expressed in the frame ``pre_i @ motion_i``
  reached before ``post_i`` (``com' = R c + p``, ``inertia' = R I R^T`` with ``(R, p)`` the
  rotation and translation of ``post_i``).

The written description therefore has the same forward kinematics (every moving frame
before each ``post_i`` and the tool frame coincide) and the same masses, centres of mass and
inertia tensors in world terms; only the link frames of joints with a ``post`` transform
change, to the frame before ``post``. Link ``hydro`` data are written field by field in the
link frame (every coefficient, the volume and the centre of buoyancy given), which is only
right in an unchanged link frame: a link with hydro data after a joint with a non-identity
``post`` raises :class:`ValueError`.

Numbers: SymPy integers are written as integers, ``Float`` values with ``repr`` precision (the
shortest text that reads back as the same double), anything else (``pi/2``, ``l/2``, ``l**2``,
``sqrt(3)/2``, ``-981/100``) as an expression text in the syntax of
:mod:`robodyn.robot.expressions`; each expression text is parsed back and compared before it is
written. Drive and friction values are written on the joint side (``side: joint``).
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import sympy as sp
import yaml
from sympy.printing.str import StrPrinter

from robodyn import spatial as S
from robodyn.robot.errors import DescriptionError, InputError
from robodyn.robot.expressions import parse_value
from robodyn.robot.hydro import HYDRO_DEFAULTS, LinkHydro
from robodyn.robot.model import IDENTITY4, Joint, Link, Robot

__all__ = ["dump_yaml", "matrix_to_rpy", "origin_form"]

_PLAIN = re.compile(r"[A-Za-z0-9_.+\-*/() ]+\Z")


# ----------------------------------------------------------------------------------------------
# Placement: xyz / rpy of a homogeneous transform


def matrix_to_rpy(rotation: sp.MatrixBase) -> tuple[sp.Expr, sp.Expr, sp.Expr]:
    """URDF roll-pitch-yaw of a rotation matrix: ``R = Rz(yaw) @ Ry(pitch) @ Rx(roll)``.

    Exact matrices give exact angles (``pi/2``, ``atan(3/4)``); matrices with ``Float`` entries
    give ``Float`` angles computed in double precision (exact zeros stay ``Integer(0)``);
    symbolic matrices give ``atan2`` expressions. The yaw is taken first, ``atan2(R10, R00)``
    (zero at gimbal lock when both are exactly zero), then pitch and roll from
    ``Rz(-yaw) @ R = Ry(pitch) @ Rx(roll)``, which stays well conditioned near gimbal lock.

    Parameters
    ----------
    rotation : sympy.Matrix, shape (3, 3)
        A rotation matrix.

    Returns
    -------
    tuple of sympy.Expr
        ``(roll, pitch, yaw)``, rad; ``pitch`` in ``[-pi/2, pi/2]``, the others in
        ``(-pi, pi]``.
    """
    r = sp.Matrix(rotation)
    if not r.free_symbols and r.has(sp.Float):
        m = np.array(r.evalf(), dtype=float)
        yaw = math.atan2(m[1, 0], m[0, 0])
        c, s = math.cos(yaw), math.sin(yaw)
        m = np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]]) @ m  # Rz(-yaw) R
        pitch = math.atan2(-m[2, 0], m[0, 0])
        roll = math.atan2(-m[1, 2], m[1, 1])
        return tuple(sp.Integer(0) if v == 0.0 else sp.Float(v) for v in (roll, pitch, yaw))
    simplify = _simplify
    if r[1, 0] == 0 and r[0, 0] == 0:
        yaw = sp.Integer(0)
    else:
        yaw = simplify(sp.atan2(r[1, 0], r[0, 0]))
    m = (S.rotz(-yaw) * r).applyfunc(simplify)
    pitch = simplify(sp.atan2(-m[2, 0], m[0, 0]))
    roll = simplify(sp.atan2(-m[1, 2], m[1, 1]))
    return roll, pitch, yaw


def _simplify(e: sp.Expr) -> sp.Expr:
    """Simplify exact and symbolic values; leave plain numbers alone."""
    e = sp.sympify(e)
    if e.is_Number or e.has(sp.Float) and not e.free_symbols:
        return e
    return sp.simplify(e)


def _xyz_rpy(t: sp.MatrixBase) -> tuple[list[sp.Expr], list[sp.Expr]]:
    """``xyz`` and ``rpy`` of a homogeneous transform, shape (4, 4)."""
    xyz = [_simplify(v) for v in S.translation(sp.ImmutableMatrix(t))]
    return xyz, list(matrix_to_rpy(S.rotation(sp.ImmutableMatrix(t))))


def _source_origin(joint: Joint, pre: sp.MatrixBase) -> tuple[list[sp.Expr], list[sp.Expr]] | None:
    """The xyz/rpy the description gave for ``joint``, when they still reproduce ``pre``."""
    p = joint.source_params
    keys = ("x", "y", "z", "roll", "pitch", "yaw")
    if joint.convention != "origin" or not all(k in p for k in keys):
        return None
    xyz, rpy = [p[k] for k in keys[:3]], [p[k] for k in keys[3:]]
    if S.transform(S.rpy_to_matrix(*rpy), xyz) != sp.ImmutableMatrix(pre):
        return None
    return xyz, rpy


def _is_identity(t: sp.MatrixBase) -> bool:
    return sp.ImmutableMatrix(t) == IDENTITY4


def _moved_link(link: Link, post: sp.MatrixBase, joint: Joint) -> Link:
    """``link``'s inertial data re-expressed in the frame before ``post``."""
    if link.hydro:
        raise InputError(
            f"link {link.name!r} has hydro data, given in its own frame, but joint "
            f"{joint.name!r} has a post transform that the origin form moves that frame by; "
            "such a robot cannot be written as a robodyn YAML description yet"
        )
    r, p = S.rotation(sp.ImmutableMatrix(post)), S.translation(sp.ImmutableMatrix(post))
    com = (r * link.com + p).applyfunc(_simplify)
    inertia = r * link.inertia * r.T
    inertia = ((inertia + inertia.T) / 2).applyfunc(_simplify)  # symmetric despite rounding
    return Link(link.name, link.mass, sp.ImmutableMatrix(com), sp.ImmutableMatrix(inertia), None)


def origin_form(
    robot: Robot,
) -> tuple[list[tuple[Joint, list[sp.Expr], list[sp.Expr], Link]], sp.ImmutableMatrix]:
    """Joints as ``origin`` placements, with every ``post`` pushed outwards (module docstring).

    Parameters
    ----------
    robot : Robot

    Returns
    -------
    joints : list of (Joint, xyz, rpy, Link)
        Per joint, base outwards: the joint, its origin ``xyz`` (m) and ``rpy`` (rad), and its
        link with inertial data in the written link frame.
    tool : sympy.ImmutableMatrix, shape (4, 4)
        The tool frame in the written last link frame.
    """
    out = []
    carry = IDENTITY4  # post transform of the previous joint, not written yet
    for joint, link in zip(robot.joints, robot.links, strict=True):
        pre = sp.ImmutableMatrix(carry * joint.pre)
        given = _source_origin(joint, pre) if _is_identity(carry) else None
        xyz, rpy = given if given is not None else _xyz_rpy(pre)
        if _is_identity(joint.post):
            out.append((joint, xyz, rpy, link))
            carry = IDENTITY4
        else:
            out.append((joint, xyz, rpy, _moved_link(link, joint.post, joint)))
            carry = joint.post
    tool = sp.ImmutableMatrix((carry * robot.tool).applyfunc(_simplify))
    return out, tool


# ----------------------------------------------------------------------------------------------
# Scalar text


class _ExpressionPrinter(StrPrinter):
    """``str`` of SymPy expressions in the description expression syntax."""

    def _print_Float(self, expr: sp.Float) -> str:
        return repr(float(expr))

    def _print_Abs(self, expr: sp.Abs) -> str:
        return f"abs({self._print(expr.args[0])})"

    def _print_Exp1(self, expr: sp.Expr) -> str:
        return "exp(1)"


_PRINTER = _ExpressionPrinter()


def _float_text(x: float) -> str:
    """``repr`` of a float in a form YAML 1.1 reads as a float (``1e-05`` -> ``1.0e-05``)."""
    text = repr(float(x))
    if "e" in text:
        mantissa, exponent = text.split("e")
        if "." not in mantissa:
            mantissa += ".0"
        if exponent[0] not in "+-":
            exponent = "+" + exponent
        text = f"{mantissa}e{exponent}"
    return text


def _string(s: str) -> str:
    """A YAML scalar for a name or text: plain when YAML reads it back unchanged, else quoted."""
    if _PLAIN.match(s) and s == s.strip():
        try:
            if yaml.safe_load(s) == s:
                return s
        except yaml.YAMLError:
            pass
    return json.dumps(s)  # a JSON string is a YAML double-quoted scalar


class _Scalars:
    """Writes description values, checking each expression text reads back the same."""

    def __init__(self, robot: Robot) -> None:
        self.symbols = robot.symbols
        self.defaults = robot.defaults()

    def __call__(self, value: Any, where: str) -> str:
        """YAML text of one numeric field (``where`` names it in errors)."""
        e = sp.sympify(value)
        if e.is_Integer:
            return str(int(e))
        if e.is_Float:
            if not math.isfinite(float(e)):
                raise InputError(f"{where}: value {e} is not finite")
            return _float_text(float(e))
        text = _PRINTER.doprint(e)
        try:
            back = parse_value(text, self.symbols, where=where)
        except DescriptionError as exc:
            raise InputError(
                f"{where}: {e} cannot be written as a description expression: {exc}"
            ) from None
        if back != e and not self._same(back, e):
            raise InputError(f"{where}: {e} would read back as {back}")
        return _string(text)

    def _same(self, a: sp.Expr, b: sp.Expr) -> bool:
        """Numeric equality at the defaults and at one other parameter point."""
        if sp.simplify(a - b) == 0:
            return True
        points = [self.defaults, {s: v + 0.123 for s, v in self.defaults.items()}]
        for point in points:
            va, vb = complex(sp.N(a.subs(point))), complex(sp.N(b.subs(point)))
            if not abs(va - vb) <= 1e-12 * max(1.0, abs(vb)):
                return False
        return True

    def seq(self, values: Sequence[Any], where: str) -> str:
        """A flow sequence ``[a, b, c]``."""
        return "[" + ", ".join(self(v, f"{where}[{k}]") for k, v in enumerate(values)) + "]"

    def mapping(self, items: Mapping[str, Any], where: str) -> str:
        """A flow mapping ``{k: v, ...}`` of numeric fields."""
        return "{" + ", ".join(f"{k}: {self(v, f'{where}.{k}')}" for k, v in items.items()) + "}"

    def pose(self, xyz: Sequence[Any], rpy: Sequence[Any], where: str) -> str:
        """``{xyz: [...], rpy: [...]}``."""
        return f"{{xyz: {self.seq(xyz, where + '.xyz')}, rpy: {self.seq(rpy, where + '.rpy')}}}"


def _hydro_text(h: LinkHydro, value: _Scalars, where: str) -> str:
    """A link's hydro data as a flow mapping with every field given (volume and centre of
    buoyancy too: they read back as given, equal to the cylinders' when derived from them)."""
    cylinders = ", ".join(
        f"{{radius: {value(c.radius, f'{where}.cylinders[{k}].radius')}, "
        f"length: {value(c.length, f'{where}.cylinders[{k}].length')}, "
        f"axis: {value.seq(list(c.axis), f'{where}.cylinders[{k}].axis')}, "
        f"start: {value.seq(list(c.start), f'{where}.cylinders[{k}].start')}}}"
        for k, c in enumerate(h.cylinders))
    coefficients = {key: getattr(h, key) for key in HYDRO_DEFAULTS}
    return (f"{{cylinders: [{cylinders}], {value.mapping(coefficients, where)[1:-1]}, "
            f"volume: {value(h.volume, where + '.volume')}, "
            f"center_of_buoyancy: {value.seq(list(h.center_of_buoyancy), where + '.center_of_buoyancy')}, "
            f"quadrature: {h.quadrature}}}")


# ----------------------------------------------------------------------------------------------
# The document


def dump_yaml(robot: Robot) -> str:
    """The robodyn YAML description of ``robot``.

    Parameters
    ----------
    robot : Robot
        Any robot (from a URDF, a YAML description or built in code).

    Returns
    -------
    str
        YAML text, starting with a comment that names ``robot.source``. Loading it with
        :func:`robodyn.robot.yaml_loader.load_yaml_text` gives the same forward kinematics and
        the same link masses, centres of mass and inertias in world terms (see the module
        docstring for how ``post`` transforms are written).

    Raises
    ------
    ValueError
        If a value cannot be written as a description expression, or a link with hydro data
        follows a joint with a ``post`` transform.
    """
    value = _Scalars(robot)
    joints, tool = origin_form(robot)
    source = " ".join(robot.source.split())
    lines = [
        f"# Generated by robodyn from {source}.",
        "# Every joint is written as origin (xyz, rpy) + axis; see robodyn.robot.yaml_writer.",
        f"name: {_string(robot.name)}",
        f"description: {json.dumps(f'Written by robodyn from {source}')}",
    ]
    if robot.parameters:
        params = ", ".join(
            f"{_string(k)}: {_float_text(v)}" for k, v in robot.parameters.items()
        )
        lines.append(f"parameters: {{{params}}}")
    lines.append(f"gravity: {value.seq(list(robot.gravity), 'gravity')}")
    lines.append(f"base: {value.pose(*_xyz_rpy(robot.base), 'base')}")
    lines.append(f"tool: {value.pose(*_xyz_rpy(tool), 'tool')}")
    if robot.fluid is not None:
        f = robot.fluid
        lines.append(f"fluid: {{density: {value(f.density, 'fluid.density')}, "
                     f"current: {value.seq(list(f.current), 'fluid.current')}}}")
    if robot.corrections is not None:  # floats as repr: read back bit for bit
        block = yaml.safe_dump({"corrections": robot.corrections.as_plain(robot.joint_names)},
                               default_flow_style=None, sort_keys=False, width=10**6)
        lines += block.rstrip("\n").split("\n")
    lines.append("joints:")
    for k, (joint, xyz, rpy, link) in enumerate(joints):
        lines += _joint_lines(joint, xyz, rpy, link, value, f"joints[{k}]")
    return "\n".join(lines) + "\n"


def _joint_lines(
    joint: Joint,
    xyz: Sequence[sp.Expr],
    rpy: Sequence[sp.Expr],
    link: Link,
    value: _Scalars,
    where: str,
) -> list[str]:
    """The lines of one joint entry (with its link)."""
    lines = [
        f"  - name: {_string(joint.name)}",
        f"    type: {joint.type}",
        f"    origin: {value.pose(xyz, rpy, where + '.origin')}",
        f"    axis: {value.seq(list(joint.axis), where + '.axis')}",
    ]
    limits = {
        "lower": joint.lower,
        "upper": joint.upper,
        "velocity": joint.velocity_limit,
        "effort": joint.effort_limit,
    }
    limits = {k: v for k, v in limits.items() if v is not None}
    if limits:
        lines.append(f"    limits: {value.mapping(limits, where + '.limits')}")
    d, f = joint.drive, joint.friction
    drive = {
        "gear_ratio": d.gear_ratio,
        "rotor_inertia": d.rotor_inertia,
        "torque_constant": d.torque_constant,
    }
    lines.append(f"    drive: {value.mapping(drive, where + '.drive')}")
    friction = {
        "viscous": f.viscous,
        "coulomb_positive": f.coulomb_positive,
        "coulomb_negative": f.coulomb_negative,
        "offset": f.offset,
    }
    lines.append(f"    friction: {{side: joint, {value.mapping(friction, where + '.friction')[1:]}")
    lw = where + ".link"
    i = link.inertia
    inertia = {
        "ixx": i[0, 0], "iyy": i[1, 1], "izz": i[2, 2],
        "ixy": i[0, 1], "ixz": i[0, 2], "iyz": i[1, 2],
    }
    lines += [
        "    link:",
        f"      name: {_string(link.name)}",
        f"      mass: {value(link.mass, lw + '.mass')}",
        f"      com: {value.seq(list(link.com), lw + '.com')}",
        f"      inertia: {value.mapping(inertia, lw + '.inertia')}",
    ]
    if link.hydro is not None:
        lines.append(f"      hydro: {_hydro_text(link.hydro, value, lw + '.hydro')}")
    return lines
