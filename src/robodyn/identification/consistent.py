"""Physically consistent estimation: least squares over the pseudo-inertia cone (Wensing et al. 2017).

A link's ten inertial parameters are physically realisable (a non-negative mass density exists)
if and only if its 4 x 4 pseudo-inertia matrix is positive semi-definite (Wensing, Kim and
Slotine, "Linear matrix inequalities for physically consistent inertial parameter
identification", IEEE RA-L 2017)::

    J = [[Sigma, h], [h^T, m]],   Sigma = tr(I_O) / 2 * 1 - I_O

with ``I_O`` the inertia about the link frame origin and ``h = m c``. The estimate minimises the
weighted squared error of the linear step (its row weights and its Tikhonov weight toward the
description's base parameters) over the full standard vector ``p`` (15 n)::

    f(p) = |A (K p) - b|^2 + lam |D (K p - theta0)|^2
    stage 1:  f* = min f(p) (+ 1e-12 of the data scale times stage 2's distance)  s.t. C
              (1e-10, then 1e-8, where Clarabel fails)
    stage 2:  min |S^-1 (p - p_nom)|^2  s.t. C,  f(p) <= f* (1 + nb / (m - nb)) + FLOOR_TOL |b|^2
    C:  J_j(p) >= eps 1 (every link),  Ia_j, Fv_j, Fcp_j, Fcn_j >= 0,  optional bounds

where ``K`` maps standard to base parameters, ``m`` the rows and ``nb`` the base parameters.
Stage 2 picks, among the consistent standard sets that the data cannot tell from the best fit,
the one closest to the description (``S`` the nominal magnitudes, floored at 1e-3): its
allowance ``nb f* / (m - nb)`` is ``nb`` times the estimated variance of a row, the mean of
chi^2 with ``nb`` degrees of freedom, the scale of the base parameters' joint confidence region
(rows filtered and decimated are correlated, so the region it stands for is, if anything,
narrower than that). Noise-free data give no allowance: the best fit itself. A
tie-break added to stage 1's objective instead (as before 2026-12-06, with weight 1e-8 of the
data's scale) acts as a prior toward the description on the identifiable parameters too: on a
plant whose centres of mass lie centimetres off its description's (noise-free data, truth
inside the cone) it moved the base parameters by 4e-4 of the largest (now 1.5e-7), and on a virtual 7-DOF
torque arm it put every link on the cone's boundary and lost to plain least squares.
``eps = EPS`` keeps a small margin inside the
cone so that the result passes robodyn's strict inertia validation after rounding. Both stages
are semidefinite programs solved by cvxpy with Clarabel; an infeasible problem (e.g.
contradictory ``bounds``) or a failure of stage 1 raises :class:`IdentificationError`; a failure
of stage 2 keeps stage 1's set (consistent and best-fitting, not the closest).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from robodyn.identification.base import BaseRelations
from robodyn.identification.estimate import LinearFit, thin_svd
from robodyn.robot.errors import IdentificationError
from robodyn.robot.model import Robot
from robodyn.robot.validation import inertia_problems
from robodyn.symbolic.regressor import PER_JOINT

__all__ = ["EPS", "consistent_standard", "pseudo_inertia"]

#: Margin inside the pseudo-inertia cone, kg m^2 (Sigma block) and kg (mass).
EPS = 1e-7
#: Weights of the distance to the description in stage 1, relative to the data's mean squared
#: singular value, tried in turn while Clarabel fails (its interior point can stall on a nearly
#: flat face: one test's problem failed at 1e-12 with the kernels' block width 1 and solved with
#: the default width); the program before 2026-12-06 used 1e-8, and no stage 2.
UNIQUE = (1e-12, 1e-10, 1e-8)
#: Stage 2's allowance relative to the target's squared norm, for data fitted exactly (solver
#: accuracy; the statistical allowance is then zero).
FLOOR_TOL = 1e-14


def pseudo_inertia(standard: np.ndarray, j: int) -> np.ndarray:
    """Pseudo-inertia matrix (4, 4) of link ``j`` from a standard vector (15 n,)."""
    xx, xy, xz, yy, yz, zz, mx, my, mz, m = standard[PER_JOINT * j:PER_JOINT * j + 10]
    i_o = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
    sigma = 0.5 * np.trace(i_o) * np.eye(3) - i_o  # Sigma = tr(I)/2 1 - I
    out = np.zeros((4, 4))
    out[:3, :3] = sigma
    out[:3, 3] = out[3, :3] = (mx, my, mz)
    out[3, 3] = m
    return out


def _pseudo_expr(cp, p, j: int):
    b = PER_JOINT * j
    xx, xy, xz, yy, yz, zz, mx, my, mz, m = (p[b + k] for k in range(10))
    tr = 0.5 * (xx + yy + zz)
    return cp.bmat([[tr - xx, -xy, -xz, mx],
                    [-xy, tr - yy, -yz, my],
                    [-xz, -yz, tr - zz, mz],
                    [mx, my, mz, m]])


def consistent_standard(robot: Robot, relations: BaseRelations, phi: np.ndarray, y: np.ndarray,
                        joint: np.ndarray, fit: LinearFit, nominal: np.ndarray,
                        bounds: Mapping[str, tuple[float, float]] | None = None) -> np.ndarray:
    """Physically consistent standard parameters (15 n,) (module docstring).

    Parameters
    ----------
    robot : Robot
    relations : BaseRelations
    phi : numpy.ndarray, shape (m, b)
        Identification matrix (base columns); ``y`` (m,) the target in torque units.
    joint : numpy.ndarray of int, shape (m,)
    fit : LinearFit
        The linear step (its row weights and regularisation weight are reused).
    nominal : numpy.ndarray, shape (15 n,)
    bounds : Mapping[str, (float, float)], optional
        Extra box constraints on named standard parameters (e.g. ``{"M3": (0.5, 2.0)}``).

    Returns
    -------
    numpy.ndarray, shape (15 n,)

    Raises
    ------
    IdentificationError
        Infeasible problem, solver failure, or a result that fails the inertia checks.
    """
    import cvxpy as cp  # a core dependency, imported when used (slow to import)

    n = robot.dof
    # the row weights relative to the largest: the program is the same (every term scales with
    # w^2), but noise-free data give weights of 1e15 and Clarabel's absolute tolerances fail
    w = fit.weights[joint] / max(float(np.max(fit.weights)), 1e-300)
    a = phi * w[:, None]
    b = y * w
    norms = np.linalg.norm(a, axis=0)
    scale = np.where(norms > 0, norms, 1.0)
    # |A theta - b|^2 = |S V^T theta - U^T b|^2 + const (thin SVD keeps the program small)
    u, s, vt = thin_svd(a)
    r_mat = s[:, None] * vt
    r_rhs = u.T @ b
    k = relations.matrix
    theta0 = relations.to_base(nominal)
    p = cp.Variable(k.shape[1])
    theta = k @ p
    fit_term = cp.sum_squares(r_mat @ theta - r_rhs)
    if fit.lam > 0:
        fit_term += fit.lam * cp.sum_squares(cp.multiply(scale, theta - theta0))
    constraints = _constraints(cp, p, n, relations.standard_names, bounds)
    mag = np.maximum(np.abs(nominal), 1e-3)
    offset = cp.multiply(1.0 / mag, p - nominal)  # S^-1 (p - p_nom)
    # stage 1: the estimate's fit over the cone (the distance at UNIQUE only makes the optimum
    # unique: parameters that no column sees would leave an unbounded optimal face)
    data = float(np.sum(s**2)) / max(s.size, 1)
    for i, weight in enumerate(UNIQUE):
        try:
            _solve(cp, cp.Problem(cp.Minimize(fit_term + weight * data * cp.sum_squares(offset)),
                                  constraints), bounds)
            break
        except _SolverFailed:
            if i == len(UNIQUE) - 1:
                raise
    first = np.asarray(p.value, dtype=float)
    best = float(fit_term.value)  # f* = f(first)
    # stage 2: among the consistent sets that the data cannot tell from the best (within the
    # base parameters' confidence region), the one closest to the description
    bound = best + _allowance(best, a.shape) + FLOOR_TOL * float(r_rhs @ r_rhs)
    residual = r_mat @ theta - r_rhs
    if fit.lam > 0:
        residual = cp.hstack([residual, np.sqrt(fit.lam) * cp.multiply(scale, theta - theta0)])
    if not _closest(cp, offset, residual, bound, constraints):
        p.value = first  # the stage-1 set stands (consistent, best fit; not the closest)
    out = np.asarray(p.value, dtype=float)
    for j in range(n):
        _project_link(out, j)
        # Ia, Fv, Fcp, Fcn >= 0 hold to the solver's tolerance (-1e-12): exactly, after the clip
        drive = slice(PER_JOINT * j + 10, PER_JOINT * j + 14)
        out[drive] = np.maximum(out[drive], 0.0)
        _check_link(out, j, robot)
    return out


def _constraints(cp, p, n: int, names: tuple[str, ...],
                 bounds: Mapping[str, tuple[float, float]] | None) -> list:
    """The cone (``J_j >= EPS 1``), ``Ia, Fv, Fcp, Fcn >= 0`` and the user's ``bounds``."""
    constraints = []
    for j in range(n):
        constraints.append(_pseudo_expr(cp, p, j) >> EPS * np.eye(4))
        base = PER_JOINT * j + 10
        constraints += [p[base + i] >= 0 for i in range(4)]  # Ia, Fv, Fcp, Fcn >= 0
    for name, (lo, hi) in (bounds or {}).items():
        if name not in names:
            raise IdentificationError(f"bounds: unknown standard parameter {name!r} "
                                      f"(names like {names[0]!r}, {names[9]!r})")
        i = names.index(name)
        constraints += [p[i] >= lo, p[i] <= hi]
    return constraints


