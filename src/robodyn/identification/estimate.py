"""Linear least-squares estimators around a prior: OLS, WLS, Tikhonov with a cross-validated weight.

The identification model is ``y = Phi theta + e`` (rows: one joint at one sample). Rows are
weighted (``w_j = 1 / sigma_j`` for joint ``j``; all 1 for OLS) and columns scaled to unit norm,
``A = diag(w) Phi D^-1``, ``z = D theta``, so the regularisation weight is dimensionless. With
the SVD ``A = U S V^T`` and the prior ``z0 = D theta0`` (the description's nominal parameters)::

    z = z0 + V diag(s / (s^2 + lam)) U^T (b - A z0)            (Tikhonov toward the prior)

``lam = 0`` is least squares; singular values below ``RANK_RTOL s_max`` are then dropped
(truncated SVD), which leaves those directions at the prior: they are reported as not excited,
never filled with arbitrary values. Uncertainty is the Bayesian posterior covariance of the
same model, ``cov(z) = sigma^2 V diag(1 / (s^2 + lam)) V^T`` with
``sigma^2 = |b - A z|^2 / (m - sum s^2 / (s^2 + lam))``, which is the usual least-squares
covariance when ``lam = 0`` (infinite along dropped directions).

Weight rule (``regularization="auto"``): K-fold cross-validation over contiguous time blocks of
the identification data only (``FOLDS`` blocks per recording; a block is left out whole, so the
strong correlation of neighbouring filtered samples does not leak into the test error), over a
log grid ``lam in {0} U [1e-10, 1e2]``. Least squares takes the weight with the least held-out
error: nothing else bounds its weakly excited directions. The physically consistent program
(:mod:`robodyn.identification.consistent`), whose constraints do, takes the smallest weight whose
held-out error lies within one standard error of the least (``"auto-least"``, :func:`cv_weight`:
the standard error of the paired block differences): the data are preferred to the prior unless
the prior predicts held-out blocks better by more than their spread, the rule of every other
choice from the data (:mod:`robodyn.identification.choices`). On the KUKA runs of the quality
table the least error picked 0.1 for the consistent program, a gain within the spread that
raised the error on another trajectory from 0.042 to 0.052, while least squares needs that pull
(0.074 with it, 0.154 with the smallest weight within one standard error).

WLS (Gautier and Poignet 2001): per-joint standard deviations from the residuals of a first,
unweighted fit, ``sigma_j^2 = |r_j|^2 / (m_j - p m_j / m)``, then the weighted fit.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["FOLDS", "LAMBDA_GRID", "RANK_RTOL", "LinearFit", "candidate_cv_errors", "cv_weight", "fit_linear",
           "paired_se", "thin_svd", "truncated_lstsq"]

RANK_RTOL = 1e-9
#: Eigenvalues of a Gram matrix below this fraction of the largest are dropped (:func:`_gram_cv`).
GRAM_RTOL = 1e-12
FOLDS = 5
LAMBDA_GRID = np.concatenate([[0.0], np.logspace(-10, 2, 25)])


@dataclass(frozen=True, eq=False)
class LinearFit:
    """Result of :func:`fit_linear`.

    Attributes
    ----------
    theta : numpy.ndarray, shape (p,)
    cov : numpy.ndarray, shape (p, p)
        Posterior covariance (inf on the diagonal of parameters not excited when ``lam = 0``).
    lam : float
        Regularisation weight used (dimensionless, unit-norm columns).
    sigma : numpy.ndarray, shape (n,)
        Per-joint residual standard deviation (target units) of the final fit.
    weights : numpy.ndarray, shape (n,)
        Row weight of each joint (1 for OLS).
    singular_values : numpy.ndarray, shape (p,)
        Of the weighted, column-scaled matrix ``A``, descending.
    directions : numpy.ndarray, shape (p, p)
        Right singular vectors in parameter space (columns, unit norm in ``z``), same order.
    condition : float
        ``s_max / s_min`` of ``A`` (inf when rank-deficient).
    unexcited : numpy.ndarray of bool, shape (p,)
        Parameters with a part in directions of singular value below ``RANK_RTOL s_max``.
    cv_errors : numpy.ndarray, shape (len(LAMBDA_GRID),) or (0,)
        Held-out error per grid weight when the weight was cross-validated.
    """

    theta: np.ndarray
    cov: np.ndarray
    lam: float
    sigma: np.ndarray
    weights: np.ndarray
    singular_values: np.ndarray
    directions: np.ndarray
    condition: float
    unexcited: np.ndarray
    cv_errors: np.ndarray


def thin_svd(a: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Thin SVD ``(u, s, vt)`` of a tall matrix (m, p) through its QR factorisation, ``A = Q R``,
    ``R = U_r S V^T`` (much faster than LAPACK's direct SVD of a tall matrix)."""
    if a.shape[0] <= 2 * a.shape[1]:
        return np.linalg.svd(a, full_matrices=False)
    q, r = np.linalg.qr(a)
    u_r, s, vt = np.linalg.svd(r)
    return q @ u_r, s, vt


