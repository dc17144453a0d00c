"""Physical and naming checks shared by the description loaders (YAML, URDF).

Errors (:class:`DescriptionError`) are for data that cannot describe a rigid body or a readable
description: a negative mass, a non-symmetric inertia tensor, duplicate names, parameter names
that clash with reserved ones. Physically implausible but usable data (an inertia tensor that is
not positive semi-definite or violates the triangle inequality of principal moments) gives a
:class:`DescriptionWarning`, or a :class:`DescriptionError` under ``strict=True``.

Numeric checks are made at the parameters' default values (``Robot.parameters``).
"""

from __future__ import annotations

import keyword
import math
import re
import warnings
from collections.abc import Iterable, Mapping, Sequence

import numpy as np
import sympy as sp

from robodyn.robot.errors import DescriptionError, DescriptionWarning
from robodyn.robot.expressions import CONSTANTS, FUNCTIONS, parameter_symbol
from robodyn.robot.model import Link

__all__ = [
    "PSD_RTOL",
    "TRIANGLE_RTOL",
    "check_link",
    "check_parameter_names",
    "check_unique_names",
    "evaluate",
    "inertia_problems",
]

#: An eigenvalue of the inertia tensor below ``-PSD_RTOL * scale`` is negative.
PSD_RTOL = 1e-12
#: Principal moments fail the triangle inequality when ``I1 + I2 < I3 - TRIANGLE_RTOL * scale``.
TRIANGLE_RTOL = 1e-6

_IDENTIFIER = re.compile(r"[A-Za-z][A-Za-z0-9_]*\Z")
_JOINT_STATE = re.compile(r"(q|qd|qdd)\d+\Z")


def evaluate(expr: sp.Expr, defaults: Mapping[str, float], *, where: str) -> float:
    """Value of a description expression at the parameters' default values.

    Parameters
    ----------
    expr : sympy.Expr
        A description quantity, over parameter symbols (``parameter_symbol(name)``).
    defaults : Mapping[str, float]
        Default value of each named parameter.
    where : str
        File and field path for error messages.

    Returns
    -------
    float

    Raises
    ------
    DescriptionError
        If the expression has a symbol without a default value, or its value is not a finite
        real number.
    """
    e = sp.sympify(expr)
    if e.free_symbols:
        subs = {parameter_symbol(k): v for k, v in defaults.items()}
        e = e.subs(subs)
    if e.free_symbols:
        names = ", ".join(sorted(str(s) for s in e.free_symbols))
        raise DescriptionError(f"{where}: depends on undeclared symbol(s) {names}")
    value = complex(sp.N(e))
    if value.imag != 0 or not math.isfinite(value.real):
        raise DescriptionError(
            f"{where}: value {expr} is not a finite real number at the parameters' "
            f"default values ({sp.N(e)})"
        )
    return value.real


def check_link(
    link: Link,
    *,
    where: str,
    strict: bool,
    defaults: Mapping[str, float],
) -> None:
    """Check a link's mass and inertia for physical plausibility.

    Parameters
    ----------
    link : Link
        The link as a loader built it (mass, com (3, 1), inertia (3, 3) about the centre of mass).
    where : str
        File and field path of the link, e.g. ``"arm.yaml: joints[1].link"``.
    strict : bool
        Raise :class:`DescriptionError` instead of warning for implausible inertia.
    defaults : Mapping[str, float]
        Default values of the named parameters, substituted before the numeric checks.

    Raises
    ------
    DescriptionError
        Negative or non-finite mass, non-finite centre of mass or inertia, non-symmetric inertia;
        with ``strict=True`` also the conditions below.

    Warns
    -----
    DescriptionWarning
        The inertia tensor has a negative principal moment (it is not positive semi-definite), or
        its principal moments violate the triangle inequality ``I1 + I2 >= I3``. Semi-definite
        tensors (point masses, thin rods) are valid and do not warn.
    """
    label = f"{where}: link {link.name!r}"
    mass = evaluate(link.mass, defaults, where=f"{where}.mass")
    if mass < 0:
        raise DescriptionError(
            f"{where}.mass: mass of link {link.name!r} is negative ({link.mass} = {mass:g})"
        )
    for k in range(3):
        evaluate(link.com[k], defaults, where=f"{where}.com[{k}]")
    inertia = link.inertia
    for i in range(3):
        for j in range(i + 1, 3):
            diff = sp.sympify(inertia[i, j] - inertia[j, i])
            if diff != 0 and sp.simplify(diff) != 0:
                raise DescriptionError(
                    f"{where}.inertia: inertia of link {link.name!r} is not symmetric: "
                    f"entry ({i}, {j}) = {inertia[i, j]} but ({j}, {i}) = {inertia[j, i]}"
                )
    values = np.array(
        [[evaluate(inertia[i, j], defaults, where=f"{where}.inertia[{i}][{j}]") for j in range(3)]
         for i in range(3)]
    )
    problems = inertia_problems(values)
    if problems:
        message = f"{label}: implausible inertia tensor: " + "; ".join(problems)
        if strict:
            raise DescriptionError(message + " (strict mode)")
        warnings.warn(DescriptionWarning(message), stacklevel=2)


