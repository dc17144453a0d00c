"""``derive``: the equations of motion of a robot by one of three formulations.

    M(q) qdd + C(q, qd) qd + g(q) = tau_rigid + rotor inertia        (M includes G^2 J_m)
    tau = M qdd + C qd + g + tau_friction(qd)                        (full inverse dynamics)
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from functools import cached_property
from typing import Literal

import sympy as sp

from robodyn.robot.model import Robot
from robodyn.symbolic import crba
from robodyn.symbolic import kane as kane_mod
from robodyn.symbolic import lagrange as lagrange_mod
from robodyn.symbolic import newton_euler as ne
from robodyn.symbolic.coriolis import christoffel_coriolis, christoffel_program
from robodyn.symbolic.kinematics import (
    Kinematics,
    end_effector_jacobian,
    forward_kinematics,
    joint_symbols,
)
from robodyn.symbolic.opcount import OpCount, cse_op_count
from robodyn.symbolic.program import Program, Recorder
from robodyn.symbolic.regressor import (
    friction_columns,
    parameter_names,
    parameter_values,
    reflected_rotor_inertia,
    regressor,
)

Method = Literal["newton_euler", "lagrange", "kane"]
METHODS: tuple[str, ...] = ("newton_euler", "lagrange", "kane")


@dataclass(frozen=True)
class EquationsOfMotion:
    """Symbolic equations of motion of one robot by one formulation.

    Attributes
    ----------
    robot : Robot
    method : str
        "newton_euler", "lagrange" or "kane".
    q, qd, qdd : tuple of Symbol, length n
        Joint positions (rad or m), velocities and accelerations.
    M_rigid_form, g_form, tau_rigid_form : ImmutableMatrix or Program
        Rigid-body inertia matrix (n, n), gravity load (n, 1) and inverse dynamics (n, 1) as
        derived: a recursive :class:`Program` (Newton-Euler) or expressions. The properties
        ``M``, ``g`` and ``tau_rigid`` give them as expressions.
    derivation_time : float
        Seconds spent deriving ``M``, ``g`` and ``tau``.
    """

    robot: Robot
    method: str
    q: tuple[sp.Symbol, ...]
    qd: tuple[sp.Symbol, ...]
    qdd: tuple[sp.Symbol, ...]
    M_rigid_form: sp.ImmutableMatrix | Program
    g_form: sp.ImmutableMatrix | Program
    tau_rigid_form: sp.ImmutableMatrix | Program
    derivation_time: float = 0.0
    symbolic_inertia: bool = False
    _extra: dict = field(default_factory=dict, repr=False, compare=False)

    @property
    def dof(self) -> int:
        """Number of joints."""
        return len(self.q)

    @property
    def program(self) -> Program | None:
        """Recursive (intermediate-variable) form of the rigid-body ``tau``, when there is one."""
        form = self.tau_rigid_form
        return form if isinstance(form, Program) else None

    @cached_property
    def M(self) -> sp.ImmutableMatrix:  # noqa: N802 - the textbook name
        """Joint-space inertia including reflected rotor inertia ``G^2 J_m``, shape (n, n)."""
        return sp.ImmutableMatrix(_expanded(self.M_rigid_form) + _rotor_matrix(self.robot))

    @cached_property
    def g(self) -> sp.ImmutableMatrix:
        """Gravity load: the torques that hold the arm still, shape (n, 1)."""
        return _expanded(self.g_form)

    @cached_property
    def tau_rigid(self) -> sp.ImmutableMatrix:
        """Rigid-body inverse dynamics (no rotor inertia, no friction), shape (n, 1)."""
        return _expanded(self.tau_rigid_form)

    @cached_property
    def friction(self) -> sp.ImmutableMatrix:
        """Friction torques ``tau_f(qd)``, shape (n, 1)."""
        out = []
        for joint, qdj in zip(self.robot.joints, self.qd, strict=True):
            fr = joint.friction
            coeffs = (fr.viscous, fr.coulomb_positive, fr.coulomb_negative, fr.offset)
            out.append(sum((c * col for c, col in zip(coeffs, friction_columns(qdj), strict=True)),
                           sp.Integer(0)))
        return sp.ImmutableMatrix(out)

    @cached_property
    def rotor(self) -> sp.ImmutableMatrix:
        """Reflected rotor inertia torques ``G^2 J_m qdd``, shape (n, 1)."""
        return sp.ImmutableMatrix([reflected_rotor_inertia(self.robot, j) * self.qdd[j]
                                   for j in range(self.dof)])

    @cached_property
    def tau(self) -> sp.ImmutableMatrix:
        """Full inverse dynamics: rigid body + rotor inertia + friction, shape (n, 1)."""
        return sp.ImmutableMatrix(self.tau_rigid + self.rotor + self.friction)

    @cached_property
    def C(self) -> sp.ImmutableMatrix:  # noqa: N802 - the textbook name
        """Coriolis/centrifugal matrix (Christoffel form), shape (n, n)."""
        if isinstance(self.M_rigid_form, Program):
            # differentiate the recursive form: linear in its size, no expression swell
            return christoffel_program(self.M_rigid_form, self.q, self.qd).expand()
        return christoffel_coriolis(self.M, self.q, self.qd)

    @cached_property
    def params(self) -> sp.ImmutableMatrix:
        """Parameter vector of the regressor (15 per joint), shape (15 n, 1).

        With ``symbolic_inertia`` the inertial entries are the barycentric symbols themselves.
        """
        values = parameter_values(self.robot)
        if not self.symbolic_inertia:
            return values
        names = self.param_names
        return sp.ImmutableMatrix([sp.Symbol(names[k], real=True) if k % 15 < 10 else v
                                   for k, v in enumerate(values)])

    @property
    def param_names(self) -> tuple[str, ...]:
        """Names of the entries of :attr:`params`."""
        return parameter_names(self.dof)

    @cached_property
    def regressor_program(self) -> Program:
        """Recursive form of the regressor (from the Newton-Euler recursion)."""
        rec = Recorder(self._reserved())
        y = regressor(self.robot, self.q, self.qd, self.qdd, rec)
        return Program(tuple(rec.assignments), y).pruned()

    @cached_property
    def Y(self) -> sp.ImmutableMatrix:  # noqa: N802 - the textbook name
        """Regressor with ``Y @ params == tau``, shape (n, 15 n)."""
        return self.regressor_program.expand()

    @cached_property
    def kinematics(self) -> Kinematics:
        """Poses of every link frame, joint frame and the tool in the world frame."""
        return forward_kinematics(self.robot, self.q)

    @property
    def fk(self) -> sp.ImmutableMatrix:
        """End-effector pose in the world frame, shape (4, 4)."""
        return self.kinematics.end_effector

    @cached_property
    def jacobian(self) -> sp.ImmutableMatrix:
        """Geometric Jacobian of the end effector ``[v; omega]``, world frame, shape (6, n)."""
        return end_effector_jacobian(self.robot, self.kinematics)

    def op_counts(self) -> dict[str, OpCount]:
        """Operations after common-subexpression elimination, per output.

        Keys: "tau" (full inverse dynamics; the recursive form when there is one), "M", "g".
        """
        if "op_counts" not in self._extra:
            if self.program is not None:
                extra = sp.ImmutableMatrix(self.program.outputs + self.rotor + self.friction)
                tau_ops = cse_op_count(list(extra), self.program.assignments)
            else:
                tau_ops = cse_op_count(list(self.tau))
            self._extra["op_counts"] = {
                "tau": tau_ops,
                "M": _form_ops(self.M_rigid_form, upper_triangle=True),
                "g": _form_ops(self.g_form),
            }
        return self._extra["op_counts"]

    def numeric(self, values: dict[str, float] | None = None) -> dict[sp.Symbol, float]:
        """Substitution map of the robot's parameters: defaults overridden by ``values``."""
        merged = {**self.robot.parameters, **(values or {})}
        return {sp.Symbol(k, real=True): float(v) for k, v in merged.items()}

    def _reserved(self) -> set[str]:
        return {s.name for s in self.q + self.qd + self.qdd} | set(self.robot.parameters)