def truncated_lstsq(a: np.ndarray, b: np.ndarray
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Least squares on the excited directions of ``a`` (m, p), ``b`` (m,): ``x`` (p,), the
    singular values ``s``, ``V^T`` and the kept mask (``s > RANK_RTOL s_max``).

    ``x = V_k S_k^-1 U_k^T b``: directions below the rank tolerance are left at zero (the
    ``lam = 0`` case of the Tikhonov solution with a zero prior).
    """
    u, s, vt = thin_svd(a)
    keep = s > RANK_RTOL * (s[0] if s.size else 1.0)
    # x = V S^-1 U^T b on the kept directions
    return vt[keep].T @ ((u[:, keep].T @ b) / s[keep]), s, vt, keep


def _solve(a: np.ndarray, b: np.ndarray, z0: np.ndarray, lams: np.ndarray
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``z`` for each weight (len(lams), p), and the SVD ``(u, s, vt)`` of ``a``."""
    u, s, vt = thin_svd(a)
    keep = s > RANK_RTOL * (s[0] if s.size else 1.0)
    c = u.T @ (b - a @ z0)
    with np.errstate(divide="ignore", invalid="ignore"):
        # z = z0 + V diag(s / (s^2 + lam)) U^T (b - A z0), dropped directions stay at z0
        gain = np.where(keep[None, :], s[None, :] / (s[None, :] ** 2 + lams[:, None]), 0.0)
    return z0[None, :] + (gain * c[None, :]) @ vt, u, s, vt


def _cv_block_errors(a: np.ndarray, b: np.ndarray, z0: np.ndarray, blocks: np.ndarray,
                     a_test: np.ndarray | None = None, b_test: np.ndarray | None = None) -> np.ndarray:
    """Held-out squared error of each block (K, len(LAMBDA_GRID)) for each grid weight; the
    held-out rows are predicted with ``a_test`` (same shape as ``a``; default ``a``) and
    compared with ``b_test`` (default ``b``)."""
    a_test = a if a_test is None else a_test
    b_test = b if b_test is None else b_test
    out = []
    for k in np.unique(blocks):
        test = blocks == k
        if test.all():
            continue
        z, *_ = _solve(a[~test], b[~test], z0, LAMBDA_GRID)
        out.append(np.sum((b_test[test][None, :] - z @ a_test[test].T) ** 2, axis=1))
    return np.array(out).reshape(-1, LAMBDA_GRID.size)


def paired_se(d: np.ndarray) -> float:
    """Standard error of the sum of paired block differences ``d`` (K,): ``std(d) sqrt(K)``, 0
    for a single block; the yardstick of every "better by more than one standard error" choice."""
    return float(np.std(d, ddof=1) * np.sqrt(d.size)) if d.size > 1 else 0.0


def cv_weight(block_errors: np.ndarray) -> float:
    """The weight of the module docstring's rule from held-out block errors.

    Parameters
    ----------
    block_errors : numpy.ndarray, shape (K, len(LAMBDA_GRID))
        Held-out squared error of each block for each grid weight (ascending).

    Returns
    -------
    float
        The smallest grid weight whose total error exceeds the least total by no more than one
        standard error of the paired block differences.
    """
    total = block_errors.sum(axis=0)
    best = int(np.argmin(total))
    for i in range(best):
        d = block_errors[:, i] - block_errors[:, best]  # paired differences to the best weight
        if d.sum() <= paired_se(d):
            return float(LAMBDA_GRID[i])
    return float(LAMBDA_GRID[best])


def _gram_cv(a: np.ndarray, b: np.ndarray, z0: np.ndarray, blocks: np.ndarray,
             a_test: np.ndarray, b_test: np.ndarray) -> np.ndarray:
    """:func:`_cv_block_errors` through the normal equations: the training Gram matrix of a fold
    is the whole one less the block's, ``G_t = G - A_k^T A_k``, and its eigendecomposition gives
    every weight at once, ``z = z0 + V diag(1 / (e + lam)) V^T A_t^T (b_t - A_t z0)``, with the
    eigenvalues below ``GRAM_RTOL`` of the largest dropped (left at the prior). The cost is
    about one pass over the rows instead of one QR per fold; squaring the condition number
    limits the truncation to ``GRAM_RTOL`` (s < 1e-6 s_max), which is why the final fit keeps
    the SVD. Returns (K, len(LAMBDA_GRID))."""
    r0 = b - a @ z0
    g = a.T @ a
    h = a.T @ r0
    out = []
    for k in np.unique(blocks):
        test = blocks == k
        if test.all():
            continue
        ak = a[test]
        # G_t = G - A_k^T A_k,  h_t = A_t^T (b_t - A_t z0)
        e, v = np.linalg.eigh(g - ak.T @ ak)
        c = v.T @ (h - ak.T @ r0[test])
        keep = e > GRAM_RTOL * max(float(e[-1]), 1e-300)
        with np.errstate(divide="ignore", invalid="ignore"):
            gain = np.where(keep[None, :], 1.0 / (e[None, :] + LAMBDA_GRID[:, None]), 0.0)
        z = z0[None, :] + (gain * c[None, :]) @ v.T  # (L, p)
        out.append(np.sum((b_test[test][None, :] - z @ a_test[test].T) ** 2, axis=1))
    return np.array(out).reshape(-1, LAMBDA_GRID.size)


def candidate_cv_errors(phi: np.ndarray, y: np.ndarray, theta0: np.ndarray, joint: np.ndarray,
                        blocks: np.ndarray, phi_test: np.ndarray, y_test: np.ndarray) -> np.ndarray:
    """Held-out squared error of each time block (K, len(LAMBDA_GRID)) of weighted least squares
    on the rows ``phi`` (m, p), ``y`` (m,) toward ``theta0`` (p,), for each grid weight.

    As :func:`fit_linear` with ``method="wls"``: columns scaled to unit norm, per-joint row
    weights ``1 / sigma_j`` from the residuals of an unweighted fit (its weight chosen by the
    same blocks); the held-out rows, predicted with ``phi_test`` (m, p), are compared
    unweighted with ``y_test`` (m,). Normal equations throughout (:func:`_gram_cv`): a score
    for choosing among preprocessing candidates, cheap enough to run for each.
    """
    norms = np.linalg.norm(phi, axis=0)
    scale = np.where(norms > 0, norms, 1.0)
    a, z0 = phi / scale[None, :], theta0 * scale
    first = _gram_cv(a, y, z0, blocks, a, y).sum(axis=0)
    lam = float(LAMBDA_GRID[int(np.argmin(first))])
    e, v = np.linalg.eigh(a.T @ a)
    keep = e > GRAM_RTOL * max(float(e[-1]), 1e-300)
    gain = np.where(keep, 1.0 / np.where(keep, e + lam, 1.0), 0.0)
    z = z0 + v @ (gain * (v.T @ (a.T @ (y - a @ z0))))
    res = y - a @ z
    n = int(joint.max()) + 1
    sig = np.array([np.sqrt(np.mean(res[joint == j] ** 2)) if np.any(joint == j) else 1.0
                    for j in range(n)])
    w = 1.0 / np.maximum(sig, 1e-12 * max(float(sig.max()), 1e-300))
    aw = phi * w[joint][:, None]
    norms = np.linalg.norm(aw, axis=0)
    scale = np.where(norms > 0, norms, 1.0)
    return _gram_cv(aw / scale[None, :], y * w[joint], theta0 * scale, blocks,
                    phi_test / scale[None, :], y_test)


def _one(phi: np.ndarray, y: np.ndarray, theta0: np.ndarray, joint: np.ndarray, blocks: np.ndarray,
         weights: np.ndarray, regularization: float | str | None,
         rows: np.ndarray | None = None) -> LinearFit:
    w = weights[joint] if rows is None else rows
    norms = np.linalg.norm(phi * w[:, None], axis=0)
    scale = np.where(norms > 0, norms, 1.0)
    a = phi * w[:, None] / scale[None, :]
    b = y * w
    z0 = theta0 * scale
    cv = np.zeros(0)
    if regularization in ("auto", "auto-least"):
        per_block = _cv_block_errors(a, b, z0, blocks)
        cv = per_block.sum(axis=0)
        least = regularization == "auto-least"
        lam = cv_weight(per_block) if least else float(LAMBDA_GRID[int(np.argmin(cv))])
    else:
        lam = 0.0 if regularization is None else float(regularization)
    zs, _, s, vt = _solve(a, b, z0, np.array([lam]))
    z = zs[0]
    keep = s > RANK_RTOL * s[0]
    m, p = a.shape
    r = b - a @ z
    with np.errstate(divide="ignore", invalid="ignore"):
        hat = np.where(keep, s**2 / (s**2 + lam), 0.0)
        sigma2 = float(r @ r) / max(m - float(hat.sum()), 1.0)
        inv = np.where(keep | (lam > 0), 1.0 / (s**2 + lam), np.inf)
    # cov(z) = sigma^2 V diag(1 / (s^2 + lam)) V^T
    finite = np.isfinite(inv)
    cov_z = (vt[finite].T * (sigma2 * inv[finite])) @ vt[finite]
    unexcited = np.any(np.abs(vt[~keep]) > 1e-6, axis=0) if lam == 0 else np.zeros(p, bool)
    if (~finite).any():
        cov_z[unexcited, :] = np.inf
        cov_z[:, unexcited] = np.inf
    cov = cov_z / scale[:, None] / scale[None, :]
    n = int(joint.max()) + 1
    res = y - phi @ (z / scale)
    sigma = np.array([np.sqrt(np.mean(res[joint == j] ** 2)) if np.any(joint == j) else 0.0
                      for j in range(n)])
    cond = float(s[0] / s[-1]) if s[-1] > 0 else float("inf")
    return LinearFit(theta=z / scale, cov=cov, lam=lam, sigma=sigma, weights=weights,
                     singular_values=s, directions=vt.T, condition=cond, unexcited=unexcited,
                     cv_errors=cv)


def fit_linear(phi: np.ndarray, y: np.ndarray, theta0: np.ndarray, joint: np.ndarray,
               blocks: np.ndarray, *, method: str = "ols",
               regularization: float | str | None = None,
               row_sigma: np.ndarray | None = None) -> LinearFit:
    """Least squares toward a prior (module docstring).

    Parameters
    ----------
    phi : numpy.ndarray, shape (m, p)
        Identification matrix, one row per joint per sample.
    y : numpy.ndarray, shape (m,)
        Target (N m, N or A).
    theta0 : numpy.ndarray, shape (p,)
        Prior (nominal) parameter values.
    joint : numpy.ndarray of int, shape (m,)
        Joint of each row (0-based).
    blocks : numpy.ndarray of int, shape (m,)
        Cross-validation block of each row.
    method : {"ols", "wls"}
    regularization : "auto", "auto-least", float or None
        Weight ``lam`` (dimensionless): chosen by cross-validation, the least held-out error
        ("auto") or the smallest weight within one standard error of it ("auto-least",
        :func:`cv_weight`); None: none.
    row_sigma : numpy.ndarray, shape (m,), optional
        Standard deviation of each row's error (e.g. :mod:`robodyn.identification.state_noise`): the
        rows are weighted by ``1 / row_sigma`` instead of per joint (``method`` is then unused).

    Returns
    -------
    LinearFit
    """
    n = int(joint.max()) + 1
    if row_sigma is not None:
        rows = 1.0 / np.asarray(row_sigma, dtype=float)
        per_joint = np.array([np.sqrt(np.mean(rows[joint == j] ** 2)) for j in range(n)])
        return _one(phi, y, theta0, joint, blocks, per_joint, regularization, rows)
    first = _one(phi, y, theta0, joint, blocks, np.ones(n), regularization)
    if method == "ols":
        return first
    m, p = phi.shape
    res = y - phi @ first.theta
    sig = np.ones(n)
    for j in range(n):
        rj = res[joint == j]
        dof = rj.size - p * rj.size / m
        # sigma_j^2 = |r_j|^2 / (m_j - p m_j / m)
        sig[j] = np.sqrt(float(rj @ rj) / max(dof, 1.0)) if rj.size else 1.0
    sig = np.maximum(sig, 1e-12 * sig.max()) if sig.max() > 0 else np.ones(n)
    return _one(phi, y, theta0, joint, blocks, 1.0 / sig, regularization)
