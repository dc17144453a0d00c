"""A physically consistent completion of identified base parameters, when one exists.

Least squares (``method="wls"``/``"ols"``) estimates the base parameters ``theta = K p`` only;
the standard set written into the identified description is one of the many ``p`` with
``K p = theta``, by default the description's values for the parameters that only appear in
combinations (:func:`completed`). That choice can put a link's
inertia outside the physically possible set (a negative principal moment, a broken triangle
inequality) although another ``p`` with the same base parameters, hence the very same
predictions, is physical. :func:`consistent_completion` looks for it::

    min |S (p - p0)|^2   s.t.  K p = K p0,  the rotor inertia and friction of p0 kept,
                               J_j(p) >= EPS 1 (every link's pseudo-inertia)

(``S`` the inverse magnitudes of ``p0``, as in :mod:`robodyn.identification.consistent`), a
semidefinite program solved by cvxpy with Clarabel. When it is infeasible the
base parameters themselves are not physical (only ``method="consistent"`` can then give a
physical model, with other base parameters), and the completion ``p0`` is kept.
"""

from __future__ import annotations

import numpy as np

from robodyn.identification.base import BaseRelations
from robodyn.identification.consistent import EPS, _project_link, _pseudo_expr, pseudo_inertia
from robodyn.robot.validation import inertia_problems
from robodyn.symbolic.regressor import PER_JOINT, joint_columns

__all__ = ["completed", "consistent_completion", "physical"]

#: Largest relative change of the base parameters the solver's tolerance may leave, |dK p| / |K p0|.
BASE_TOL = 1e-7


def _link_ok(p: np.ndarray, j: int) -> bool:
    b = PER_JOINT * j
    m = p[b + 9]
    if not m > 0 or np.linalg.eigvalsh(pseudo_inertia(p, j))[0] < 0:
        return False
    c = p[b + 6:b + 9] / m
    xx, xy, xz, yy, yz, zz = p[b:b + 6]
    i_o = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
    i_c = i_o - m * (float(c @ c) * np.eye(3) - np.outer(c, c))  # about the centre of mass
    return not inertia_problems(i_c)


def physical(p: np.ndarray, n: int) -> bool:
    """Whether every link of the standard set ``p`` (15 n,) is physically possible and every
    rotor inertia is non-negative."""
    return all(_link_ok(p, j) and p[PER_JOINT * j + 10] >= 0 for j in range(n))


def consistent_completion(relations: BaseRelations, p0: np.ndarray, n: int) -> np.ndarray:
    """``p0`` (15 n,) when it is physical, else the physical standard set closest to it with the
    same base parameters, rotor inertias and friction (module docstring), else ``p0`` (none
    exists)."""
    if physical(p0, n) or any(p0[PER_JOINT * j + 10] < 0 for j in range(n)):
        return p0  # physical already, or a negative rotor inertia no completion can change
    import cvxpy as cp  # a core dependency, imported when used (slow to import)

    k = relations.matrix
    theta = k @ p0
    mag = np.maximum(np.abs(p0), 1e-3)
    p = cp.Variable(p0.size)
    drive = np.array([PER_JOINT * j + i for j in range(n) for i in range(10, PER_JOINT)])
    constraints = [k @ p == theta, p[drive] == p0[drive]]  # Ia, Fv, Fcp, Fcn, Fo as they are
    for j in range(n):
        constraints.append(_pseudo_expr(cp, p, j) >> 2 * EPS * np.eye(4))
    problem = cp.Problem(cp.Minimize(cp.sum_squares(cp.multiply(1.0 / mag, p - p0))), constraints)
    try:
        problem.solve(solver=cp.CLARABEL)
    except cp.error.SolverError:
        return p0
    if problem.status not in ("optimal", "optimal_inaccurate") or p.value is None:
        return p0  # infeasible: the base parameters themselves are not physical
    out = np.asarray(p.value, dtype=float)
    out[drive] = p0[drive]
    for j in range(n):
        _project_link(out, j)  # the solver's tolerance: back inside the cone
    drift = np.linalg.norm(k @ out - theta) / max(np.linalg.norm(theta), 1e-300)
    if drift > BASE_TOL or not physical(out, n):
        return p0
    return out


def completed(relations: BaseRelations, theta: np.ndarray, nominal: np.ndarray) -> np.ndarray:
    """Standard vector with the dependent parameters at their nominal values and the
    independent ones set so that its base parameters equal ``theta``."""
    p = nominal.copy()
    # theta = p_b + beta p_d  ->  p_b = theta - beta p_d
    p[relations.independent] = theta - relations.beta @ nominal[relations.dependent]
    return _split_coulomb(relations, p)


def _split_coulomb(relations: BaseRelations, p: np.ndarray) -> np.ndarray:
    """Move along the one direction the data cannot see among a joint's (Fcp, Fcn, Fo) (an
    offset against asymmetric Coulomb friction) so that both Coulomb levels are non-negative,
    as a description requires, staying as close as possible to the prior's split."""
    k = relations.matrix
    out = p.copy()
    for j in range(p.size // PER_JOINT):
        idx = np.arange(p.size)[joint_columns(j, "Fcp", "Fo")]  # Fcp, Fcn, Fo
        _, sv, vt = np.linalg.svd(k[:, idx])
        null = vt[np.sum(sv > 1e-9 * max(sv[0], 1e-300)):]
        if null.shape[0] != 1:
            continue
        d = null[0]
        c = out[idx[:2]]
        # Fcp, Fcn + t d[:2] >= 0: an interval of t (or none)
        lo, hi = -np.inf, np.inf
        for ci, di in zip(c, d[:2], strict=True):
            if abs(di) < 1e-12:
                continue
            if di > 0:
                lo = max(lo, -ci / di)
            else:
                hi = min(hi, -ci / di)
        if lo <= hi:
            t = float(np.clip(0.0, lo, hi))
        elif abs(d[0] - d[1]) > 1e-12:
            t = float((c[1] - c[0]) / (d[0] - d[1]))  # no such split: equal levels
        else:
            continue
        out[idx] += t * d
    return out