class _SolverFailed(IdentificationError):
    """Clarabel stopped without a solution (not an infeasible problem)."""


def _solve(cp, problem, bounds: Mapping[str, tuple[float, float]] | None) -> None:
    """Solve ``problem`` with Clarabel; IdentificationError unless it ends optimal."""
    try:
        problem.solve(solver=cp.CLARABEL)
    except cp.error.SolverError as exc:
        raise _SolverFailed(f"method='consistent': the semidefinite program failed in "
                            f"Clarabel: {exc}") from exc
    if problem.status in ("infeasible", "infeasible_inaccurate"):
        raise IdentificationError(
            "method='consistent': the semidefinite program is infeasible: no physically "
            "consistent parameters (pseudo-inertia >= 0, rotor inertia and friction >= 0)"
            + (f" satisfy the bounds {dict(bounds)}" if bounds else ""))
    if problem.status not in ("optimal", "optimal_inaccurate") or problem.variables()[0].value is None:
        raise _SolverFailed(f"method='consistent': the semidefinite program ended with "
                            f"status {problem.status!r}")


def _allowance(best: float, shape: tuple[int, int]) -> float:
    """Stage 2's allowance on stage 1's objective ``best`` for a problem of ``shape`` (m, b).

    ``sigma^2 = best / (m - b)`` estimates the residual variance of a row (in the weighted units
    of the objective); ``b sigma^2`` is the mean of chi^2 with ``b`` degrees of freedom, the scale
    of the base parameters' joint confidence region around the best fit.
    """
    m, b = shape
    # delta f = b sigma^2 = b best / (m - b)
    return b * best / max(m - b, 1)


