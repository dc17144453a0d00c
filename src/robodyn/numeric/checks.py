"""Checks of the compiled model's inputs and generated structure (helpers of :mod:`.model`)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import sympy as sp

from robodyn.codegen.kernels import KernelSet
from robodyn.robot.errors import SingularMassMatrixError
from robodyn.robot.model import Robot

__all__ = ["check_structure", "out_buffer"]


def out_buffer(out: np.ndarray, shape: tuple[int, ...], inputs: Sequence[np.ndarray],
               name: str) -> np.ndarray:
    """``out`` as a view of ``shape``, checked: float64, C-contiguous, writeable, right size."""
    if not isinstance(out, np.ndarray) or out.dtype != np.float64 or not out.flags.c_contiguous \
            or not out.flags.writeable:
        raise ValueError(f"{name}(out=...): expected a writeable C-contiguous float64 NumPy array, "
                         f"got {type(out).__name__}"
                         + (f" of dtype {out.dtype}" if isinstance(out, np.ndarray) else ""))
    size = int(np.prod(shape))
    if out.size != size:
        raise ValueError(f"{name}(out=...): the result has shape {shape} ({size} values), out has "
                         f"shape {out.shape} ({out.size} values)")
    if any(np.shares_memory(out, a) for a in inputs):
        raise ValueError(f"{name}(out=...): out overlaps an input array")
    return out.reshape(shape)


def check_structure(robot: Robot, kset: KernelSet, values: Mapping[str, float]) -> None:
    """Refuse a mass matrix that is singular everywhere: the Cholesky pivot folds to ``1/0``."""
    fd = kset["forward_dynamics"]
    exprs = [e for _, e in fd.body] + list(fd.outputs[0].entries)
    if not any(sp.sympify(e).has(sp.zoo, sp.nan, sp.oo) for e in exprs):
        return
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
    raise SingularMassMatrixError(
        f"{robot.source}: the mass matrix of {robot.name} is singular in every configuration "
        f"(M[{j}, {j}] = {diag[j]:.3g} for joint {joint!r}): joint {joint!r} moves no mass, "
        f"inertia or rotor inertia, so the forward dynamics has no solution; give link {link!r} "
        "(or the links beyond it) a mass and an inertia, or the joint a rotor inertia")
