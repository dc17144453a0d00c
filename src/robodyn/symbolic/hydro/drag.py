"""Drag: normal (form) drag integrated along each cylinder, and axial skin friction.

Normal drag per unit length at arc length xi, on the normal velocity relative to the current
``u_n(xi) = P (v(xi) - c) = A + xi B`` (``A = P (J_s qd - R^T c)``, ``B = J_b qd``, link-frame
components: :mod:`robodyn.symbolic.hydro.geometry`)::

    f_d(xi) = -1/2 rho C_d D |u_n| u_n            (D = 2 r)

Its generalised force follows from the partial velocities ``J(xi) = J_s + xi J_b``; the joint
torque that overcomes it is::

    tau_d = int_0^L J(xi)^T (1/2 rho C_d D |u_n| u_n) d xi  ~=  sum_k w_k J(xi_k)^T (...)(xi_k)

by Gauss-Legendre quadrature (:mod:`robodyn.symbolic.hydro.quadrature`, rule and error there), exact for
a cylinder rotating about one of its ends in still water (the integrand is then ``xi^3``).
``|u| = sqrt(u . u)``: no branches in generated code.

Axial skin friction per unit length, on the axial relative velocity ``u_a = e . (J_s qd - c)``
(uniform along the cylinder, so the integral is exact), over the wetted perimeter ``pi D``::

    f_f = -1/2 rho C_f pi D |u_a| u_a e,        tau_f = L J_s^T e (1/2 rho C_f pi D |u_a| u_a)
"""

from __future__ import annotations

from collections.abc import Sequence

import sympy as sp

from robodyn.robot.hydro import Cylinder, Fluid, LinkHydro
from robodyn.symbolic.hydro.geometry import CylinderMotion
from robodyn.symbolic.hydro.quadrature import gauss_legendre

__all__ = ["drag_torque", "normal_relative_velocity", "skin_friction_torque"]


def normal_relative_velocity(motion: CylinderMotion, qd: Sequence[sp.Expr],
                             current: sp.MatrixBase) -> tuple[sp.Matrix, sp.Matrix]:
    """``(A, B)`` with ``u_n(xi) = A + xi B``, each (3, 1), m/s and 1/s, link-frame
    components (``current``: world frame)."""
    qv = sp.Matrix(qd)
    # A = P (J_s qd - R^T c),  B = J_b qd
    a = motion.normal_projector() * (motion.j_start * qv - motion.to_link(current))
    return a, motion.j_bend * qv


def _norm(v: sp.MatrixBase) -> sp.Expr:
    # |v| = sqrt(v . v)
    return sp.sqrt((v.T * v)[0, 0])


def drag_torque(fluid: Fluid, h: LinkHydro, cyl: Cylinder, motion: CylinderMotion,
                qd: Sequence[sp.Expr], points: int) -> sp.ImmutableMatrix:
    """Joint torques that overcome the normal drag of one cylinder, shape (n, 1) (N m or N).

    Parameters
    ----------
    fluid : Fluid
    h : LinkHydro
        C_d of the cylinder's link.
    cyl : Cylinder
    motion : CylinderMotion
    qd : sequence of Expr, length n
        Joint velocities, rad/s (m/s).
    points : int
        Gauss-Legendre points along the cylinder.
    """
    n = len(qd)
    if h.drag == 0:
        return sp.ImmutableMatrix(sp.zeros(n, 1))
    a, b = normal_relative_velocity(motion, qd, fluid.current)
    k = fluid.density * h.drag * cyl.radius  # 1/2 rho C_d D = rho C_d r
    out = sp.zeros(n, 1)
    for xi, w in gauss_legendre(points, cyl.length):
        u = a + xi * b
        jac = motion.j_start + xi * motion.j_bend
        # tau_d += w J(xi)^T (1/2 rho C_d D |u_n| u_n)
        out += w * jac.T * (k * _norm(u) * u)
    return sp.ImmutableMatrix(out)


def skin_friction_torque(fluid: Fluid, h: LinkHydro, cyl: Cylinder, motion: CylinderMotion,
                         qd: Sequence[sp.Expr]) -> sp.ImmutableMatrix:
    """Joint torques that overcome the axial skin friction of one cylinder, shape (n, 1)."""
    n = len(qd)
    if h.skin_friction == 0:
        return sp.ImmutableMatrix(sp.zeros(n, 1))
    e = motion.axis
    # u_a = a . (J_s qd - R^T c)   (link frame)
    u_a = (e.T * (motion.j_start * sp.Matrix(qd) - motion.to_link(fluid.current)))[0, 0]
    # tau_f = L J_s^T e (1/2 rho C_f pi D |u_a| u_a),  D = 2 r
    force = fluid.density * h.skin_friction * sp.pi * cyl.radius * sp.sqrt(u_a**2) * u_a
    return sp.ImmutableMatrix(cyl.length * motion.j_start.T * e * force)
