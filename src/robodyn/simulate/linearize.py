"""Linearisation ``xd ~ f(x0, u0) + A (x - x0) + B (u - u0)`` from the symbolic equations.

With ``x = [q; qd]`` and the full inverse dynamics ``tau(q, qd, qdd) = M(q) qdd + h(q, qd)``, the
state equation ``xd = f(x, u) = [qd; qdd]`` is defined implicitly by ``tau(q, qd, qdd) = u``.
Differentiating that identity at ``(q0, qd0, qdd0 = FD(q0, qd0, u0))``::

    d tau/dq dq + d tau/dqd dqd + M dqdd = du
    A = [[0, I], [-M^-1 d tau/dq, -M^-1 d tau/dqd]],    B = [[0], [M^-1]]

``d tau/dq`` (which contains ``dM/dq qdd``) and ``d tau/dqd`` are exact symbolic derivatives:
the recursive Newton-Euler program of :func:`robodyn.derive` is differentiated in forward mode
(linear in its size, no expression swell), the robot's parameter values are substituted, and the
result is turned into a Python function once per robot. Friction adds its viscous coefficients to
``d tau/dqd``; Coulomb friction is a step in ``qd`` whose derivative is zero away from ``qd = 0``
and is left out (at ``qd = 0`` it has no derivative).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import sympy as sp
from sympy.printing.pycode import pycode

from robodyn.numeric.model import Model
from robodyn.symbolic.coriolis import program_derivative
from robodyn.symbolic.eom import derive
from robodyn.symbolic.program import Program, Recorder


@dataclass(frozen=True, eq=False)
class Linearization:
    """Local linear model of ``xd = f(x, u)``.

    Attributes
    ----------
    A : (2 n, 2 n) ndarray
    B : (2 n, n) ndarray
    x0 : (2 n,) ndarray
        Linearisation state ``[q0; qd0]``.
    u0 : (n,) ndarray
        Linearisation input (N m or N).
    xd0 : (2 n,) ndarray
        ``f(x0, u0)``; zero at an equilibrium.
    """

    A: np.ndarray
    B: np.ndarray
    x0: np.ndarray
    u0: np.ndarray
    xd0: np.ndarray

    @property
    def is_equilibrium(self) -> bool:
        """True when ``f(x0, u0)`` vanishes (to 1e-9 relative)."""
        return bool(np.max(np.abs(self.xd0)) <= 1e-9 * max(1.0, np.max(np.abs(self.x0))))


_MEMO: dict[tuple, Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray]] = {}


def tau_jacobians(model: Model, q: np.ndarray, qd: np.ndarray,
                  qdd: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Exact ``d tau/dq`` and ``d tau/dqd`` of the full inverse dynamics, (n, n) each."""
    key = (model.robot.description_hash, tuple(sorted(model.parameters.items())))
    if key not in _MEMO:
        _MEMO[key] = _derivative_function(model)
    n = model.dof
    d = _MEMO[key](q, qd, qdd)
    return d[:, :n], d[:, n:]


def linearize(model: Model, q0: np.ndarray, qd0: np.ndarray | None = None,
              u0: np.ndarray | None = None) -> Linearization:
    """Linearise the state equation at ``(x0, u0)``.

    Parameters
    ----------
    model : Model
    q0 : (n,) array_like
    qd0 : (n,) array_like, optional
        Default zero.
    u0 : (n,) array_like, optional
        Default: the torque that makes ``qdd = 0`` (``g(q0)`` at rest), so that ``(x0, u0)`` is an
        equilibrium when ``qd0 = 0``.

    Returns
    -------
    Linearization
    """
    n = model.dof
    q0 = _vec(q0, n, "q0")
    qd0 = np.zeros(n) if qd0 is None else _vec(qd0, n, "qd0")
    u0 = model.inverse_dynamics(q0, qd0, np.zeros(n)) if u0 is None else _vec(u0, n, "u0")
    qdd0 = model.forward_dynamics(q0, qd0, u0)
    m = model.mass_matrix(q0)
    dq, dqd = tau_jacobians(model, q0, qd0, qdd0)
    minv = np.linalg.inv(m)
    a = np.zeros((2 * n, 2 * n))
    a[:n, n:] = np.eye(n)
    # dqdd = M^-1 (du - dtau/dq dq - dtau/dqd dqd)
    a[n:, :n] = -minv @ dq
    a[n:, n:] = -minv @ dqd
    b = np.vstack([np.zeros((n, n)), minv])
    return Linearization(a, b, np.concatenate([q0, qd0]), u0, np.concatenate([qd0, qdd0]))


def _derivative_function(model: Model) -> Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray]:
    """Build ``(q, qd, qdd) -> [d tau/dq, d tau/dqd]`` (n, 2 n) from the Newton-Euler program."""
    robot = model.robot
    eom = derive(robot, "newton_euler")
    prog = eom.program
    assert prog is not None
    rec = Recorder({s.name for s, _ in prog.assignments} | {s.name for s in eom.q + eom.qd + eom.qdd})
    columns = [program_derivative(prog, v, rec) for v in eom.q + eom.qd]
    values = eom.numeric(model.parameters)
    assignments = [(s, e.xreplace(values)) for s, e in prog.assignments + tuple(rec.assignments)]
    n = eom.dof
    viscous = [float(sp.sympify(j.friction.viscous).xreplace(values)) for j in robot.joints]
    jac = sp.Matrix.hstack(*columns).xreplace(values)
    full = Program(tuple(assignments), sp.ImmutableMatrix(jac)).pruned()
    lines = ["def f(q, qd, qdd):"]
    for i in range(n):
        lines.append(f"    {eom.q[i]}, {eom.qd[i]}, {eom.qdd[i]} = q[{i}], qd[{i}], qdd[{i}]")
    for sym, expr in full.assignments:
        lines.append(f"    {sym} = {pycode(expr)}")
    rows = ", ".join("[" + ", ".join(pycode(full.outputs[i, j]) for j in range(2 * n)) + "]"
                     for i in range(n))
    lines.append(f"    return [{rows}]")
    scope: dict[str, object] = {"math": math}
    exec(compile("\n".join(lines), f"<robodyn linearize {robot.name}>", "exec"), scope)  # noqa: S102
    fn = scope["f"]

    def evaluate(q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> np.ndarray:
        d = np.array(fn(q, qd, qdd), dtype=float)  # type: ignore[operator]
        # viscous friction: d tau_f/dqd = diag(Fv)
        d[:, n:] += np.diag(viscous)
        return d

    return evaluate


def _vec(v: np.ndarray, n: int, name: str) -> np.ndarray:
    arr = np.asarray(v, dtype=float)
    if arr.shape != (n,) or not np.all(np.isfinite(arr)):
        raise ValueError(f"linearize: {name} must be a finite ({n},) array, got shape {arr.shape}")
    return arr


__all__ = ["Linearization", "linearize", "tau_jacobians"]
