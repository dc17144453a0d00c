"""Parameter values given at compile time (``compile_model(robot, parameters=...)``), checked.

A description is validated at its parameters' default values when it is loaded. Values that
override the defaults later are checked the same way before anything is generated: each must be
a finite real number, and every quantity that depends on an overridden parameter is checked again
at the new values with the loaders' rules (:mod:`robodyn.robot.validation`): link mass not
negative, centre of mass and inertia finite (implausible inertia warns), rotor inertia, friction,
velocity and effort limits not negative, gear ratio not zero, lower limit not above upper, joint
placement finite. Quantities that do not depend on an overridden parameter were checked at load.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping

import sympy as sp

from robodyn.robot import validation
from robodyn.robot.errors import DescriptionError
from robodyn.robot.expressions import parameter_symbol
from robodyn.robot.model import Joint, Robot

__all__ = ["checked_parameter_values"]


def checked_parameter_values(
    robot: Robot, parameters: Mapping[str, object] | None, *, where: str = "parameters"
) -> dict[str, float]:
    """The robot's parameter values with ``parameters`` overriding the defaults, checked.

    Parameters
    ----------
    robot : Robot
    parameters : mapping of str to float, optional
        Overriding values (SI units of each parameter); ``None`` or empty keeps the defaults.
    where : str
        What gave the values, for messages (e.g. ``"compile_model(parameters=...)"``).

    Returns
    -------
    dict of str to float
        Every parameter of ``robot``, overridden ones at their new values.

    Raises
    ------
    DescriptionError
        An unknown parameter name, a value that is not a finite real number, or a quantity that
        is physically impossible at the new values; the message names ``where``, the
        description, the field and the values.

    Warns
    -----
    DescriptionWarning
        A link's inertia becomes implausible at the new values.
    """
    given = dict(parameters or {})
    unknown = [k for k in given if k not in robot.parameters]
    if unknown:
        raise DescriptionError(
            f"{where}: robot {robot.name!r} has no parameter(s) {', '.join(map(str, unknown))}; "
            f"it has {', '.join(robot.parameters) or 'none'}"
        )
    values = {k: float(v) for k, v in robot.parameters.items()}
    for name, raw in given.items():
        values[name] = _finite(raw, f"{where}: {name!r}")
    changed = {parameter_symbol(k) for k, v in given.items() if values[k] != robot.parameters[k]}
    if not changed:
        return values
    label = ", ".join(f"{s} = {values[str(s)]:g}" for s in sorted(changed, key=str))
    context = f"{where} ({label}): {robot.source}"
    for i, (joint, link) in enumerate(zip(robot.joints, robot.links, strict=True)):
        link_exprs = [link.mass, *link.com, *link.inertia]
        if _depends(link_exprs, changed):
            validation.check_link(link, where=f"{context}: links[{i}]", strict=False,
                                  defaults=values)
        _check_joint(joint, changed, values, f"{context}: joints[{i}]")
    return values


def _finite(raw: object, where: str) -> float:
    """``raw`` as a finite float, or a clear error."""
    if isinstance(raw, bool | str) or raw is None:
        raise DescriptionError(f"{where}: expected a finite real number, got {raw!r}")
    try:
        value = float(raw)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise DescriptionError(f"{where}: expected a finite real number, got {raw!r}") from None
    if not math.isfinite(value):
        raise DescriptionError(f"{where}: expected a finite real number, got {value!r}")
    return value


def _depends(exprs: Iterable[object], changed: set[sp.Symbol]) -> bool:
    """Whether any expression has an overridden parameter among its symbols."""
    return any(sp.sympify(e).free_symbols & changed for e in exprs)


def _check_joint(joint: Joint, changed: set[sp.Symbol], values: Mapping[str, float],
                 where: str) -> None:
    """A joint's placement, drive, friction and limits at the new values."""

    def value(expr: object, field: str) -> float | None:
        if expr is None or not _depends([expr], changed):
            return None
        return validation.evaluate(sp.sympify(expr), values, where=f"{where}.{field}")

    for field in ("pre", "axis", "post"):
        for k, e in enumerate(getattr(joint, field)):
            value(e, f"{field}[{k}]")  # finite
    nonnegative = {
        "drive.rotor_inertia": (joint.drive.rotor_inertia, "rotor inertia"),
        "friction.viscous": (joint.friction.viscous, "viscous friction"),
        "friction.coulomb_positive": (joint.friction.coulomb_positive, "Coulomb friction"),
        "friction.coulomb_negative": (joint.friction.coulomb_negative, "Coulomb friction"),
        "limits.velocity": (joint.velocity_limit, "velocity limit"),
        "limits.effort": (joint.effort_limit, "effort limit"),
    }
    for field, (expr, what) in nonnegative.items():
        v = value(expr, field)
        if v is not None and v < 0:
            raise DescriptionError(f"{where}.{field}: {what} must not be negative "
                                   f"({expr} = {v:g})")
    for expr, field in ((joint.drive.torque_constant, "drive.torque_constant"),
                        (joint.friction.offset, "friction.offset")):
        value(expr, field)  # finite
    gear = value(joint.drive.gear_ratio, "drive.gear_ratio")
    if gear == 0:
        raise DescriptionError(f"{where}.drive.gear_ratio: gear ratio must not be zero "
                               f"({joint.drive.gear_ratio} = 0)")
    if joint.lower is not None and joint.upper is not None and _depends(
            [joint.lower, joint.upper], changed):
        lo = validation.evaluate(joint.lower, values, where=f"{where}.limits.lower")
        hi = validation.evaluate(joint.upper, values, where=f"{where}.limits.upper")
        if lo > hi:
            raise DescriptionError(f"{where}.limits: lower limit {lo:g} is above upper limit "
                                   f"{hi:g}")
