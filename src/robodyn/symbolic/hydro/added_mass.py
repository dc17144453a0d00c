"""Added mass by strip theory: the fluid accelerated with each cylinder.

Each strip ``d xi`` of a cylinder of radius r carries the normal added mass
``m_a' = C_a rho pi r^2`` per unit length on the normal velocity ``v_n(xi) = P v(xi)`` and the
whole cylinder an axial added mass ``m_ax = C_ax rho pi r^2 L`` on the axial velocity ``e . v``
(the same at every point; this is where end effects are lumped; C_ax = 0 by default). The added
kinetic energy is therefore::

    T_a = 1/2 int_0^L m_a' |P v(xi)|^2 d xi + 1/2 m_ax (e . v(0))^2 = 1/2 qd^T M_a(q) qd

with ``v(xi) = (J_s + xi J_b) qd`` (``J_b`` already normal to e), integrated exactly::

    M_a = m_a' (L A^T A + L^2/2 (A^T J_b + J_b^T A) + L^3/3 J_b^T J_b) + m_ax J_s^T e e^T J_s,
    A = P J_s

``M_a`` is symmetric positive semidefinite, so ``M + M_a`` stays positive definite. Its Coriolis
and centrifugal terms come from the same Christoffel symbols robodyn uses for the rigid body:
``C_a = christoffel(M_a)`` (Lagrange's equations of ``T_a``).

In a uniform steady current ``c`` the fluid's kinetic energy is that of the motion RELATIVE to
the water, as in Fossen's equations (added mass on the relative velocity ``nu_r``): seen from
a frame drifting with the water (inertial, the fluid at rest far away) the base moves at
``-c``. With ``c_l = R^T c`` in link components the relative velocity is ``v(xi) - c_l`` and::

    T_a = 1/2 qd^T M_a qd - qd^T b(q) + 1/2 k(q)
    b = m_a' (L A^T + L^2/2 J_b^T) P c_l + m_ax J_s^T e (e . c_l)
    k = m_a' L |P c_l|^2 + m_ax (e . c_l)^2

Lagrange's equations of ``T_a`` add to ``M_a qdd + C_a qd`` the current's terms::

    tau_c = (db/dq^T - db/dq) qd - 1/2 dk/dq

a gyroscopic part (skew, does no work) and the Munk moment ``-1/2 dk/dq`` (a slender body at
rest turns broadside to the flow). Without a current both vanish. The relative acceleration is
the body's, and a steady uniform flow has no Froude-Krylov force.
"""

from __future__ import annotations

from collections.abc import Sequence

import sympy as sp

from robodyn.robot.hydro import Cylinder, Fluid, LinkHydro
from robodyn.symbolic.hydro.geometry import CylinderMotion

__all__ = ["added_mass_matrix", "current_energy_terms", "current_torque"]


def added_mass_matrix(fluid: Fluid, h: LinkHydro, cyl: Cylinder,
                      motion: CylinderMotion) -> sp.ImmutableMatrix:
    """Added-mass matrix of one cylinder, shape (n, n), kg m^2 (kg for prismatic joints).

    Parameters
    ----------
    fluid : Fluid
    h : LinkHydro
        The coefficients C_a and C_ax of the cylinder's link.
    cyl : Cylinder
    motion : CylinderMotion
        The cylinder's Jacobians (expressions in q).

    Returns
    -------
    ImmutableMatrix, shape (n, n)
    """
    rho, r, length = fluid.density, cyl.radius, cyl.length
    a = motion.normal_projector() * motion.j_start
    b = motion.j_bend
    # m_a' = C_a rho pi r^2 (per unit length),  m_ax = C_ax rho pi r^2 L
    m_n = h.added_mass * rho * sp.pi * r**2
    m_ax = h.axial_added_mass * rho * sp.pi * r**2 * length
    # M_a = m_a' (L A^T A + L^2/2 (A^T B + B^T A) + L^3/3 B^T B)
    cross = a.T * b
    m = m_n * (length * a.T * a + length**2 / 2 * (cross + cross.T) + length**3 / 3 * b.T * b)
    if m_ax != 0:
        s = motion.axis.T * motion.j_start
        # + m_ax J_s^T e e^T J_s
        m += m_ax * s.T * s
    return sp.ImmutableMatrix(m)


def current_energy_terms(fluid: Fluid, h: LinkHydro, cyl: Cylinder,
                         motion: CylinderMotion) -> tuple[sp.Matrix, sp.Expr]:
    """``(b, k)`` of one cylinder in the current: ``T_a = 1/2 qd^T M_a qd - qd^T b + 1/2 k``.

    Parameters
    ----------
    fluid : Fluid
        Its ``current`` (world frame, m/s) is rotated into the link frame.
    h : LinkHydro
    cyl : Cylinder
    motion : CylinderMotion

    Returns
    -------
    b : Matrix, shape (n, 1)
        Added momentum taken by the current, kg m^2/s (kg m/s for prismatic joints).
    k : Expr
        Twice the added kinetic energy of the arm at rest in the current, J.
    """
    rho, r, length = fluid.density, cyl.radius, cyl.length
    c = motion.to_link(fluid.current)
    pc = motion.normal_projector() * c
    a = motion.normal_projector() * motion.j_start
    m_n = h.added_mass * rho * sp.pi * r**2
    m_ax = h.axial_added_mass * rho * sp.pi * r**2 * length
    # b = m_a' (L A^T + L^2/2 J_b^T) P c_l,  k = m_a' L |P c_l|^2
    b = m_n * (length * a.T + length**2 / 2 * motion.j_bend.T) * pc
    k = m_n * length * (pc.T * pc)[0, 0]
    if m_ax != 0:
        e_c = (motion.axis.T * c)[0, 0]
        # + m_ax J_s^T e (e . c_l),  + m_ax (e . c_l)^2
        b += m_ax * motion.j_start.T * motion.axis * e_c
        k += m_ax * e_c**2
    return b, k


def current_torque(b: sp.MatrixBase, k: sp.Expr, q: Sequence[sp.Symbol],
                   qd: Sequence[sp.Expr]) -> sp.ImmutableMatrix:
    """``tau_c``: Lagrange's equations of ``- qd^T b(q) + 1/2 k(q)``, shape (n, 1), N m (N).

    Parameters
    ----------
    b : Matrix, shape (n, 1)
        Summed over the cylinders (:func:`current_energy_terms`).
    k : Expr
    q : sequence of Symbol, length n
        ``b`` and ``k`` are differentiated with respect to them.
    qd : sequence of Expr, length n
    """
    n = len(q)
    if k == 0 and all(x == 0 for x in b):
        return sp.ImmutableMatrix(sp.zeros(n, 1))
    db = sp.Matrix(b).jacobian(list(q))
    # tau_c = (db/dq^T - db/dq) qd - 1/2 dk/dq
    grad = sp.Matrix([sp.diff(k, qj) for qj in q])
    return sp.ImmutableMatrix((db.T - db) * sp.Matrix(qd) - grad / 2)
