"""Read a robodyn YAML robot description into an immutable :class:`~robodyn.robot.model.Robot`.

The format is documented in ``docs/description-format.md``. Every numeric field is a number or
a whitelisted expression over the declared ``parameters`` (see
:mod:`robodyn.robot.expressions`). Unknown keys, missing required fields, wrong shapes and
physically impossible values are rejected with a :class:`DescriptionError` whose message reads
``"<source>: <field path>: <reason>"``.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from types import MappingProxyType
from typing import Any

import sympy as sp

from robodyn import spatial as S
from robodyn.robot import placement, validation
from robodyn.robot.chain import ChainElement, assemble
from robodyn.robot.corrections import corrections_from_plain
from robodyn.robot.errors import DescriptionError
from robodyn.robot.expressions import parameter_symbol, parse_value
from robodyn.robot.hydro import parse_fluid, parse_hydro
from robodyn.robot.model import Drive, Friction, Link, Robot
from robodyn.robot.safe_yaml import MAX_YAML_DEPTH, safe_yaml
from robodyn.robot.safe_yaml import parse_yaml as _parse_yaml

__all__ = [
    "JOINT_TYPES",
    "MAX_DESCRIPTION_BYTES",
    "MAX_YAML_DEPTH",
    "safe_yaml",
    "load_yaml_file",
    "load_yaml_text",
]

#: Joint types accepted in ``joints[i].type`` and the type they load as.
JOINT_TYPES: Mapping[str, str] = MappingProxyType(
    {"revolute": "revolute", "continuous": "revolute", "prismatic": "prismatic", "fixed": "fixed"}
)

_TOP_KEYS = ("name", "description", "parameters", "gravity", "base", "tool", "fluid", "corrections",
             "joints")
_JOINT_KEYS = ("name", "type", "dh", "mdh", "origin", "axis", "limits", "drive", "friction", "link")
_PLACEMENTS = ("dh", "mdh", "origin")
_DH_KEYS = ("a", "alpha", "d", "theta")
_POSE_KEYS = ("xyz", "rpy")
_LIMIT_KEYS = ("lower", "upper", "velocity", "effort")
_DRIVE_KEYS = ("gear_ratio", "rotor_inertia", "torque_constant")
_FRICTION_KEYS = ("side", "viscous", "coulomb", "coulomb_positive", "coulomb_negative", "offset")
_LINK_KEYS = ("name", "mass", "com", "inertia", "hydro")
_INERTIA_KEYS = ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")
_ZERO = sp.Integer(0)

#: Largest description file read, bytes (the 7-joint Kinova Gen3 built-in is 6 kB).
MAX_DESCRIPTION_BYTES = 4 * 2**20


def load_yaml_file(path: str | Path, *, strict: bool = False) -> Robot:
    """Load a robodyn YAML description from a file.

    Parameters
    ----------
    path : str or Path
        The ``.yaml``/``.yml`` file; it is only read.
    strict : bool
        Turn physical-plausibility warnings (inertia) into errors.

    Returns
    -------
    Robot
        With ``source == str(path)``.

    Raises
    ------
    DescriptionError
        Malformed or physically impossible description (the message names file and field).
    OSError
        The file cannot be read.
    """
    p = Path(path)
    size = p.stat().st_size
    if size > MAX_DESCRIPTION_BYTES:
        raise DescriptionError(f"{p}: {size:,} bytes is too large for a robot description (at "
                               f"most {MAX_DESCRIPTION_BYTES:,}); is it the right file?")
    try:
        text = p.read_text(encoding="utf-8")
    except UnicodeDecodeError as exc:
        raise DescriptionError(f"{p}: not a UTF-8 text file ({exc.reason})") from None
    return load_yaml_text(text, source=str(p), strict=strict)


def load_yaml_text(text: str, *, source: str, strict: bool = False) -> Robot:
    """Load a robodyn YAML description from its text.

    Parameters
    ----------
    text : str
        The YAML document.
    source : str
        Where the text came from (a path or ``builtin:NAME``); starts every error message and
        becomes ``Robot.source``.
    strict : bool
        Turn physical-plausibility warnings (inertia) into errors.

    Returns
    -------
    Robot

    Raises
    ------
    DescriptionError
        Malformed or physically impossible description.

    Warns
    -----
    DescriptionWarning
        A link's inertia tensor is implausible (only when ``strict`` is false).
    """
    data = _parse_yaml(text, source)
    return _Reader(source, strict).robot(data)


def _kind(value: Any) -> str:
    """A user-facing name of a YAML value's type."""
    if value is None:
        return "nothing (null)"
    if isinstance(value, bool):
        return f"the boolean {value}"
    if isinstance(value, Mapping):
        return "a mapping"
    if isinstance(value, list | tuple):
        return f"a list of {len(value)} entries"
    if isinstance(value, str):
        return f"the text {value!r}"
    return f"{type(value).__name__} {value!r}"


