"""Physical and naming checks shared by the description loaders (YAML, URDF).

Errors (:class:`DescriptionError`) are for data that cannot describe a rigid body or a readable
description: a negative mass, a non-symmetric inertia tensor, duplicate names, parameter names
that clash with reserved ones. Physically implausible but usable data (an inertia tensor that is
not positive semi-definite or violates the triangle inequality of principal moments) gives a
:class:`DescriptionWarning`, or a :class:`DescriptionError` under ``strict=True``.

A robot whose mass matrix is singular (a moving joint that moves no inertia, e.g. because the
links it carries have no mass) can be used for kinematics but not for forward dynamics or
simulation: :func:`check_mass_matrix` warns, naming the joint and the links.

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
from robodyn.robot.model import Link, Robot

__all__ = [
    "PSD_RTOL",
    "TRIANGLE_RTOL",
    "SINGULAR_RTOL",
    "check_link",
    "check_mass_matrix",
    "mass_matrix_problems",
    "check_parameter_names",
    "check_unique_names",
    "evaluate",
    "inertia_problems",
]

#: An eigenvalue of the inertia tensor below ``-PSD_RTOL * scale`` is negative.
PSD_RTOL = 1e-12
#: Principal moments fail the triangle inequality when ``I1 + I2 < I3 - TRIANGLE_RTOL * scale``.
TRIANGLE_RTOL = 1e-6

#: The mass matrix is singular when its smallest eigenvalue is below ``SINGULAR_RTOL`` times its
#: largest at every sampled configuration.
SINGULAR_RTOL = 1e-12

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


def mass_matrix_problems(robot: Robot, *, missing: Iterable[str] = ()) -> list[str]:
    """Why the robot's joint-space mass matrix is singular at every configuration, if it is.

    ``M(q)`` is assembled numerically as ``sum_k m_k Jv_k^T Jv_k + Jw_k^T R_k I_k R_k^T Jw_k``
    (rigid links only, parameters at their default values) at three pseudo-random
    configurations; drive (rotor) inertia is left out because it does not make the arm's own
    inertia regular.

    Parameters
    ----------
    robot : Robot
    missing : iterable of str
        Names of links the file gave no inertial data (named in the message as such).

    Returns
    -------
    list of str
        One sentence per moving joint that moves no inertia (its diagonal entry of ``M`` is
        zero), or one sentence naming the joints whose motions are dependent; empty when ``M``
        is regular.
    """
    nums = _numeric_robot(robot)
    rng = np.random.default_rng(0)
    with np.errstate(over="ignore", invalid="ignore"):
        samples = [_mass_matrix(nums, rng.uniform(-np.pi, np.pi, robot.dof)) for _ in range(3)]
    if not all(np.isfinite(m).all() for m in samples):
        return []  # magnitudes beyond double range: nothing to say about singularity here
    scale = max(float(np.max(np.abs(m))) for m in samples)
    missing = set(missing)
    problems = []
    if scale == 0.0:
        zero = list(range(robot.dof))
    else:
        zero = [j for j in range(robot.dof)
                if all(m[j, j] <= SINGULAR_RTOL * scale for m in samples)]
    for j in zero:
        carried = [lk.name for lk in robot.links[j:]]
        empty = [n for n in carried if n in missing]
        note = (f"; link(s) {', '.join(map(repr, empty))} have no <inertial>" if empty else "")
        problems.append(
            f"joint {robot.joints[j].name!r} moves no inertia: the links it carries "
            f"({', '.join(map(repr, carried))}) have no mass or inertia about its axis{note}"
        )
    if problems or scale == 0.0:
        return problems
    smallest = [float(np.linalg.eigvalsh(m)[0]) for m in samples]
    if max(smallest) > SINGULAR_RTOL * scale:
        return []
    values, vectors = np.linalg.eigh(samples[0])
    null = np.abs(vectors[:, 0])  # the motion that moves no inertia
    joints = [robot.joints[j].name for j in range(robot.dof) if null[j] > 0.1 * null.max()]
    return [
        f"the motions of joints {', '.join(map(repr, joints))} move the inertia in the same way "
        f"(smallest eigenvalue of M {values[0]:.3g} against largest {values[-1]:.3g}; e.g. "
        "coincident axes with no mass between them)"
    ]


def check_mass_matrix(robot: Robot, *, where: str, strict: bool,
                      missing: Iterable[str] = ()) -> None:
    """Warn (or raise under ``strict``) when the robot's mass matrix is singular.

    Parameters
    ----------
    robot : Robot
    where : str
        The description (file) for the message.
    strict : bool
        Raise :class:`DescriptionError` instead of warning.
    missing : iterable of str
        Links the file gave no inertial data (see :func:`mass_matrix_problems`).

    Warns
    -----
    DescriptionWarning
        Naming the joint that moves no inertia and the links it carries: kinematics work, but
        forward dynamics and simulation need a regular mass matrix.
    """
    problems = mass_matrix_problems(robot, missing=missing)
    if not problems:
        return
    message = (f"{where}: the mass matrix is singular: " + "; ".join(problems)
               + ". Kinematics work, but forward dynamics and simulation need every moving "
               "joint to move some mass or inertia")
    if strict:
        raise DescriptionError(message + " (strict mode)")
    warnings.warn(DescriptionWarning(message), stacklevel=3)


def _numeric_robot(robot: Robot) -> list[tuple[str, np.ndarray, np.ndarray, np.ndarray,
                                               float, np.ndarray, np.ndarray]]:
    """Per joint: type, pre (4, 4), axis (3,), post (4, 4), link mass, com (3,), inertia (3, 3)."""
    subs = {parameter_symbol(k): sp.Float(float(v)) for k, v in robot.parameters.items()}

    def num(e: sp.Basic) -> np.ndarray:
        return np.array(sp.sympify(e).xreplace(subs).evalf(), dtype=float)

    return [(j.type, num(j.pre), num(j.axis).ravel(), num(j.post), float(num(lk.mass)),
             num(lk.com).ravel(), num(lk.inertia))
            for j, lk in zip(robot.joints, robot.links, strict=True)]


def _mass_matrix(nums: Sequence[tuple], q: np.ndarray) -> np.ndarray:
    """Rigid-body mass matrix, shape (n, n), at ``q`` (base frame; the base pose is irrelevant)."""
    n = len(nums)
    t = np.eye(4)
    axes, points, kinds, frames = [], [], [], []
    for (kind, pre, axis, post, *_), qi in zip(nums, q, strict=True):
        t = t @ pre
        a = t[:3, :3] @ axis
        motion = np.eye(4)
        if kind == "revolute":
            k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
            # Rodrigues: R = I + sin q [u]x + (1 - cos q) [u]x^2
            motion[:3, :3] = np.eye(3) + np.sin(qi) * k + (1 - np.cos(qi)) * k @ k
        else:
            motion[:3, 3] = axis * qi
        axes.append(a)
        points.append(t[:3, 3].copy())
        kinds.append(kind)
        t = t @ motion @ post
        frames.append(t)
    m_q = np.zeros((n, n))
    for k, (_, _, _, _, mass, com, inertia) in enumerate(nums):
        r = frames[k][:3, :3]
        c = frames[k][:3, :3] @ com + frames[k][:3, 3]
        jv, jw = np.zeros((3, n)), np.zeros((3, n))
        for j in range(k + 1):
            if kinds[j] == "revolute":
                jw[:, j] = axes[j]
                jv[:, j] = np.cross(axes[j], c - points[j])  # v = w x (c - p)
            else:
                jv[:, j] = axes[j]
        # M += m Jv^T Jv + Jw^T (R I R^T) Jw
        m_q += mass * jv.T @ jv + jw.T @ (r @ inertia @ r.T) @ jw
    return m_q
