"""Potential energy and link-frame positions of a compiled model, from its symbolic kinematics.

The compiled :class:`~robodyn.numeric.model.Model` has no energy kernel, so the potential energy
is built once per robot (and parameter values) from the symbolic forward kinematics::

    V(q) = - sum_i m_i g . p_ci(q)  +  sum_i rho V_i g . p_Bi(q)

with ``p_ci`` the centre of mass of link ``i`` in the world frame, ``g`` the gravity vector and,
for a robot under water (``fluid``/``hydro`` blocks), the buoyancy potential of each wet link:
displaced volume ``V_i`` at its centre of buoyancy ``p_Bi`` in a fluid of density ``rho``
(:mod:`robodyn.symbolic.hydro.buoyancy`). The compiled mass matrix holds the added mass, so the kinetic
energy ``1/2 qd^T M qd`` of a simulation includes the added-mass (fluid) kinetic energy, and
``K + V`` is conserved in a passive run without drag, skin friction and lift.
It is exact (no quadrature) and consistent with the model's gravity load: ``dV/dq = g(q)``, the
torque that holds the arm still (checked in the tests). The expression is turned into a NumPy
function by ``sympy.lambdify`` and memoised.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import sympy as sp

from robodyn import spatial as S
from robodyn.numeric.model import Model
from robodyn.robot.errors import InputError
from robodyn.robot.hydro import fluid_of, hydro_of
from robodyn.symbolic.kinematics import forward_kinematics, joint_symbols

_MEMO: dict[tuple, Callable[..., object]] = {}


def _key(model: Model, what: str) -> tuple:
    runtime = model.runtime_parameters
    folded = tuple(sorted((k, v) for k, v in model.parameters.items() if k not in runtime))
    return (what, model.robot.description_hash, folded, runtime)


def _values(model: Model) -> dict[sp.Symbol, float]:
    """The folded parameter values (runtime parameters stay symbols, arguments of the function)."""
    return {sp.Symbol(k, real=True): float(v) for k, v in model.parameters.items()
            if k not in model.runtime_parameters}


def potential_energy(model: Model, q: np.ndarray, parameters: object = None) -> np.ndarray:
    """Potential energy ``V(q) = -sum_i m_i g . p_ci`` (J), plus the buoyancy potential
    ``sum_i rho V_i g . p_Bi`` under water; () for (n,), (N,) for (N, n).

    The zero of ``V`` is at the world origin's height. ``parameters``: values of the model's
    runtime parameters, one set or one per state (as every :class:`Model` method takes them).
    """
    key = _key(model, "V")
    if key not in _MEMO:
        qs, _, _ = joint_symbols(model.dof)
        kin = forward_kinematics(model.robot, qs)
        v = sp.Integer(0)
        for link, t in zip(model.robot.links, kin.links, strict=True):
            # p_c = R_i c_i + o_i
            p_c = S.rotation(t) * link.com + S.translation(t)
            # V -= m g . p_c
            v -= link.mass * (model.robot.gravity.T * p_c)[0, 0]
        fluid = fluid_of(model.robot)
        if fluid is not None:
            for h, t in zip(hydro_of(model.robot), kin.links, strict=True):
                if h is not None:
                    # V += rho V_B g . p_B (buoyancy: a mass -rho V_B at the centre of buoyancy)
                    p_b = S.rotation(t) * h.center_of_buoyancy + S.translation(t)
                    v += fluid.density * h.volume * (model.robot.gravity.T * p_b)[0, 0]
        prm = [sp.Symbol(k, real=True) for k in model.runtime_parameters]
        _MEMO[key] = sp.lambdify([*qs, *prm], v.xreplace(_values(model)), modules="numpy", cse=True)
    q = _states(model, q)
    p = (model.parameter_input(parameters, q.shape[:-1], "potential_energy")
         if model.runtime_parameters else np.empty(q.shape[:-1] + (0,)))
    out = np.asarray(_MEMO[key](*q.T, *p.T), dtype=float)
    return np.broadcast_to(out, q.shape[:-1]).copy()


def frame_origins(model: Model, q: np.ndarray) -> np.ndarray:
    """World positions of the base, every link frame origin and the tool point (m).

    Returns
    -------
    (n + 2, 3) for one state, (N, n + 2, 3) for a batch: a stick figure of the arm.
    """
    # (runtime parameters at the model's values)
    key = ("points", model.robot.description_hash, tuple(sorted(model.parameters.items())))
    if key not in _MEMO:
        qs, _, _ = joint_symbols(model.dof)
        kin = forward_kinematics(model.robot, qs)
        frames = (sp.ImmutableMatrix(model.robot.base),) + kin.links + (kin.end_effector,)
        every = {sp.Symbol(k, real=True): float(v) for k, v in model.parameters.items()}
        pts = sp.Matrix([list(S.translation(f)) for f in frames]).xreplace(every)
        _MEMO[key] = sp.lambdify(qs, pts, modules="numpy", cse=True)
    q = _states(model, q)
    fn = _MEMO[key]
    if q.ndim == 1:
        return np.asarray(fn(*q), dtype=float)
    return np.stack([np.asarray(fn(*row), dtype=float) for row in q])


def _states(model: Model, q: np.ndarray) -> np.ndarray:
    q = np.asarray(q, dtype=float)
    if q.ndim not in (1, 2) or q.shape[-1] != model.dof:
        raise InputError(f"q must have shape ({model.dof},) or (N, {model.dof}), got {q.shape}")
    return q


__all__ = ["frame_origins", "potential_energy"]
