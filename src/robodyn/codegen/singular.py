"""Robots whose mass matrix is singular in every configuration, seen in their generated kernels.

A joint that moves no mass, inertia or rotor inertia (a massless final link, or a kinematics-only
description such as a calibration's) makes the symbolic Cholesky pivot of the forward dynamics
fold to ``1/0``: SymPy's ``zoo`` then sits in the kernels, where no printer can write it.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping

import numpy as np
import sympy as sp

from robodyn.codegen.kernels import KernelSet
from robodyn.robot.model import Robot

__all__ = ["structural_singularity", "without_infinities"]


def _infinite(e: sp.Expr) -> bool:
    return bool(sp.sympify(e).has(sp.zoo, sp.nan, sp.oo))


def without_infinities(kset: KernelSet) -> KernelSet:
    """``kset`` with every ``zoo``/``oo``/``nan`` the symbolic folding left (the Cholesky pivot of
    a mass matrix that is singular everywhere) replaced by NaN: the kernels of such a robot
    print and compile, and its forward dynamics returns NaN instead of a printer error."""
    def fix(e: sp.Expr) -> sp.Expr:
        return sp.nan if _infinite(e) else e  # zoo, oo and nan never fold back to a number

    kernels = []
    for k in kset.kernels:
        body = tuple((s, fix(e)) for s, e in k.body)
        outputs = tuple(dataclasses.replace(a, entries=tuple(fix(e) for e in a.entries))
                        for a in k.outputs)
        kernels.append(dataclasses.replace(k, body=body, outputs=outputs))
    return dataclasses.replace(kset, kernels=tuple(kernels))


def structural_singularity(robot: Robot, kset: KernelSet, values: Mapping[str, float]) -> str | None:
    """Why the mass matrix is singular in every configuration (a joint that moves no mass,
    inertia or rotor inertia), or None when it is not."""
    fd = kset["forward_dynamics"]
    exprs = [e for _, e in fd.body] + list(fd.outputs[0].entries)
    if not any(_infinite(e) for e in exprs):
        return None
    mass = kset["mass_matrix"]
    env: dict[sp.Symbol, sp.Expr] = dict.fromkeys(mass.inputs[0].entries, sp.Float(0.3))
    if kset.runtime_parameters:
        # runtime parameters at their default values
        env.update({s: sp.Float(values[k]) for s, k in zip(mass.inputs[-1].entries,
                                                            kset.runtime_parameters, strict=True)})
    for sym, expr in mass.body:
        env[sym] = expr.xreplace(env).evalf()
    m = np.array([float(sp.sympify(e).xreplace(env).evalf()) for e in mass.outputs[0].entries])
    diag = np.diag(m.reshape(robot.dof, robot.dof))
    j = int(np.argmin(np.abs(diag)))
    joint, link = robot.joints[j].name, robot.links[j].name
    return (
        f"{robot.source}: the mass matrix of {robot.name} is singular in every configuration "
        f"(M[{j}, {j}] = {diag[j]:.3g} for joint {joint!r}): joint {joint!r} moves no mass, "
        f"inertia or rotor inertia, so the forward dynamics has no solution; give link {link!r} "
        "(or the links beyond it) a mass and an inertia, or the joint a rotor inertia")
