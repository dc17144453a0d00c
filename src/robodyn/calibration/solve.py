"""Weighted nonlinear least squares of an error model's parameters on measured poses.

Residuals are ``(measured - predicted) / sigma`` for every coordinate of every measured target
position, plus ``log(R_measured R_predicted^T) / sigma_rot`` (a rotation vector, world frame)
when orientations are measured. They are minimised over the identifiable parameters by
Levenberg-Marquardt (MINPACK, through :func:`scipy.optimize.least_squares`, ``method="lm"``)
with the analytic Jacobian of :mod:`robodyn.calibration.kinematics`; a robust loss (Huber,
soft-L1, Cauchy, arctan) switches to the trust-region reflective method, which supports it.

Standard uncertainties: ``cov = s^2 (J^T J)^-1`` with ``J`` the weighted Jacobian at the solution
and ``s^2 = sum(r^2) / (m - L)`` the residual variance factor (``s`` is about 1 when ``sigma``
is right), for m residuals and L parameters.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from robodyn.calibration.models import ErrorModel
from robodyn.robot.errors import InputError

__all__ = ["LOSSES", "Fit", "covariance", "fit", "rotation_vector"]

#: Loss functions accepted by :func:`fit`.
LOSSES = ("linear", "huber", "soft_l1", "cauchy", "arctan")


def rotation_vector(r: np.ndarray) -> np.ndarray:
    """Rotation vectors (axis times angle, rad) of rotations of shape (N, 3, 3), shape (N, 3)."""
    v = 0.5 * np.stack((r[:, 2, 1] - r[:, 1, 2], r[:, 0, 2] - r[:, 2, 0], r[:, 1, 0] - r[:, 0, 1]), 1)
    s = np.linalg.norm(v, axis=1)
    c = 0.5 * (np.trace(r, axis1=1, axis2=2) - 1.0)
    angle = np.arctan2(s, c)
    # angle / sin(angle), 1 at zero
    k = np.where(s > 1e-12, angle / np.where(s > 1e-12, s, 1.0), 1.0 + angle**2 / 6)
    out = v * k[:, None]
    big = c < -0.99  # near pi: axis from the symmetric part
    for i in np.flatnonzero(big):
        w, vec = np.linalg.eigh((r[i] + r[i].T) / 2)
        axis = vec[:, np.argmax(w)]
        if axis @ v[i] < 0:
            axis = -axis
        out[i] = axis * angle[i]
    return out


def covariance(j: np.ndarray, s2: float) -> np.ndarray:
    """``s^2 (J^T J)^-1`` for a weighted Jacobian ``j`` (m, L) with independent columns.

    Through the column-scaled normal matrix ``D J^T J D`` (``D`` = 1 / column norms), formed by
    :func:`numpy.einsum`, and its eigendecomposition (L x L): no LAPACK call on the tall ``J``,
    whose multithreaded BLAS can take seconds on a busy machine for what one thread does in
    milliseconds. Directions below 1e-15 of the largest scaled eigenvalue (singular values below
    3e-8 of the largest) count as unidentified (infinite variance).
    """
    g = np.einsum("ki,kj->ij", j, j)
    norms = np.sqrt(np.diag(g))
    d = 1.0 / np.where(norms > 0, norms, 1.0)
    w, v = np.linalg.eigh(g * d[:, None] * d[None, :])
    inv_w = np.where(w > w[-1] * 1e-15, 1.0 / np.where(w > 0, w, 1.0), np.inf)
    # (D G D)^-1 = V diag(1/w) V^T, so G^-1 = D V diag(1/w) V^T D
    return (d[:, None] * ((v * inv_w) @ v.T) * d[None, :]) * s2


@dataclass(frozen=True, eq=False)
class Fit:
    """Result of :func:`fit`.

    Attributes
    ----------
    params : numpy.ndarray, shape (P,)
        All parameters (the fixed ones at their given values).
    free : numpy.ndarray of int, shape (L,)
        The estimated ones.
    covariance : numpy.ndarray, shape (L, L)
        Covariance of the estimated parameters (m^2, rad^2, m rad).
    residuals : numpy.ndarray, shape (N, 3)
        Measured minus predicted target positions, m.
    rotation_residuals : numpy.ndarray or None, shape (N, 3)
        ``log(R_measured R_predicted^T)``, rad.
    variance_factor : float
        ``s^2``, the weighted residual sum of squares over the degrees of freedom.
    nfev : int
        Residual evaluations.
    success : bool
    message : str
    jacobian : numpy.ndarray, shape (m, L)
        Weighted residual Jacobian at the solution (``-J / sigma``).
    """

    params: np.ndarray
    free: np.ndarray
    covariance: np.ndarray
    residuals: np.ndarray
    rotation_residuals: np.ndarray | None
    variance_factor: float
    nfev: int
    success: bool
    message: str
    jacobian: np.ndarray


class Problem:
    """Weighted residuals and their Jacobian for one model and data set."""

    def __init__(self, model: ErrorModel, params: np.ndarray, free: Sequence[int], q: np.ndarray,
                 points: np.ndarray, weights: np.ndarray, orientations: np.ndarray | None = None,
                 rot_weight: float = 0.0) -> None:
        self.model = model
        self.base = np.array(params, dtype=float)
        self.free = np.asarray(free, dtype=int)
        self.q = q
        self.points = points
        self.weights = weights  # (N, 3), 1 / sigma
        self.orientations = orientations
        self.rot_weight = rot_weight
        self.k = model.targets  # targets per pose; one orientation per pose

    def full(self, x: np.ndarray) -> np.ndarray:
        """All parameters with the free ones set to ``x``."""
        p = self.base.copy()
        p[self.free] = x
        return p

    def _eval(self, x: np.ndarray, derivatives: bool):
        return self.model.evaluate(self.full(x), self.q, derivatives=derivatives)

    def raw(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray | None]:
        """Unweighted position and rotation residuals, shapes (N, 3)."""
        ev = self._eval(x, False)
        rres = None
        if self.orientations is not None:
            rot = ev.rotation[:: self.k]  # every target of a pose has the body's rotation
            rres = rotation_vector(self.orientations @ np.swapaxes(rot, 1, 2))
        return self.points - ev.position, rres

    def residuals(self, x: np.ndarray) -> np.ndarray:
        """Weighted residual vector, shape (m,)."""
        pos, rres = self.raw(x)
        r = pos * self.weights
        if rres is not None and self.k > 1:
            return np.concatenate((r.ravel(), (rres * self.rot_weight).ravel()))
        if rres is not None:
            r = np.concatenate((r, rres * self.rot_weight), axis=1)
        return r.ravel()

    def jacobian(self, x: np.ndarray) -> np.ndarray:
        """Weighted residual Jacobian, shape (m, L)."""
        ev = self._eval(x, True)
        jp = ev.jac_param[:, :, self.free]
        j = -jp[:, :3] * self.weights[:, :, None]  # r = (y - f) / sigma
        if self.orientations is not None and self.k > 1:
            jr = -jp[:: self.k, 3:] * self.rot_weight
            return np.concatenate((j.reshape(-1, len(self.free)), jr.reshape(-1, len(self.free))))
        if self.orientations is not None:
            # r_rot = log(R_m R^T): a small world rotation dw of R changes it by -dw
            j = np.concatenate((j, -jp[:, 3:] * self.rot_weight), axis=1)
        return j.reshape(-1, len(self.free))


def fit(
    model: ErrorModel,
    params: np.ndarray,
    free: Sequence[int],
    q: np.ndarray,
    points: np.ndarray,
    *,
    sigma: float | np.ndarray = 5e-5,
    orientations: np.ndarray | None = None,
    sigma_rot: float = 1e-4,
    loss: str = "linear",
    loss_scale: float = 3.0,
    jacobian: str = "analytic",
    max_nfev: int | None = None,
) -> Fit:
    """Estimate parameters ``free`` of ``model`` from measured target positions.

    Parameters
    ----------
    model : ErrorModel
    params : numpy.ndarray, shape (P,)
        Starting values of all parameters; those not in ``free`` stay fixed.
    free : sequence of int
        Indices of the parameters to estimate.
    q : numpy.ndarray, shape (N, n)
        Joint readings, rad (m).
    points : numpy.ndarray, shape (N K, 3)
        Measured target positions in the instrument frame, m (pose-major for ``model.targets``
        = K targets per pose).
    sigma : float or numpy.ndarray, shape (N K,) or (N K, 3)
        Standard uncertainty of each measured coordinate, m.
    orientations : numpy.ndarray, shape (N, 3, 3), optional
        Measured orientations in the instrument frame, one per pose (the targets' common frame).
    sigma_rot : float
        Standard uncertainty of a measured orientation about each axis, rad.
    loss : {"linear", "huber", "soft_l1", "cauchy", "arctan"}
    loss_scale : float
        Weighted residual (in units of sigma) where a robust loss starts to flatten.
    jacobian : {"analytic", "2-point", "3-point"}
        Analytic Jacobian, or finite differences (for comparisons).
    max_nfev : int, optional
        Most residual evaluations.

    Returns
    -------
    Fit
    """
    from scipy.optimize import least_squares  # 0.3-0.8 s to import: only when solving

    if loss not in LOSSES:
        raise InputError(f"unknown loss {loss!r}; choose one of {', '.join(LOSSES)}")
    weights = np.broadcast_to(1.0 / np.asarray(sigma, dtype=float).reshape(
        (-1, 1) if np.ndim(sigma) == 1 else np.shape(sigma)), points.shape).copy()
    problem = Problem(model, params, free, q, points, weights, orientations,
                      1.0 / sigma_rot if orientations is not None else 0.0)
    x0 = np.asarray(params, dtype=float)[problem.free]
    jac = problem.jacobian if jacobian == "analytic" else jacobian
    method = "lm" if loss == "linear" else "trf"
    kwargs = {"x_scale": "jac", "ftol": 1e-12, "xtol": 1e-12, "gtol": 1e-12}
    if max_nfev is not None:
        kwargs["max_nfev"] = max_nfev
    if method == "trf":
        kwargs.update(loss=loss, f_scale=loss_scale)
    if len(x0):
        sol = least_squares(problem.residuals, x0, jac=jac, method=method, **kwargs)
        x, nfev, success, message = sol.x, int(sol.nfev), bool(sol.success), str(sol.message)
    else:
        x, nfev, success, message = x0, 0, True, "nothing to estimate"
    j = problem.jacobian(x)
    r = problem.residuals(x)
    dof = max(r.size - len(x), 1)
    s2 = float(r @ r / dof)
    cov = covariance(j, s2) if len(x) else np.zeros((0, 0))
    pos, rres = problem.raw(x)
    return Fit(problem.full(x), problem.free, cov, pos, rres, s2, nfev, success, message, j)
