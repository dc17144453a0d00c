"""Numbers for the exporters: a robot's expressions at its parameter values, and their text.

A :class:`~robodyn.robot.model.Robot` holds SymPy expressions, possibly over named parameters.
Export formats hold numbers, so every value is evaluated with the parameters at their defaults
(or at the values the caller overrides). Evaluation is done in SymPy at :data:`DIGITS` significant
digits, compositions of transforms included, and only then rounded once to a double; each double
is written with ``repr`` precision, the shortest text that reads back as the same double.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from pathlib import Path

import numpy as np
import sympy as sp

from robodyn.robot.errors import InputError
from robodyn.robot.model import Robot
from robodyn.robot.yaml_writer import matrix_to_rpy

__all__ = [
    "DIGITS",
    "Values",
    "array",
    "check_names",
    "exact",
    "number",
    "quaternion",
    "rpy",
    "text",
    "unique_name",
    "values_of",
    "vector_text",
    "write",
]

#: Significant digits of the SymPy evaluation before the single rounding to a double.
DIGITS = 30

Values = dict[sp.Symbol, sp.Float]


def values_of(robot: Robot, parameters: Mapping[str, float] | None = None) -> Values:
    """Substitution map of the robot's named parameters: defaults overridden by ``parameters``.

    Parameters
    ----------
    robot : Robot
    parameters : Mapping[str, float] or None
        Values (SI units) for some of ``robot.parameters``.

    Returns
    -------
    dict
        ``{Symbol(name, real=True): Float(value)}`` for every named parameter.

    Raises
    ------
    TypeError
        If ``robot`` is not a :class:`Robot`.
    ValueError
        If ``parameters`` names a parameter the robot does not declare, or a value is not a
        finite number.
    """
    if not isinstance(robot, Robot):
        raise TypeError(f"expected a robodyn Robot, got {type(robot).__name__}")
    given = dict(parameters or {})
    unknown = sorted(set(given) - set(robot.parameters))
    if unknown:
        declared = ", ".join(robot.parameters) or "none"
        raise InputError(
            f"{robot.source}: unknown parameter(s) {unknown} for robot {robot.name!r} "
            f"(declared: {declared})"
        )
    out: Values = {}
    for name, default in {**robot.parameters, **given}.items():
        try:
            value = float(default)
        except (TypeError, ValueError):
            raise InputError(f"{robot.source}: parameter {name!r}: {default!r} is not a number") from None
        if not math.isfinite(value):
            raise InputError(f"{robot.source}: parameter {name!r}: {value} is not finite")
        out[sp.Symbol(name, real=True)] = sp.Float(value)
    return out


def exact(value: sp.Expr | sp.MatrixBase, values: Values, where: str) -> sp.Expr | sp.Matrix:
    """``value`` with the parameters substituted, evaluated to :data:`DIGITS` digits.

    Parameters
    ----------
    value : sympy.Expr or sympy.Matrix
        A scalar or matrix of the robot description.
    values : dict
        From :func:`values_of`.
    where : str
        Names the field in error messages.

    Returns
    -------
    sympy.Expr or sympy.Matrix
        Numbers only (``Float`` of :data:`DIGITS` digits, or exact ``0``/``1``).

    Raises
    ------
    ValueError
        If a symbol is left over (not a declared parameter) or a value is not finite.
    """
    if isinstance(value, sp.MatrixBase):
        out = sp.Matrix(value).xreplace(values).evalf(DIGITS)
        entries: Iterable[sp.Expr] = list(out)
    else:
        out = sp.sympify(value).xreplace(values).evalf(DIGITS)
        entries = [out]
    for e in entries:
        if e.free_symbols:
            names = ", ".join(sorted(str(s) for s in e.free_symbols))
            raise InputError(f"{where}: {e} depends on {names}, which is not a declared parameter")
        if not (e.is_real and e.is_finite):
            raise InputError(f"{where}: value {e} is not a finite real number")
    return out


def number(value: sp.Expr, values: Values, where: str) -> float:
    """A scalar field as a double (see :func:`exact`)."""
    return float(exact(value, values, where))


def array(value: sp.MatrixBase, values: Values, where: str) -> np.ndarray:
    """A matrix field as a float array of the same shape (see :func:`exact`)."""
    return np.array(exact(value, values, where).tolist(), dtype=float)


def text(x: float) -> str:
    """``repr`` of a double (``-0.0`` written as ``0.0``); reads back as the same double."""
    x = float(x)
    if not math.isfinite(x):
        raise InputError(f"cannot write the non-finite number {x}")
    return repr(x + 0.0)


def vector_text(xs: Iterable[float]) -> str:
    """Space-separated :func:`text` of each number (the XML list format)."""
    return " ".join(text(x) for x in np.asarray(list(xs), dtype=float).ravel())


def rpy(rotation: np.ndarray) -> tuple[float, float, float]:
    """URDF roll, pitch, yaw (rad) of a rotation matrix, shape (3, 3): ``R = Rz Ry Rx``."""
    angles = matrix_to_rpy(sp.Matrix(np.asarray(rotation, dtype=float).tolist()))
    return tuple(float(a) for a in angles)  # type: ignore[return-value]


def quaternion(rotation: np.ndarray) -> np.ndarray:
    """Unit quaternion ``(w, x, y, z)`` of a rotation matrix, shape (3, 3) -> (4,), ``w >= 0``."""
    from scipy.spatial.transform import Rotation  # scipy.spatial: 0.3 s, MJCF only

    x, y, z, w = Rotation.from_matrix(np.asarray(rotation, dtype=float)).as_quat()
    quat = np.array([w, x, y, z])
    return -quat if w < 0 else quat


def unique_name(name: str, taken: set[str]) -> str:
    """``name``, or ``name`` with underscores appended until it is not in ``taken``; added to it."""
    out = name
    while out in taken:
        out += "_"
    taken.add(out)
    return out


def check_names(robot: Robot) -> None:
    """Raise :class:`ValueError` unless joint names and link names are non-empty and unique."""
    for kind, names in (("joint", robot.joint_names), ("link", [lk.name for lk in robot.links])):
        seen: set[str] = set()
        for name in names:
            if not name or not name.strip():
                raise InputError(f"{robot.source}: robot {robot.name!r} has a {kind} with an empty name")
            if name in seen:
                raise InputError(
                    f"{robot.source}: robot {robot.name!r} has two {kind}s named {name!r}; "
                    "the export formats need unique names"
                )
            seen.add(name)


def header_comment(robot: Robot, values: Values, note: str) -> str:
    """The comment at the top of an exported document (no ``--``, which XML comments forbid).

    Parameters
    ----------
    robot : Robot
    values : Values
        The parameter values used (listed when any).
    note : str
        A last line saying where the format's conventions are documented.
    """
    lines = [f" Generated by robodyn from {robot.source} (robot {robot.name!r})."]
    if values:
        listed = ", ".join(f"{s.name} = {text(float(v))}" for s, v in values.items())
        lines.append(f" Parameter values: {listed}.")
    lines.append(f" {note} ")
    return "\n".join(lines).replace("--", "- -")


def write(document: str, path: str | Path, what: str) -> None:
    """Write ``document`` (UTF-8) to ``path``; an :class:`OSError` names the file and the reason."""
    target = Path(path)
    try:
        target.write_text(document, encoding="utf-8")
    except OSError as exc:
        reason = exc.strerror or str(exc)
        raise OSError(exc.errno, f"{target}: cannot write the {what} file: {reason}") from exc
