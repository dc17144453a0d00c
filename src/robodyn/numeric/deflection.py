"""Exact static joint deflection: the compliance fixed point solved by Newton's method.

The linear compliance model (:mod:`robodyn.calibration.nongeometric`) evaluates the holding torque
at the joint readings, ``q_link = u - C tau(u)``, with ``u = q + B_h(q) theta_h`` the link angles
the transmission terms give (``u = q`` without them) and ``C = diag(c)``. The joint actually
deflects under the torque at its deflected pose::

    x = u - C tau(x)                      (fixed point, x = q_link)

solved here by Newton's method with the Jacobian of ``F(x) = x - u + C tau(x)``::

    dF/dx = I + C G(x),      G = d tau / d q

(``G`` from the compiled model's analytic derivatives, ``inverse_dynamics_derivatives(x, 0, 0)``:
at zero velocity and acceleration ``d tau / d q = d g / d q``). By the implicit function theorem the
derivatives of the solution with respect to the compliances and to ``u`` are::

    dx/dc_j = -(I + C G)^-1 e_j tau_j(x),      dx/du = (I + C G)^-1

The linear model's error is ``C G C tau`` to first order: about ``5e-3 rad`` of deflection of a
cobot joint (stiffness 1e4 N m/rad under 50 N m) times ``50 N m/rad`` of torque change per radian
gives ``2.5e-5 rad``, 25 um at 1 m.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from robodyn.robot.errors import SimulationError

__all__ = ["Deflection", "DeflectionNotConvergedError", "exact_deflection"]


class DeflectionNotConvergedError(SimulationError):
    """Newton's method found no static equilibrium (compliance so large the arm would fold)."""


@dataclass(frozen=True)
class Deflection:
    """Static equilibrium of compliant joints.

    Attributes
    ----------
    q_link : numpy.ndarray, shape (N, n)
        Deflected link angles ``x`` (rad, m), the fixed point ``x = u - C tau(x)``.
    torque : numpy.ndarray, shape (N, n)
        Holding torques at ``x``, N m (N).
    sensitivity : numpy.ndarray, shape (N, n, n)
        ``(I + C G(x))^-1``: ``dx/du``; ``dx/dc_j = -sensitivity[:, :, j] * torque[:, j]``.
    iterations : int
        Newton steps taken.
    """

    q_link: np.ndarray
    torque: np.ndarray
    sensitivity: np.ndarray
    iterations: int


def exact_deflection(u: np.ndarray, c: np.ndarray,
                     torque: Callable[[np.ndarray], np.ndarray],
                     torque_jacobian: Callable[[np.ndarray], np.ndarray], *,
                     tol: float = 1e-13, max_iter: int = 50) -> Deflection:
    """Solve ``x = u - diag(c) tau(x)`` for every pose by Newton's method.

    Parameters
    ----------
    u : numpy.ndarray, shape (N, n)
        Undeflected link angles (readings plus transmission corrections), rad (m).
    c : numpy.ndarray, shape (n,)
        Compliances, rad/(N m) (m/N); zero for a rigid joint.
    torque : callable
        ``torque(x)``: holding torques (N, n), N m, for link angles (N, n).
    torque_jacobian : callable
        ``torque_jacobian(x)``: ``G = d tau / d x`` (N, n, n), ``[i, j, k] = d tau_j / d x_k``.
    tol : float
        Stop when the largest Newton step is below ``tol`` (rad, m) after at least one step.
    max_iter : int

    Returns
    -------
    Deflection

    Raises
    ------
    DeflectionNotConvergedError
        When the steps do not fall below ``tol`` within ``max_iter`` (the compliance is too large
        for an equilibrium near the readings), or ``I + C G`` is singular.
    """
    u = np.asarray(u, dtype=float)
    c = np.asarray(c, dtype=float)
    n = u.shape[1]
    eye = np.eye(n)
    x = u.copy()
    tau = torque(x)
    if not np.any(c):
        return Deflection(x, tau, np.broadcast_to(eye, (len(u), n, n)).copy(), 0)
    x = u - c * tau  # the linear model's answer: the first iterate
    steps = 0
    for steps in range(1, max_iter + 1):  # noqa: B007 (the count is reported)
        tau = torque(x)
        jac = eye + c[None, :, None] * torque_jacobian(x)  # dF/dx = I + C G
        residual = x - u + c * tau  # F(x) = x - u + C tau(x)
        try:
            step = np.linalg.solve(jac, residual[..., None])[..., 0]
        except np.linalg.LinAlgError:
            raise DeflectionNotConvergedError(
                "exact deflection: I + C dtau/dq is singular at a pose (the compliance is too large "
                "for a static equilibrium)") from None
        x = x - step
        if np.max(np.abs(step)) < tol:
            break
    else:
        raise DeflectionNotConvergedError(
            f"exact deflection: Newton's method did not converge in {max_iter} steps (largest step "
            f"{np.max(np.abs(step)):.3g}); the compliances are too large for an equilibrium near "
            "the readings")
    tau = torque(x)
    jac = eye + c[None, :, None] * torque_jacobian(x)
    return Deflection(x, tau, np.linalg.inv(jac), steps)
