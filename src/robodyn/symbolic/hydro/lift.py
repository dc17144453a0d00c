"""Lift: a force per unit length perpendicular to the cylinder axis and to the relative flow.

With the normal relative velocity ``u_n(xi) = A + xi B`` (see :mod:`robodyn.symbolic.hydro.drag`)::

    f_L(xi) = 1/2 rho C_L D |u_n| (e x u_n)       magnitude 1/2 rho C_L D |u_n|^2

(sign convention: positive C_L pushes the strip along ``e x u_n``). A circular section in a
symmetric wake has no mean lift (C_L = 0 by default); a non-zero C_L models an asymmetric section
or a mean vortex-shedding bias. The joint torque that balances it::

    tau_L = -int_0^L J(xi)^T f_L(xi) d xi        (Gauss-Legendre, as for drag)
"""

from __future__ import annotations

from collections.abc import Sequence

import sympy as sp

from robodyn import spatial as S
from robodyn.robot.hydro import Cylinder, Fluid, LinkHydro
from robodyn.symbolic.hydro.drag import normal_relative_velocity
from robodyn.symbolic.hydro.geometry import CylinderMotion
from robodyn.symbolic.hydro.quadrature import gauss_legendre

__all__ = ["lift_torque"]


def lift_torque(fluid: Fluid, h: LinkHydro, cyl: Cylinder, motion: CylinderMotion,
                qd: Sequence[sp.Expr], points: int) -> sp.ImmutableMatrix:
    """Joint torques that balance the lift on one cylinder, shape (n, 1) (N m or N)."""
    n = len(qd)
    if h.lift == 0:
        return sp.ImmutableMatrix(sp.zeros(n, 1))
    a, b = normal_relative_velocity(motion, qd, fluid.current)
    k = fluid.density * h.lift * cyl.radius  # 1/2 rho C_L D
    e_x = S.skew(motion.axis)
    out = sp.zeros(n, 1)
    for xi, w in gauss_legendre(points, cyl.length):
        u = a + xi * b
        jac = motion.j_start + xi * motion.j_bend
        # tau_L -= w J(xi)^T (1/2 rho C_L D |u_n| (e x u_n))
        out -= w * jac.T * (k * sp.sqrt((u.T * u)[0, 0]) * (e_x * u))
    return sp.ImmutableMatrix(out)
