"""Linearisation ``xd ~ f(x0, u0) + A (x - x0) + B (u - u0)`` from the generated derivatives.

With ``x = [q; qd]`` and the full inverse dynamics ``tau(q, qd, qdd) = M(q) qdd + h(q, qd)``, the
state equation ``xd = f(x, u) = [qd; qdd]`` is defined implicitly by ``tau(q, qd, qdd) = u``.
Differentiating that identity at ``(q0, qd0, qdd0 = FD(q0, qd0, u0))``::

    d tau/dq dq + d tau/dqd dqd + M dqdd = du
    A = [[0, I], [-M^-1 d tau/dq, -M^-1 d tau/dqd]],    B = [[0], [M^-1]]

The lower blocks are :meth:`robodyn.numeric.model.Model.forward_dynamics_derivatives`: generated
code from the forward-mode derivative of the recorded Newton-Euler program (exact, including
rotor inertia, viscous friction and, under water, the hydrodynamic terms), solved with the
Cholesky factor of ``M``. Coulomb friction is a step in ``qd`` whose derivative is zero away from
``qd = 0`` and is left out (at ``qd = 0`` it has no derivative).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robodyn.numeric.model import Model
from robodyn.robot.errors import InputError


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


def tau_jacobians(model: Model, q: np.ndarray, qd: np.ndarray,
                  qdd: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Exact ``d tau/dq`` and ``d tau/dqd`` of the full inverse dynamics, (n, n) each.

    The same as ``model.inverse_dynamics_derivatives(q, qd, qdd)`` (kept for existing callers).
    """
    dq, dqd = model.inverse_dynamics_derivatives(q, qd, qdd)
    return np.array(dq), np.array(dqd)


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
    dq, dqd, dtau = model.forward_dynamics_derivatives(q0, qd0, u0)
    a = np.zeros((2 * n, 2 * n))
    a[:n, n:] = np.eye(n)
    # dqdd = M^-1 (du - dtau/dq dq - dtau/dqd dqd)
    a[n:, :n] = dq
    a[n:, n:] = dqd
    b = np.vstack([np.zeros((n, n)), dtau])
    return Linearization(a, b, np.concatenate([q0, qd0]), u0, np.concatenate([qd0, qdd0]))


def _vec(v: np.ndarray, n: int, name: str) -> np.ndarray:
    arr = np.asarray(v, dtype=float)
    if arr.shape != (n,) or not np.all(np.isfinite(arr)):
        raise InputError(f"linearize: {name} must be a finite ({n},) array, got shape {arr.shape}")
    return arr


__all__ = ["Linearization", "linearize", "tau_jacobians"]
