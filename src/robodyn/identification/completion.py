"""A physically consistent completion of identified base parameters, when one exists.

Least squares (``method="wls"``/``"ols"``) estimates the base parameters ``theta = K p`` only;
the standard set written into the identified description is one of the many ``p`` with
``K p = theta``, by default the description's values for the parameters that only appear in
combinations (:func:`robodyn.identification.pipeline._complete`). That choice can put a link's
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
from robodyn.symbolic.regressor import PER_JOINT

__all__ = ["consistent_completion", "physical"]

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
