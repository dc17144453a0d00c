"""Drive gains from current with a known payload: gains and inertia separated.

With motor current as the target, joint ``j``'s current is its torque through the drive gain
``K_j`` (N m / A)::

    i_j = (Y_j theta + P_j) / K_j                        P = Y_n pi_payload (0 without payload)

where ``theta`` are the base parameters (rigid body, rotor inertia, friction and offset in torque
units). Without a payload, ``(K, theta) -> (c K, c theta)`` leaves every current unchanged: the
data fix the gains only up to one common scale (and a fit with the gains absorbed joint by joint
is as good as any). A run with a known payload breaks the symmetry, because ``P`` does not scale;
together with a run without it (or with another payload), the gains are identified.

Estimation, in two steps:

1. linear: multiplying through by ``K_j`` gives ``K_j i_j - Y_j theta = P_j``, linear in
   ``x = (K, theta)``; solved by least squares on unit-norm columns (the starting point);
2. output error (Gauss-Newton): ``i_j = a_j (Y_j theta + P_j)``, ``a_j = 1 / K_j``, with per-joint
   weights ``1 / sigma_j`` from the residuals, so that the noise of the current enters as
   measured (the multiplied-through form has it in a regressor column and is slightly biased).
   The covariance of ``(a, theta)`` is ``(J^T W J)^-1`` times the weighted residual variance;
   ``std(K_j) = K_j^2 std(a_j)``. A direction of singular value below ``RANK_RTOL`` of the
   largest that involves the gains means they are not identifiable from these runs.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robodyn.identification.estimate import RANK_RTOL, truncated_lstsq
from robodyn.robot.errors import IdentificationError

__all__ = ["DriveGains", "GN_ITERATIONS", "RANK_RTOL", "estimate_drive_gains"]

GN_ITERATIONS = 30


@dataclass(frozen=True, eq=False)
class DriveGains:
    """Result of :func:`estimate_drive_gains`.

    Attributes
    ----------
    gains : numpy.ndarray, shape (n,)
        ``K_j``, N m / A (signed as the current is).
    std : numpy.ndarray, shape (n,)
        Standard deviations of ``K_j``, N m / A.
    theta : numpy.ndarray, shape (b,)
        The base parameters of the same fit (torque units).
    sigma : numpy.ndarray, shape (n,)
        Per-joint residual standard deviation of the current, A.
    iterations : int
        Gauss-Newton iterations run.
    """

    gains: np.ndarray
    std: np.ndarray
    theta: np.ndarray
    sigma: np.ndarray
    iterations: int


def _lstsq(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Truncated-SVD least squares on unit-norm columns: ``x``, scale, singular values, ``V^T``."""
    scale = np.linalg.norm(a, axis=0)
    scale = np.where(scale > 0, scale, 1.0)
    z, s, vt, _ = truncated_lstsq(a / scale, b)
    return z / scale, scale, s, vt


def estimate_drive_gains(phi: np.ndarray, current: np.ndarray, payload: np.ndarray,
                         joint: np.ndarray, names: tuple[str, ...]) -> DriveGains:
    """Drive gains and base parameters from current with a known payload (module docstring).

    Parameters
    ----------
    phi : numpy.ndarray, shape (m, b)
        Identification matrix (base columns), one row per joint per sample.
    current : numpy.ndarray, shape (m,)
        Measured (filtered) current, A.
    payload : numpy.ndarray, shape (m,)
        Known payload torque ``P`` of each row, N m (0 in runs without a payload).
    joint : numpy.ndarray of int, shape (m,)
        Joint of each row.
    names : tuple of str, length n
        Joint names (for messages).

    Returns
    -------
    DriveGains

    Raises
    ------
    IdentificationError
        No payload torque, or the gains not identifiable from these runs.
    """
    n = len(names)
    m, b = phi.shape
    if not np.any(payload != 0):
        raise IdentificationError("payloads: the known payloads add no torque to these runs; "
                                  "the drive gains cannot be separated from the inertia")
    onehot = np.zeros((m, n))
    onehot[np.arange(m), joint] = 1.0
    # K_j i_j - Y_j theta = P_j: linear in (K, theta)
    x, *_ = _lstsq(np.hstack([onehot * current[:, None], -phi]), payload)
    k0 = x[:n]
    if np.any(k0 == 0):
        j = int(np.flatnonzero(k0 == 0)[0])
        raise IdentificationError(f"payloads: the drive gain of joint {names[j]!r} is not seen by "
                                  f"these runs (its current never responds to the payload)")
    a, theta = 1.0 / k0, x[n:]
    w = np.ones(n)
    iterations = 0
    for _ in range(GN_ITERATIONS):
        iterations += 1
        load = phi @ theta + payload  # Y_j theta + P_j
        r = current - a[joint] * load
        sigma = np.array([np.sqrt(np.mean(r[joint == j] ** 2)) for j in range(n)])
        w = 1.0 / np.maximum(sigma, 1e-12 * max(float(sigma.max()), 1e-300))
        if sigma.max() == 0:
            w = np.ones(n)
        # J = [d i / d a_j, d i / d theta] = [load_j e_j, a_j Y_j]
        jac = np.hstack([onehot * load[:, None], a[joint][:, None] * phi])
        dx, *_ = _lstsq(jac * w[joint][:, None], r * w[joint])
        a, theta = a + dx[:n], theta + dx[n:]
        if np.linalg.norm(dx) <= 1e-13 * np.linalg.norm(np.concatenate([a, theta])):
            break
    load = phi @ theta + payload
    r = current - a[joint] * load
    sigma = np.array([np.sqrt(np.mean(r[joint == j] ** 2)) for j in range(n)])
    jac = np.hstack([onehot * load[:, None], a[joint][:, None] * phi]) * w[joint][:, None]
    _, scale, s, vt = _lstsq(jac, r * w[joint])
    keep = s > RANK_RTOL * s[0]
    # an unresolved direction (unit norm in the column-scaled coordinates) touching the gains
    if np.any(np.abs(vt[~keep][:, :n]) > 1e-6):
        raise IdentificationError(
            "payloads: the drive gains are not identifiable from these runs (the payload torque "
            "can be absorbed by the last link's parameters): record at least one run without the "
            "payload, or with a different one, and excite the arm in both")
    rw = r * w[joint]
    # cov = s2 (J^T W J)^-1 on the kept directions, s2 the weighted residual variance
    s2 = float(rw @ rw) / max(m - (n + b), 1)
    cov_z = (vt[keep].T / s[keep] ** 2) @ vt[keep]
    cov = s2 * cov_z / scale[:, None] / scale[None, :]
    std_a = np.sqrt(np.clip(np.diag(cov)[:n], 0.0, np.inf))
    k = 1.0 / a
    # std(K) = K^2 std(a)  (delta method)
    return DriveGains(gains=k, std=k**2 * std_a, theta=theta, sigma=sigma, iterations=iterations)