def inertia_problems(inertia: np.ndarray) -> list[str]:
    """Physical-plausibility conditions a symmetric numeric inertia tensor fails.

    Parameters
    ----------
    inertia : numpy.ndarray, shape (3, 3)
        Symmetric inertia tensor about the centre of mass, kg m^2.

    Returns
    -------
    list of str
        One sentence per failed condition (not positive semi-definite; triangle inequality of
        the principal moments); empty when the tensor is plausible.
    """
    moments = np.linalg.eigvalsh(0.5 * (inertia + inertia.T))  # ascending principal moments
    scale = float(np.max(np.abs(moments)))
    if scale == 0.0:
        return []  # a point mass
    text = ", ".join(f"{m:.6g}" for m in moments)
    problems = []
    if moments[0] < -PSD_RTOL * scale:
        problems.append(
            f"not positive semi-definite (principal moments {text}; {moments[0]:.6g} < 0)"
        )
    i1, i2, i3 = moments
    if i1 + i2 < i3 - TRIANGLE_RTOL * scale:
        problems.append(
            f"principal moments {text} violate the triangle inequality "
            f"I1 + I2 >= I3 ({i1 + i2:.6g} < {i3:.6g})"
        )
    return problems


def check_unique_names(
    names: Sequence[str],
    *,
    what: str,
    where: str,
    paths: Sequence[str] | None = None,
) -> None:
    """Raise when a name occurs twice.

    Parameters
    ----------
    names : sequence of str
        Names in description order.
    what : str
        What they name, for the message ("joint", "link").
    where : str
        The description (file) the names come from.
    paths : sequence of str, optional
        Field path of each name (e.g. ``"joints[2].name"``); positions are used when omitted.

    Raises
    ------
    DescriptionError
        Naming the duplicate and both places it is used.
    """
    labels = list(paths) if paths is not None else [f"{what} #{i}" for i in range(len(names))]
    first: dict[str, int] = {}
    for i, name in enumerate(names):
        if name in first:
            raise DescriptionError(
                f"{where}: {labels[i]}: duplicate {what} name {name!r} "
                f"(first used at {labels[first[name]]})"
            )
        first[name] = i


def check_parameter_names(names: Iterable[str], *, where: str) -> None:
    """Raise when a parameter name is not usable as a symbol in every generated language.

    A parameter name must be an ASCII identifier starting with a letter, not a Python keyword,
    and must not clash with reserved names: the constant ``pi``, the functions of the expression
    parser (``sqrt``, ``sin``, ...) and the joint-state symbols ``q1``, ``qd1``, ``qdd1``, ...

    Parameters
    ----------
    names : iterable of str
        Declared parameter names.
    where : str
        File and field path of the declaration, e.g. ``"arm.yaml: parameters"``.

    Raises
    ------
    DescriptionError
    """
    for name in names:
        if not isinstance(name, str) or not _IDENTIFIER.match(name):
            raise DescriptionError(
                f"{where}: parameter name {name!r} is not valid: use ASCII letters, digits and "
                f"underscores, starting with a letter"
            )
        if keyword.iskeyword(name):
            raise DescriptionError(f"{where}: parameter name {name!r} is a reserved word")
        if name in CONSTANTS or name in FUNCTIONS:
            raise DescriptionError(
                f"{where}: parameter name {name!r} is reserved (constant or function of the "
                f"expression syntax)"
            )
        if _JOINT_STATE.match(name):
            raise DescriptionError(
                f"{where}: parameter name {name!r} is reserved for joint-state symbols "
                f"(q<i>, qd<i>, qdd<i>)"
            )