def _closest(cp, offset, residual, bound: float, constraints: list) -> bool:
    """Stage 2: minimise ``|offset|`` subject to ``constraints`` and ``|residual| <= sqrt(bound)``
    (the same set as ``f <= bound``, better scaled for the solver than the squared form);
    False where Clarabel fails (the variable's value is then not this program's)."""
    closest = cp.Problem(cp.Minimize(cp.norm(offset)), [*constraints, cp.norm(residual) <= np.sqrt(bound)])
    try:
        closest.solve(solver=cp.CLARABEL)
    except cp.error.SolverError:
        return False
    return closest.status in ("optimal", "optimal_inaccurate") and closest.variables()[0].value is not None


def _project_link(p: np.ndarray, j: int) -> None:
    """Put link ``j``'s pseudo-inertia of ``p`` (15 n,) back into ``J >= EPS I`` in place.

    The interior-point solver meets the LMI only to its own tolerance: a link whose optimum
    lies on the boundary (a point mass: inertia about the centre of mass near zero) can come
    back with principal moments of -1e-7 kg m^2. Clipping the eigenvalues of
    ``J = [[Sigma, h], [h^T, m]]`` (``Sigma = tr(I)/2 1 - I``) at ``EPS`` moves the parameters by
    at most the solver's tolerance and makes the link exactly consistent.
    """
    b = PER_JOINT * j
    lam, vec = np.linalg.eigh(pseudo_inertia(p, j))
    if lam[0] >= EPS:
        return
    pseudo = (vec * np.maximum(lam, EPS)) @ vec.T
    sigma = 0.5 * (pseudo[:3, :3] + pseudo[:3, :3].T)
    # I = tr(Sigma) 1 - Sigma
    i_new = np.trace(sigma) * np.eye(3) - sigma
    p[b:b + 10] = (i_new[0, 0], i_new[0, 1], i_new[0, 2], i_new[1, 1], i_new[1, 2], i_new[2, 2],
                   *pseudo[:3, 3], pseudo[3, 3])


def _check_link(p: np.ndarray, j: int, robot: Robot) -> None:
    b = PER_JOINT * j
    m = p[b + 9]
    c = p[b + 6:b + 9] / m
    xx, xy, xz, yy, yz, zz = p[b:b + 6]
    i_o = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
    i_c = i_o - m * (float(c @ c) * np.eye(3) - np.outer(c, c))
    problems = inertia_problems(i_c)
    if m <= 0 or problems:
        raise IdentificationError(
            f"method='consistent': link {robot.links[j].name!r} came out physically inconsistent "
            f"(mass {m:g}; {'; '.join(problems)}): solver inaccuracy")