def _form_ops(form: sp.ImmutableMatrix | Program, upper_triangle: bool = False) -> OpCount:
    """Operations after CSE of a derived form (the recursive program when there is one)."""
    out = form.outputs if isinstance(form, Program) else form
    if upper_triangle:
        exprs = [out[i, j] for i in range(out.rows) for j in range(i, out.cols)]
    else:
        exprs = list(out)
    assignments = form.assignments if isinstance(form, Program) else ()
    return cse_op_count(exprs, assignments)


def _expanded(form: sp.ImmutableMatrix | Program) -> sp.ImmutableMatrix:
    return form.expand() if isinstance(form, Program) else sp.ImmutableMatrix(form)


def _rotor_matrix(robot: Robot) -> sp.ImmutableMatrix:
    return sp.ImmutableMatrix(sp.diag(*[reflected_rotor_inertia(robot, j) for j in range(robot.dof)]))


def derive(robot: Robot, method: Method = "newton_euler", *,
           symbolic_inertia: bool = False) -> EquationsOfMotion:
    """Derive the equations of motion of ``robot``.

    Parameters
    ----------
    robot : Robot
    method : {"newton_euler", "lagrange", "kane"}
        Recursive Newton-Euler (intermediate-variable form, linear cost), Lagrange-Euler from the
        energies, or Kane's method.
    symbolic_inertia : bool
        Replace every link's mass, first moment and inertia by the barycentric parameter symbols
        ``XXj, XYj, XZj, YYj, YZj, ZZj, MXj, MYj, MZj, Mj`` (the regressor's names), as needed for
        identification; supported by ``newton_euler`` (whose equations are linear in them).

    Returns
    -------
    EquationsOfMotion
    """
    if method not in METHODS:
        raise ValueError(f"unknown method {method!r}; choose one of {', '.join(METHODS)}")
    n = robot.dof
    if symbolic_inertia and method != "newton_euler":
        raise ValueError(
            f"symbolic_inertia=True is supported by method='newton_euler' (the barycentric "
            f"parameters enter it linearly), not by {method!r}"
        )
    inertials = ne.symbolic_inertials(n) if symbolic_inertia else None
    q, qd, qdd = joint_symbols(n)
    start = time.perf_counter()
    if method == "newton_euler":
        reserved = {s.name for s in q + qd + qdd} | set(robot.parameters)
        forms = []
        for build in (
            lambda rec: ne.inverse_dynamics(robot, q, qd, qdd, rec, inertials=inertials),
            lambda rec: crba.mass_matrix(robot, q, rec, inertials),
            lambda rec: ne.gravity_torque(robot, q, rec, inertials),
        ):
            rec = Recorder(reserved)
            out = build(rec)
            forms.append(Program(tuple(rec.assignments), out).pruned())
        tau_rigid, m_rigid, g = forms
    elif method == "lagrange":
        lag = lagrange_mod.lagrange(robot, q, qd, qdd)
        m_rigid, g, tau_rigid, c = lag.mass_matrix, lag.gravity, lag.tau, lag.coriolis
    else:
        terms = kane_mod.kane(robot, q, qd, qdd)
        m_rigid, g, tau_rigid = terms.mass_matrix, terms.gravity, terms.tau
    elapsed = time.perf_counter() - start
    eom = EquationsOfMotion(
        robot=robot, method=method, q=q, qd=qd, qdd=qdd,
        M_rigid_form=m_rigid, g_form=g, tau_rigid_form=tau_rigid, derivation_time=elapsed,
        symbolic_inertia=symbolic_inertia,
    )
    if method == "lagrange":
        # C was already needed for tau: keep it
        eom.__dict__["C"] = c
    return eom
