"""The effort a validation compares: the measured target, drive gains, friction, joint matching.

A recording's target is the joint torque (``"tau"``, N m or N) or the motor current
(``"current"``, A). The model predicts joint torque; with ``target="current"`` it is divided by
each joint's drive gain ``k_j = gear_ratio_j * torque_constant_j`` (joint torque per ampere).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, Literal

import numpy as np
import sympy as sp

from robodyn.robot.errors import ValidationError
from robodyn.robot.model import Robot

__all__ = ["MIN_SAMPLES", "Target", "check_finite", "drive_gains", "friction_torque",
           "ignored_joints", "in_chain_order", "measured_target", "resolve_target", "target_unit"]

Target = Literal["tau", "current"]

#: Fewest samples a validation accepts (the zero-phase filter and the spectra need a few periods).
MIN_SAMPLES = 50


def _where(rec: Any) -> str:
    return getattr(rec, "source", "") or "recording"


def resolve_target(rec: Any, target: str | None) -> Target:
    """``target``, or the recording's measured effort when None (torque first, then current).

    Raises
    ------
    ValidationError
        Unknown target, or the recording lacks it.
    """
    if target is None:
        if getattr(rec, "tau", None) is not None:
            return "tau"
        if getattr(rec, "current", None) is not None:
            return "current"
        raise ValidationError(f"{_where(rec)}: the recording has neither tau nor current; "
                              "nothing to compare the model with")
    if target not in ("tau", "current"):
        raise ValidationError(f"unknown target {target!r}; choose 'tau' (joint torque) or "
                              "'current' (motor current)")
    if getattr(rec, target, None) is None:
        raise ValidationError(f"{_where(rec)}: field {target}: the recording has no {target} "
                              f"column to validate against (target={target!r})")
    return target  # type: ignore[return-value]


def target_unit(target: Target, robot: Robot | None = None) -> str:
    """``"N m"`` (``"N m | N"`` with prismatic joints) for torque, ``"A"`` for current."""
    if target == "current":
        return "A"
    if robot is not None and any(j.type == "prismatic" for j in robot.joints):
        return "N m | N"
    return "N m"


def _numeric(expr: object, values: Mapping[str, float], where: str) -> float:
    """Value of a description expression with the named parameters substituted."""
    e = sp.sympify(expr)
    subs = {s: values[s.name] for s in e.free_symbols if s.name in values}
    try:
        return float(e.subs(subs))
    except TypeError:
        raise ValidationError(f"{where}: expression {e} has unknown symbols "
                              f"{sorted(s.name for s in e.free_symbols)}") from None


def drive_gains(robot: Robot, parameters: Mapping[str, float] | None = None) -> np.ndarray:
    """Joint torque per motor ampere, ``gear_ratio * torque_constant`` per joint.

    The gear ratio keeps its sign (the description's convention: motor angle / joint angle), so
    a drive whose motor turns against its joint draws a current of the opposite sign to the
    joint torque, as :func:`robodyn.measure.conversions.current_to_torque` and the virtual lab
    have it.

    Parameters
    ----------
    robot : Robot
    parameters : mapping, optional
        Named parameter values (default: the robot's defaults).

    Returns
    -------
    (n,) ndarray
        N m / A (N / A for prismatic joints).

    Raises
    ------
    ValidationError
        When a gain is zero or not finite.
    """
    values = {**robot.parameters, **(parameters or {})}
    gains = np.empty(robot.dof)
    for k, j in enumerate(robot.joints):
        where = f"{robot.source}: joints[{k}].drive"
        # k_j = N_j K_t,j (signed: the motor's sense)
        gains[k] = _numeric(j.drive.gear_ratio, values, where) * _numeric(
            j.drive.torque_constant, values, where)
        if not np.isfinite(gains[k]) or gains[k] == 0:
            raise ValidationError(f"{where}: gear_ratio x torque_constant = {gains[k]:g}; a current "
                                  "target needs a non-zero drive gain (give gains=...)")
    return gains


def friction_torque(robot: Robot, qd: np.ndarray,
                    parameters: Mapping[str, float] | None = None) -> np.ndarray:
    """The description's joint friction at velocities ``qd``.

    ``tau_f = viscous qd + coulomb_positive H(qd) - coulomb_negative H(-qd) + offset``
    (see :class:`robodyn.robot.model.Friction`).

    Parameters
    ----------
    robot : Robot
    qd : (N, n) array_like
        Joint velocities, rad/s (m/s).
    parameters : mapping, optional
        Named parameter values (default: the robot's defaults).

    Returns
    -------
    (N, n) ndarray
        N m (N).
    """
    qd = np.asarray(qd, dtype=float)
    values = {**robot.parameters, **(parameters or {})}
    out = np.empty_like(qd)
    for k, j in enumerate(robot.joints):
        f = j.friction
        where = f"{robot.source}: joints[{k}].friction"
        visc, cp, cn, off = (_numeric(v, values, where) for v in
                             (f.viscous, f.coulomb_positive, f.coulomb_negative, f.offset))
        v = qd[..., k]
        # tau_f = b qd + c+ H(qd) - c- H(-qd) + offset
        out[..., k] = visc * v + cp * (v > 0) - cn * (v < 0) + off
    return out


def in_chain_order(robot: Robot, rec: Any) -> Any:
    """The recording with its joints in the robot's chain order.

    Joints are matched by name; joints the robot does not have (a gripper's, say) are left out
    (:func:`ignored_joints` names them). A recording with the generic names ``q1 .. qn`` (no
    names given) and as many joints as the robot is taken in chain order as it is.

    Raises
    ------
    ValidationError
        When the joints do not match (names missing or extra, or a different count).
    """
    names = tuple(getattr(rec, "joint_names", ()) or ())
    want = robot.joint_names
    if names == want:
        return rec
    generic = tuple(f"q{k + 1}" for k in range(len(names)))
    if names == generic and len(names) == robot.dof:
        return rec
    missing = [n for n in want if n not in names]
    extra = [n for n in names if n not in want]
    if not missing and hasattr(rec, "select"):
        return rec.select(list(want))  # extra joints (a gripper's, say) are left out
    raise ValidationError(
        f"{_where(rec)}: joint_names: the recording's joints do not match robot {robot.name!r} "
        f"({robot.dof} joints: {', '.join(want)}); recording has {len(names)}: {', '.join(names)}"
        + (f"; missing {', '.join(missing)}" if missing else "")
        + (f"; not in the robot {', '.join(extra)}" if extra else ""))


def ignored_joints(robot: Robot, rec: Any) -> list[str]:
    """The recording's joints that the robot does not have."""
    return [n for n in (getattr(rec, "joint_names", ()) or ()) if n not in robot.joint_names]


def measured_target(rec: Any, target: Target) -> np.ndarray:
    """The recording's measured ``tau`` or ``current``, (N, n), checked finite.

    A column entirely NaN (that joint has no such sensor) is kept as NaN.

    Raises
    ------
    ValidationError
        Naming the field, row and column of the first value that is not finite.
    """
    y = np.asarray(getattr(rec, target), dtype=float)
    absent = np.all(np.isnan(y), axis=0)
    if absent.all():
        raise ValidationError(f"{_where(rec)}: field {target}: every column is NaN; no joint has "
                              "a measurement to validate against")
    check_finite(rec, target, y, skip=absent)
    return y


def check_finite(rec: Any, field: str, values: np.ndarray, skip: np.ndarray | None = None) -> None:
    """Raise :class:`ValidationError` at the first NaN or infinity of ``values`` (N,) or (N, n).

    ``skip`` (n,) bool marks columns not to check (joints without that sensor).
    """
    mask = ~np.isfinite(values)
    if skip is not None:
        mask &= ~np.asarray(skip, dtype=bool)
    bad = np.argwhere(mask)
    if bad.size:
        row = int(bad[0][0])
        col = int(bad[0][1]) if values.ndim > 1 else 0
        names = tuple(getattr(rec, "joint_names", ()) or ())
        joint = f" ({names[col]})" if col < len(names) else ""
        raise ValidationError(f"{_where(rec)}: field {field}, row {row}, column {col}{joint}: value "
                              f"{values[bad[0][0]] if values.ndim == 1 else values[row, col]} is not "
                              "finite")
