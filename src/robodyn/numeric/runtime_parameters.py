"""Values of the runtime parameters of a compiled model, as the kernels' ``p`` input.

A model compiled with ``compile_model(robot, runtime_parameters=...)`` keeps those named
parameters (``robot.parameters``) as inputs of every kernel instead of folding them into the
code: one value per parameter, per state or per trajectory. This module turns what a caller
gives (nothing, a mapping, a sequence of mappings, an array) into that input, checked.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import sympy as sp

from robodyn.robot.errors import InputError
from robodyn.robot.expressions import parameter_symbol
from robodyn.robot.model import Robot
from robodyn.robot.overrides import checked_parameter_values

__all__ = ["ParameterValues", "check_physics", "parameter_array", "runtime_names"]

#: Runtime parameter values: a mapping (name -> value), a sequence of N mappings, or an array
#: (P,) / (N, P) in the order of :attr:`robodyn.numeric.model.Model.runtime_parameters`.
ParameterValues = Mapping[str, float] | Sequence[Mapping[str, float]] | np.ndarray | None


def runtime_names(robot: Robot, runtime: bool | Sequence[str]) -> tuple[str, ...]:
    """The names of ``compile_model(runtime_parameters=...)``, checked.

    Parameters
    ----------
    robot : Robot
    runtime : bool or sequence of str
        True: every named parameter of the description, in its order; False: none; or names.

    Returns
    -------
    tuple of str

    Raises
    ------
    ValueError
        Unknown or repeated names, or True for a description without named parameters.
    """
    if runtime is False or runtime is None:
        return ()
    if runtime is True:
        if not robot.parameters:
            raise InputError(f"compile_model(runtime_parameters=True): robot {robot.name!r} "
                             f"({robot.source}) declares no named parameters (a 'parameters:' "
                             "block); nothing can stay a runtime input")
        return tuple(robot.parameters)
    if isinstance(runtime, str):
        raise InputError("compile_model(runtime_parameters=...): give a sequence of names or True, "
                         f"not the string {runtime!r}")
    names = tuple(runtime)
    unknown = [k for k in names if k not in robot.parameters]
    if unknown:
        raise InputError(f"compile_model(runtime_parameters=...): robot {robot.name!r} has no "
                         f"parameter(s) {', '.join(map(repr, unknown))}; it has "
                         f"{', '.join(robot.parameters) or 'none'}")
    if len(set(names)) != len(names):
        raise InputError(f"compile_model(runtime_parameters=...): a name is repeated in {names}")
    return names


def parameter_array(names: tuple[str, ...], defaults: Mapping[str, float], value: object,
                    batch: tuple[int, ...], where: str) -> np.ndarray:
    """The ``p`` input: (P,) for one state, ``batch + (P,)`` for a batch, C-contiguous float64.

    Parameters
    ----------
    names : tuple of str
        The runtime parameters, in the kernels' order (P of them).
    defaults : mapping of str to float
        Values used for the names ``value`` leaves out.
    value : None, mapping, sequence of mappings, or array (P,) / (N, P)
        None: the defaults; a mapping: defaults overridden by name (every state); a sequence
        of N mappings: one set per state; an array: values in the order of ``names``, one row
        for every state or one per state.
    batch : tuple of int
        ``()`` for one state, ``(N,)`` for a batch.
    where : str
        The caller, for messages.

    Raises
    ------
    ValueError
        Unknown names, wrong shape, a number of rows other than N, non-finite values (the row
        and the parameter are named).
    """
    count = len(names)
    base = np.array([float(defaults[k]) for k in names], dtype=np.float64)
    if value is None:
        rows = base
    elif isinstance(value, Mapping):
        rows = _row(names, base, value, where)
    elif (isinstance(value, Sequence) and not isinstance(value, str) and len(value) > 0
          and all(isinstance(v, Mapping) for v in value)):
        rows = np.stack([_row(names, base, v, f"{where}[{i}]") for i, v in enumerate(value)])
    else:
        try:
            rows = np.array(value, dtype=np.float64)
        except (TypeError, ValueError) as exc:
            raise InputError(f"{where}: expected a mapping of parameter values, a sequence of "
                             f"them, or an array of shape ({count},) or (N, {count}) in the order "
                             f"{', '.join(names)}: {exc}") from None
        if rows.ndim not in (1, 2) or rows.shape[-1] != count:
            raise InputError(f"{where}: an array of parameter values must have shape ({count},) "
                             f"or (N, {count}) (columns {', '.join(names)}), got {rows.shape}")
    if rows.ndim == 2:
        if not batch:
            raise InputError(f"{where}: {rows.shape[0]} parameter sets for one state; give one "
                             "set, or a batch of states")
        if rows.shape[0] != batch[0]:
            raise InputError(f"{where}: {rows.shape[0]} parameter sets for a batch of {batch[0]} "
                             "states; give one set, or one per state")
    bad = np.argwhere(~np.isfinite(np.atleast_2d(rows)))
    if bad.size:
        i, j = (int(v) for v in bad[0])
        raise InputError(f"{where}: parameter {names[j]!r} is not finite "
                         f"({np.atleast_2d(rows)[i, j]}) in row {i}")
    if batch and rows.ndim == 1:
        rows = np.broadcast_to(rows, (*batch, count))
    return np.ascontiguousarray(rows)


def check_physics(robot: Robot, names: tuple[str, ...], defaults: Mapping[str, float],
                  rows: np.ndarray, where: str) -> None:
    """Every parameter set of ``rows`` (P,) or (N, P) checked like compile-time values.

    The description's rules that depend on parameters (:func:`checked_parameter_values`: link
    mass not negative, centre of mass and inertia finite, rotor inertia, friction, velocity and
    effort limits not negative, gear ratio not zero, lower limit not above upper, placement
    finite) are screened for all sets at once with NumPy; a set that breaks one, and the first
    set, go through :func:`checked_parameter_values` itself, which raises the project's error
    naming the row (the implausible-inertia warning is given for the first set only).

    Raises
    ------
    DescriptionError
        A set that makes a quantity physically impossible (a negative mass, ...); the message
        names the row.
    """
    table = np.atleast_2d(rows)
    suspects = [0] + [int(i) for i in np.flatnonzero(_screen(robot, names, defaults, table))]
    for i in dict.fromkeys(suspects):
        values = {**defaults, **dict(zip(names, (float(v) for v in table[i]), strict=True))}
        checked_parameter_values(robot, values, where=f"{where} row {i}")


_SCREENS: dict[tuple, list[tuple[str, object]]] = {}


def _screen(robot: Robot, names: tuple[str, ...], defaults: Mapping[str, float],
            table: np.ndarray) -> np.ndarray:
    """(N,) bool: the sets that break a rule of :func:`check_physics` (vectorised screen)."""
    symbols = [parameter_symbol(k) for k in robot.parameters]
    key = (robot.description_hash, tuple(robot.parameters))
    if key not in _SCREENS:
        rules: list[tuple[str, object]] = []

        def add(kind: str, *exprs: object) -> None:
            if all(e is not None for e in exprs):
                parts = [sp.sympify(e) for e in exprs]
                if any(e.free_symbols for e in parts):
                    rules.append((kind, sp.lambdify(symbols, parts, modules="numpy")))

        for link in robot.links:
            add("nonnegative", link.mass)
            for e in (*link.com, *link.inertia):
                add("finite", e)
        for joint in robot.joints:
            for e in (*joint.pre, *joint.axis, *joint.post):
                add("finite", e)
            for e in (joint.drive.rotor_inertia, joint.friction.viscous,
                      joint.friction.coulomb_positive, joint.friction.coulomb_negative,
                      joint.velocity_limit, joint.effort_limit):
                add("nonnegative", e)
            add("finite", joint.drive.torque_constant)
            add("finite", joint.friction.offset)
            add("nonzero", joint.drive.gear_ratio)
            add("ordered", joint.lower, joint.upper)
        _SCREENS[key] = rules
    count = table.shape[0]
    columns = {k: np.full(count, float(defaults[k])) for k in robot.parameters}
    for j, k in enumerate(names):
        columns[k] = table[:, j]
    args = [columns[k] for k in robot.parameters]
    bad = np.zeros(count, dtype=bool)
    with np.errstate(all="ignore"):
        for kind, fn in _SCREENS[key]:
            vals = [np.broadcast_to(np.asarray(v, dtype=float), (count,))
                    for v in fn(*args)]  # type: ignore[operator]
            ok = np.all([np.isfinite(v) for v in vals], axis=0)
            if kind == "nonnegative":
                ok &= vals[0] >= 0
            elif kind == "nonzero":
                ok &= vals[0] != 0
            elif kind == "ordered":
                ok &= vals[0] <= vals[1]
            bad |= ~ok
    return bad


def _row(names: tuple[str, ...], base: np.ndarray, value: Mapping[str, object],
         where: str) -> np.ndarray:
    """Defaults overridden by a mapping of runtime parameter values."""
    unknown = [k for k in value if k not in names]
    if unknown:
        raise InputError(f"{where}: {', '.join(map(repr, unknown))} is not a runtime parameter of "
                         f"this model (runtime: {', '.join(names)}); compile it with "
                         "runtime_parameters naming it, or compile_model(parameters=...) for a "
                         "fixed value")
    row = base.copy()
    for k, v in value.items():
        try:
            row[names.index(k)] = float(v)  # type: ignore[arg-type]
        except (TypeError, ValueError):
            raise InputError(f"{where}: parameter {k!r} must be a number, got {v!r}") from None
    return row
