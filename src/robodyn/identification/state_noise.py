"""Torque variance from the noise of the joint states, by the model's analytic derivatives.

The regressor of an identification is evaluated at estimated states (filtered positions, their
derivatives), which carry noise of standard deviations ``s_q``, ``s_qd``, ``s_qdd`` (n,) per joint.
To first order, independent state noise makes the model torque of joint ``i`` at one sample
uncertain by::

    sigma_tau,i^2 = sigma_meas,i^2 + sum_j (dtau_i/dq_j)^2 s_q,j^2 + (dtau_i/dqd_j)^2 s_qd,j^2
                    + M_ij^2 s_qdd,j^2

with ``(dtau/dq, dtau/dqd)`` the analytic derivatives of the inverse dynamics
(:meth:`Model.inverse_dynamics_derivatives`) and ``dtau/dqdd = M`` the mass matrix, at the
current parameter estimate. Either the model is the estimate itself (``rd.compile_model(
ident.robot)``), or a standard parameter vector ``p`` is given and the derivatives are those of
``tau = Y(q, qd, qdd) p``: ``dtau/dx = (dY/dx) p`` (:meth:`Model.regressor_derivatives`, no
new compilation per estimate). Coulomb steps have derivative 0 (exact away from ``qd = 0``).

Used as the errors-in-variables weighting of :func:`robodyn.identification` (``weights="state-noise"``:
each row weighted by ``1 / sigma_tau`` of its sample and joint).
"""

from __future__ import annotations

import numpy as np

from robodyn.numeric.model import Model
from robodyn.robot.errors import IdentificationError

__all__ = ["state_noise_std", "torque_variance"]


def state_noise_std(value: object, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Validate ``(s_q, s_qd, s_qdd)``: three finite, non-negative scalars or (n,) arrays."""
    try:
        parts = list(value)  # type: ignore[call-overload]
    except TypeError as exc:
        raise IdentificationError(f"state_noise: expected (s_q, s_qd, s_qdd), got {value!r}") from exc
    if len(parts) != 3:
        raise IdentificationError(f"state_noise: expected 3 entries (s_q, s_qd, s_qdd), got {len(parts)}")
    out = []
    for name, part in zip(("s_q", "s_qd", "s_qdd"), parts, strict=True):
        a = np.broadcast_to(np.asarray(part, dtype=float), (n,)).copy() if np.ndim(part) == 0 \
            else np.asarray(part, dtype=float).copy()
        if a.shape != (n,):
            raise IdentificationError(f"state_noise.{name}: expected a scalar or shape ({n},), "
                                      f"got {a.shape}")
        if not np.all(np.isfinite(a)) or np.any(a < 0):
            raise IdentificationError(f"state_noise.{name}: must be finite and >= 0, got {a.tolist()}")
        out.append(a)
    return out[0], out[1], out[2]


def torque_variance(model: Model, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray,
                    s_q: np.ndarray, s_qd: np.ndarray, s_qdd: np.ndarray, *,
                    standard: np.ndarray | None = None, threads: int = 1) -> np.ndarray:
    """Propagated variance of the model torque (module docstring), without the measurement term.

    Parameters
    ----------
    model : Model
        Compiled model; the estimate itself when ``standard`` is None.
    q, qd, qdd : numpy.ndarray, shape (N, n)
        States (rad, rad/s, rad/s^2).
    s_q, s_qd, s_qdd : numpy.ndarray, shape (n,)
        Standard deviations of the state noise per joint (rad, rad/s, rad/s^2).
    standard : numpy.ndarray, shape (15 n,), optional
        Standard parameters of the estimate; then ``dtau/dx = (dY/dx) p``.
    threads : int

    Returns
    -------
    numpy.ndarray, shape (N, n)
        ``sum_j (dtau_i/dq_j)^2 s_q,j^2 + (dtau_i/dqd_j)^2 s_qd,j^2 + (dtau_i/dqdd_j)^2 s_qdd,j^2``,
        (N m)^2.
    """
    q, qd, qdd = (np.atleast_2d(np.asarray(a, dtype=float)) for a in (q, qd, qdd))
    if standard is None:
        d_q, d_qd = model.inverse_dynamics_derivatives(q, qd, qdd, threads=threads)
        d_qdd = model.mass_matrix(q, threads=threads)
    else:
        y_q, y_qd, y_qdd = model.regressor_derivatives(q, qd, qdd, threads=threads)
        # dtau_i/dx_j = sum_c dY_ic/dx_j p_c
        d_q, d_qd, d_qdd = (np.einsum("kicj,c->kij", y, standard) for y in (y_q, y_qd, y_qdd))
    # sigma^2 = (dtau/dq)^2 s_q^2 + (dtau/dqd)^2 s_qd^2 + M^2 s_qdd^2, summed over j
    return d_q**2 @ s_q**2 + d_qd**2 @ s_qd**2 + d_qdd**2 @ s_qdd**2
