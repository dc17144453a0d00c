"""All hydrodynamic terms of a robot, one by one: ``eom.hydro``.

With the rigid-body terms they give the underwater equations of motion::

    (M + M_a) qdd + (C + C_a) qd + g + g_B + tau_c + tau_d + tau_f + tau_L + friction = tau

``M_a``, ``C_a``: added mass, ``tau_c``: its terms in a current (relative velocity, as in Fossen;
:mod:`~robodyn.symbolic.hydro.added_mass`); ``g_B``: buoyancy
(:mod:`~robodyn.symbolic.hydro.buoyancy`); ``tau_d``, ``tau_f``: normal drag and axial skin friction
(:mod:`~robodyn.symbolic.hydro.drag`); ``tau_L``: lift (:mod:`~robodyn.symbolic.hydro.lift`).

The terms are generalised forces computed once here from the link kinematics and added to each
formulation's rigid-body terms; Newton-Euler, Lagrange and Kane share them (they are not derived
three times).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import sympy as sp

from robodyn.robot.hydro import fluid_of, hydro_of
from robodyn.robot.model import Robot
from robodyn.symbolic.coriolis import christoffel_coriolis
from robodyn.symbolic.hydro.added_mass import added_mass_matrix, current_energy_terms, current_torque
from robodyn.symbolic.hydro.buoyancy import buoyancy_torque
from robodyn.symbolic.hydro.drag import drag_torque, skin_friction_torque
from robodyn.symbolic.hydro.geometry import cylinder_motion
from robodyn.symbolic.hydro.lift import lift_torque
from robodyn.symbolic.kinematics import forward_kinematics

__all__ = ["HydroTerms", "hydro_terms"]


@dataclass(frozen=True)
class HydroTerms:
    """The hydrodynamic terms of one robot, SymPy expressions in q, qd, qdd.

    Attributes
    ----------
    mass_matrix : ImmutableMatrix, shape (n, n)
        Added mass ``M_a(q)``, symmetric positive semidefinite.
    coriolis : ImmutableMatrix, shape (n, n)
        ``C_a(q, qd)``: Christoffel symbols of ``M_a``.
    buoyancy : ImmutableMatrix, shape (n, 1)
        ``g_B(q)``: enters the gravity load.
    added_mass : ImmutableMatrix, shape (n, 1)
        The whole added-mass force ``M_a qdd + C_a qd + tau_c``.
    current_added_mass : ImmutableMatrix, shape (n, 1)
        ``tau_c(q, qd)``: the added mass's terms in the current (the motion relative to the
        water, as in Fossen): a gyroscopic part and the Munk moment; zero without a current.
    drag, skin_friction, lift : ImmutableMatrix, shape (n, 1)
        ``tau_d``, ``tau_f``, ``tau_L`` (functions of q, qd and the current).
    """

    mass_matrix: sp.ImmutableMatrix
    coriolis: sp.ImmutableMatrix
    buoyancy: sp.ImmutableMatrix
    added_mass: sp.ImmutableMatrix
    current_added_mass: sp.ImmutableMatrix
    drag: sp.ImmutableMatrix
    skin_friction: sp.ImmutableMatrix
    lift: sp.ImmutableMatrix

    @property
    def velocity_forces(self) -> sp.ImmutableMatrix:
        """``tau_c + tau_d + tau_f + tau_L``, shape (n, 1): the fluid forces outside
        ``M_a qdd``, ``C_a qd`` and ``g_B``."""
        return sp.ImmutableMatrix(self.current_added_mass + self.drag + self.skin_friction + self.lift)

    @property
    def tau(self) -> sp.ImmutableMatrix:
        """Everything the fluid adds to the inverse dynamics, shape (n, 1)."""
        return sp.ImmutableMatrix(self.added_mass + self.buoyancy + self.drag + self.skin_friction
                                  + self.lift)


def hydro_terms(robot: Robot, q: Sequence[sp.Symbol], qd: Sequence[sp.Expr],
                qdd: Sequence[sp.Expr]) -> HydroTerms | None:
    """The hydrodynamic terms of ``robot``, or None when it has no ``fluid`` block.

    Parameters
    ----------
    robot : Robot
    q : sequence of Symbol, length n
        Joint positions (symbols: ``C_a`` differentiates ``M_a`` with respect to them).
    qd, qdd : sequence of Expr, length n
        Joint velocities and accelerations.

    Returns
    -------
    HydroTerms or None
    """
    fluid = fluid_of(robot)
    if fluid is None:
        return None
    n = robot.dof
    hydro = hydro_of(robot)
    kin = forward_kinematics(robot, q)
    m_a, b_c, k_c = sp.zeros(n, n), sp.zeros(n, 1), sp.Integer(0)
    still = all(c == 0 for c in fluid.current)
    drag, skin, lift = sp.zeros(n, 1), sp.zeros(n, 1), sp.zeros(n, 1)
    for i, h in enumerate(hydro):
        if h is None:
            continue
        for cyl in h.cylinders:
            motion = cylinder_motion(robot, kin, i, cyl, q)
            m_a += added_mass_matrix(fluid, h, cyl, motion)
            if not still:
                b, k = current_energy_terms(fluid, h, cyl, motion)
                b_c, k_c = b_c + b, k_c + k
            drag += drag_torque(fluid, h, cyl, motion, qd, h.quadrature)
            skin += skin_friction_torque(fluid, h, cyl, motion, qd)
            lift += lift_torque(fluid, h, cyl, motion, qd, h.quadrature)
    m_a = sp.ImmutableMatrix(m_a)
    c_a = christoffel_coriolis(m_a, q, qd)
    tau_c = current_torque(b_c, k_c, q, qd)
    # M_a qdd + C_a qd + tau_c
    inertial = m_a * sp.Matrix(qdd) + c_a * sp.Matrix(qd) + tau_c
    return HydroTerms(
        mass_matrix=m_a, coriolis=c_a,
        buoyancy=buoyancy_torque(robot, kin, fluid, hydro),
        added_mass=sp.ImmutableMatrix(inertial), current_added_mass=tau_c,
        drag=sp.ImmutableMatrix(drag),
        skin_friction=sp.ImmutableMatrix(skin), lift=sp.ImmutableMatrix(lift),
    )

