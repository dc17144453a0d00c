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
``C_a = christoffel(M_a)`` (Lagrange's equations of ``T_a``). The current (uniform and steady)
does not enter: the relative acceleration equals the body's (Morison's inertia term without the
Froude-Krylov part, which vanishes for a steady uniform flow).
"""

from __future__ import annotations

import sympy as sp

from robodyn.hydro.geometry import CylinderMotion
from robodyn.hydro.schema import Cylinder, Fluid, LinkHydro

__all__ = ["added_mass_matrix"]


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