class _Reader:
    """Converts the parsed YAML data, field by field, keeping the field path for errors."""

    def __init__(self, source: str, strict: bool) -> None:
        self.source = source
        self.strict = strict
        self.symbols: dict[str, sp.Symbol] = {}
        self.defaults: dict[str, float] = {}

    # -- generic helpers -------------------------------------------------------------------

    def error(self, path: str, reason: str) -> DescriptionError:
        """An error ``"<source>: <path>: <reason>"``."""
        return DescriptionError(f"{self.source}: {path}: {reason}")

    def mapping(
        self, value: Any, path: str, allowed: Sequence[str], required: Sequence[str] = ()
    ) -> Mapping[str, Any]:
        """Check a mapping: type, unknown keys (named), required keys (named)."""
        if not isinstance(value, Mapping):
            raise self.error(path, f"expected a mapping, got {_kind(value)}")
        unknown = [k for k in value if k not in allowed]
        if unknown:
            raise self.error(
                path,
                f"unknown key(s) {', '.join(repr(k) for k in unknown)} "
                f"(allowed: {', '.join(allowed)})",
            )
        for key in required:
            if key not in value:
                raise self.error(f"{path}.{key}" if path else key, "required field is missing")
        return value

    def string(self, value: Any, path: str) -> str:
        """A non-empty text."""
        if not isinstance(value, str) or not value.strip():
            raise self.error(path, f"expected a non-empty text, got {_kind(value)}")
        return value

    def expr(self, value: Any, path: str) -> sp.Expr:
        """A number or whitelisted expression over the declared parameters."""
        return parse_value(value, self.symbols, where=f"{self.source}: {path}")

    def value_at_defaults(self, expr: sp.Expr, path: str) -> float:
        """Numeric value at the parameters' default values."""
        return validation.evaluate(expr, self.defaults, where=f"{self.source}: {path}")

    def nonnegative(self, value: Any, path: str, what: str) -> sp.Expr:
        """An expression whose default value must be >= 0."""
        e = self.expr(value, path)
        v = self.value_at_defaults(e, path)
        if v < 0:
            raise self.error(path, f"{what} must not be negative (got {e} = {v:g})")
        return e

    def vector(self, value: Any, path: str, n: int = 3) -> list[sp.Expr]:
        """A list of ``n`` numbers or expressions."""
        if not isinstance(value, list | tuple) or len(value) != n:
            raise self.error(path, f"expected a list of {n} numbers, got {_kind(value)}")
        return [self.expr(v, f"{path}[{k}]") for k, v in enumerate(value)]

    def plain(self, value: Any, path: str) -> None:
        """Plain data before it is parsed (``hydro``, ``fluid``): text-keyed mappings, lists,
        text, numbers, booleans."""
        if isinstance(value, Mapping):
            for key, item in value.items():
                if not isinstance(key, str):
                    raise self.error(path, f"keys must be texts, got {_kind(key)}")
                self.plain(item, f"{path}.{key}")
        elif isinstance(value, list):
            for k, item in enumerate(value):
                self.plain(item, f"{path}[{k}]")
        elif isinstance(value, float) and not math.isfinite(value):
            raise self.error(path, f"expected a finite number, got {value!r}")
        elif value is not None and not isinstance(value, str | int | float | bool):
            raise self.error(
                path, f"expected a text, number, list or mapping, got {type(value).__name__}"
            )

    # -- sections ----------------------------------------------------------------------------

    def robot(self, data: Any) -> Robot:
        """The whole document."""
        if not isinstance(data, Mapping):
            raise DescriptionError(
                f"{self.source}: the top level must be a mapping with keys name, joints, ...; "
                f"got {_kind(data)}"
            )
        top = self.mapping(data, "", _TOP_KEYS, ("name", "joints"))
        name = self.string(top["name"], "name")
        if "description" in top and not isinstance(top["description"], str):
            raise self.error("description", f"expected a text, got {_kind(top['description'])}")
        self.parameters(top.get("parameters"))
        gravity = None
        if "gravity" in top:
            gravity = sp.ImmutableMatrix(self.vector(top["gravity"], "gravity"))
        base = self.pose(top["base"], "base") if "base" in top else None
        fluid = None
        if "fluid" in top:
            self.plain(top["fluid"], "fluid")
            fluid = parse_fluid(top["fluid"], self.symbols, self.defaults, where=f"{self.source}: fluid")
        tool = self.pose(top["tool"], "tool") if "tool" in top else None

        joints = top["joints"]
        if not isinstance(joints, list) or not joints:
            raise self.error("joints", f"expected a non-empty list of joints, got {_kind(joints)}")
        elements = [self.element(j, f"joints[{i}]") for i, j in enumerate(joints)]
        validation.check_unique_names(
            [e.joint_name for e in elements], what="joint", where=self.source,
            paths=[f"joints[{i}].name" for i in range(len(elements))],
        )
        validation.check_unique_names(
            [e.link.name for e in elements], what="link", where=self.source,
            paths=[f"joints[{i}].link.name" for i in range(len(elements))],
        )
        if all(e.joint_type == "fixed" for e in elements):
            raise self.error("joints", "no moving joint: every joint is fixed")
        kwargs: dict[str, Any] = {}
        if base is not None:
            kwargs["base"] = base
        if tool is not None:
            kwargs["tool"] = tool
        self.check_immersion(fluid, elements)
        robot = assemble(
            name, elements, gravity=gravity, parameters=dict(self.defaults),
            source=self.source, **kwargs,
        )
        extra: dict[str, Any] = {}
        if fluid is not None:
            extra["fluid"] = fluid
        if "corrections" in top:
            extra["corrections"] = corrections_from_plain(top["corrections"], robot.joint_names,
                                                          self.source)
        return dataclasses.replace(robot, **extra) if extra else robot

    def check_immersion(self, fluid: Any, elements: Sequence[ChainElement]) -> None:
        """A fluid block needs a link with hydro data (hydro alone means still fresh water)."""
        wet = [i for i, e in enumerate(elements) if e.link.hydro is not None]
        if fluid is not None and not wet:
            raise self.error("fluid", "no link has a hydro block, so nothing is immersed; "
                             "add hydro blocks to the links or remove the fluid block")

    def parameters(self, value: Any) -> None:
        """``parameters``: name -> default value (a number or a constant expression)."""
        if value is None:
            return
        if not isinstance(value, Mapping):
            raise self.error("parameters", f"expected a mapping name: value, got {_kind(value)}")
        validation.check_parameter_names(value.keys(), where=f"{self.source}: parameters")
        for key, raw in value.items():
            path = f"parameters.{key}"
            e = parse_value(raw, {}, where=f"{self.source}: {path}")
            self.defaults[key] = validation.evaluate(e, {}, where=f"{self.source}: {path}")
            self.symbols[key] = parameter_symbol(key)

    def pose(self, value: Any, path: str) -> sp.ImmutableMatrix:
        """``{xyz: [..], rpy: [..]}`` -> 4x4 homogeneous transform."""
        m = self.mapping(value, path, _POSE_KEYS)
        xyz = self.vector(m["xyz"], f"{path}.xyz") if "xyz" in m else [_ZERO] * 3
        rpy = self.vector(m["rpy"], f"{path}.rpy") if "rpy" in m else [_ZERO] * 3
        return S.transform(S.rpy_to_matrix(*rpy), xyz)

    def element(self, value: Any, path: str) -> ChainElement:
        """One ``joints[i]`` entry with its link."""
        j = self.mapping(value, path, _JOINT_KEYS, ("name", "type", "link"))
        name = self.string(j["name"], f"{path}.name")
        raw_type = j["type"]
        if not isinstance(raw_type, str) or raw_type not in JOINT_TYPES:
            raise self.error(
                f"{path}.type",
                f"unknown joint type {raw_type!r} (allowed: {', '.join(JOINT_TYPES)})",
            )
        jtype = JOINT_TYPES[raw_type]
        pre, axis, post, convention, params = self.placement(j, path, jtype)
        link = self.link(j["link"], f"{path}.link", default_name=f"{name}_link")
        fields: dict[str, Any] = {"convention": convention, "source_params": params}
        if jtype == "fixed":
            for key in ("limits", "drive", "friction"):
                if key in j:
                    raise self.error(f"{path}.{key}", "not allowed on a fixed joint")
            if link.hydro is not None:
                raise self.error(
                    f"{path}.link.hydro", "not supported on a link attached by a fixed joint "
                    "(it is merged into its parent): give its cylinders in the parent's hydro block",
                )
        else:
            fields.update(self.limits(j.get("limits"), f"{path}.limits"))
            drive = self.drive(j.get("drive"), f"{path}.drive")
            fields["drive"] = drive
            fields["friction"] = self.friction(
                j.get("friction"), f"{path}.friction", drive if "drive" in j else None
            )
        return ChainElement(name, jtype, pre, axis, post, link, fields)

    def placement(
        self, j: Mapping[str, Any], path: str, jtype: str
    ) -> tuple[sp.ImmutableMatrix, sp.ImmutableMatrix, sp.ImmutableMatrix, str,
               MappingProxyType[str, sp.Expr]]:
        """Exactly one of ``dh``, ``mdh``, ``origin`` (+ ``axis``) -> pre, axis, post."""
        given = [k for k in _PLACEMENTS if k in j]
        if len(given) != 1:
            got = " and ".join(given) if given else "none"
            raise self.error(
                path, f"exactly one placement (dh, mdh or origin) is required, got {got}"
            )
        kind = given[0]
        if "axis" in j and kind != "origin":
            raise self.error(
                f"{path}.axis",
                f"axis is only allowed with an origin placement ({kind} joints move about z)",
            )
        if kind in ("dh", "mdh"):
            m = self.mapping(j[kind], f"{path}.{kind}", _DH_KEYS)
            a, alpha, d, theta = (
                self.expr(m[k], f"{path}.{kind}.{k}") if k in m else _ZERO for k in _DH_KEYS
            )
            build = placement.from_dh if kind == "dh" else placement.from_mdh
            pre, axis, post = build(jtype, a, alpha, d, theta)
            params = {"a": a, "alpha": alpha, "d": d, "theta": theta}
            return pre, axis, post, kind, MappingProxyType(params)
        m = self.mapping(j["origin"], f"{path}.origin", _POSE_KEYS)
        xyz = self.vector(m["xyz"], f"{path}.origin.xyz") if "xyz" in m else [_ZERO] * 3
        rpy = self.vector(m["rpy"], f"{path}.origin.rpy") if "rpy" in m else [_ZERO] * 3
        if "axis" in j:
            u = self.vector(j["axis"], f"{path}.axis")
            norm = sum(self.value_at_defaults(e, f"{path}.axis") ** 2 for e in u) ** 0.5
            if norm == 0 or all(sp.simplify(e) == 0 for e in u):
                raise self.error(f"{path}.axis", f"axis {u} has zero length")
        else:
            u = [_ZERO, _ZERO, sp.Integer(1)]
        pre, axis, post = placement.from_origin(xyz, rpy, u)
        params = dict(zip(("x", "y", "z", "roll", "pitch", "yaw"), (*xyz, *rpy), strict=True))
        return pre, axis, post, "origin", MappingProxyType(params)

    def limits(self, value: Any, path: str) -> dict[str, sp.Expr]:
        """``limits`` -> Joint fields lower, upper, velocity_limit, effort_limit."""
        if value is None:
            return {}
        m = self.mapping(value, path, _LIMIT_KEYS)
        out: dict[str, sp.Expr] = {}
        if "lower" in m:
            out["lower"] = self.expr(m["lower"], f"{path}.lower")
        if "upper" in m:
            out["upper"] = self.expr(m["upper"], f"{path}.upper")
        if "lower" in out and "upper" in out:
            lo = self.value_at_defaults(out["lower"], f"{path}.lower")
            hi = self.value_at_defaults(out["upper"], f"{path}.upper")
            if lo > hi:
                raise self.error(path, f"lower limit {lo:g} is above upper limit {hi:g}")
        if "velocity" in m:
            out["velocity_limit"] = self.nonnegative(
                m["velocity"], f"{path}.velocity", "velocity limit"
            )
        if "effort" in m:
            out["effort_limit"] = self.nonnegative(m["effort"], f"{path}.effort", "effort limit")
        return out

    def drive(self, value: Any, path: str) -> Drive:
        """``drive`` -> :class:`Drive` (defaults: gear 1, no rotor inertia, constant 1)."""
        if value is None:
            return Drive()
        m = self.mapping(value, path, _DRIVE_KEYS)
        kwargs: dict[str, sp.Expr] = {}
        if "gear_ratio" in m:
            g = self.expr(m["gear_ratio"], f"{path}.gear_ratio")
            if self.value_at_defaults(g, f"{path}.gear_ratio") == 0:
                raise self.error(f"{path}.gear_ratio", "gear ratio must not be zero")
            kwargs["gear_ratio"] = g
        if "rotor_inertia" in m:
            kwargs["rotor_inertia"] = self.nonnegative(
                m["rotor_inertia"], f"{path}.rotor_inertia", "rotor inertia"
            )
        if "torque_constant" in m:
            kwargs["torque_constant"] = self.expr(m["torque_constant"], f"{path}.torque_constant")
        return Drive(**kwargs)

    def friction(self, value: Any, path: str, drive: Drive | None) -> Friction:
        """``friction`` -> joint-side :class:`Friction` (motor-side values reflected)."""
        if value is None:
            return Friction()
        m = self.mapping(value, path, _FRICTION_KEYS)
        side = m.get("side", "joint")
        if side not in ("joint", "motor"):
            raise self.error(f"{path}.side", f"expected 'joint' or 'motor', got {_kind(side)}")
        viscous = (
            self.nonnegative(m["viscous"], f"{path}.viscous", "viscous friction")
            if "viscous" in m else _ZERO
        )
        split = [k for k in ("coulomb_positive", "coulomb_negative") if k in m]
        if "coulomb" in m and split:
            raise self.error(
                path,
                f"give either coulomb (symmetric) or coulomb_positive and coulomb_negative, "
                f"not coulomb together with {' and '.join(split)}",
            )
        if len(split) == 1:
            missing = ({"coulomb_positive", "coulomb_negative"} - set(split)).pop()
            raise self.error(f"{path}.{missing}", f"required together with {split[0]}")
        if "coulomb" in m:
            c_pos = c_neg = self.nonnegative(m["coulomb"], f"{path}.coulomb", "Coulomb friction")
        elif split:
            c_pos = self.nonnegative(
                m["coulomb_positive"], f"{path}.coulomb_positive", "Coulomb friction"
            )
            c_neg = self.nonnegative(
                m["coulomb_negative"], f"{path}.coulomb_negative", "Coulomb friction"
            )
        else:
            c_pos = c_neg = _ZERO
        offset = self.expr(m["offset"], f"{path}.offset") if "offset" in m else _ZERO
        if side == "motor":
            if drive is None:
                raise self.error(
                    f"{path}.side", "motor-side friction needs a drive with a gear_ratio"
                )
            g = drive.gear_ratio
            # tau_joint = G tau_motor and qd_motor = G qd: viscous scales with G^2, Coulomb with
            # |G| (and swaps direction when G < 0), a constant offset with G.
            if self.value_at_defaults(g, f"{path}.side") < 0:
                c_pos, c_neg = c_neg, c_pos
            viscous, offset = g**2 * viscous, g * offset
            c_pos, c_neg = sp.Abs(g) * c_pos, sp.Abs(g) * c_neg
        return Friction(
            viscous=viscous, coulomb_positive=c_pos, coulomb_negative=c_neg, offset=offset
        )

    def link(self, value: Any, path: str, *, default_name: str) -> Link:
        """``link`` -> :class:`Link`, checked for physical plausibility."""
        m = self.mapping(value, path, _LINK_KEYS, ("mass",))
        name = self.string(m["name"], f"{path}.name") if "name" in m else default_name
        mass = self.expr(m["mass"], f"{path}.mass")
        com = self.vector(m["com"], f"{path}.com") if "com" in m else [_ZERO] * 3
        inertia = self.inertia(m["inertia"], f"{path}.inertia") if "inertia" in m else sp.zeros(3)
        hydro = None
        if "hydro" in m and m["hydro"] is not None:
            if not isinstance(m["hydro"], Mapping):
                raise self.error(f"{path}.hydro", f"expected a mapping, got {_kind(m['hydro'])}")
            self.plain(m["hydro"], f"{path}.hydro")
            hydro = parse_hydro(m["hydro"], self.symbols, self.defaults,
                                where=f"{self.source}: {path}.hydro")
        link = Link(
            name=name, mass=mass, com=sp.ImmutableMatrix(com),
            inertia=sp.ImmutableMatrix(inertia), hydro=hydro,
        )
        validation.check_link(
            link, where=f"{self.source}: {path}", strict=self.strict, defaults=self.defaults
        )
        return link

    def inertia(self, value: Any, path: str) -> sp.Matrix:
        """Six named entries or a full symmetric 3x3 list -> 3x3 matrix about the COM."""
        if isinstance(value, Mapping):
            m = self.mapping(value, path, _INERTIA_KEYS, ("ixx", "iyy", "izz"))
            e = {k: self.expr(m[k], f"{path}.{k}") if k in m else _ZERO for k in _INERTIA_KEYS}
            return sp.Matrix([
                [e["ixx"], e["ixy"], e["ixz"]],
                [e["ixy"], e["iyy"], e["iyz"]],
                [e["ixz"], e["iyz"], e["izz"]],
            ])
        if not isinstance(value, list | tuple) or len(value) != 3:
            raise self.error(
                path,
                f"expected a mapping ixx, iyy, izz, ixy, ixz, iyz or a 3x3 list, "
                f"got {_kind(value)}",
            )
        rows = [self.vector(row, f"{path}[{i}]") for i, row in enumerate(value)]
        return sp.Matrix(rows)
