"""``derive``: the equations of motion of a robot by one of three formulations.

    M(q) qdd + C(q, qd) qd + g(q) = tau_rigid + rotor inertia        (M includes G^2 J_m)
    tau = M qdd + C qd + g + tau_friction(qd)                        (full inverse dynamics)

:meth:`EquationsOfMotion.numeric_function` evaluates ``M``, ``C``, ``g`` and ``tau`` of the
formulation's own straight-line form (after ``sympy.cse``) with NumPy, in seconds where
``lambdify`` of the expanded expressions takes minutes on a 6-joint arm.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from functools import cached_property
from typing import Literal

import numpy as np
import sympy as sp
from sympy.printing.numpy import NumPyPrinter

from robodyn.robot.errors import InputError
from robodyn.robot.model import Robot
from robodyn.symbolic import crba
from robodyn.symbolic import kane as kane_mod
from robodyn.symbolic import lagrange as lagrange_mod
from robodyn.symbolic import newton_euler as ne
from robodyn.symbolic.coriolis import christoffel_coriolis, christoffel_program
from robodyn.symbolic.hydro.terms import HydroTerms, hydro_terms
from robodyn.symbolic.kinematics import (
    Kinematics,
    end_effector_jacobian,
    forward_kinematics,
    joint_symbols,
)
from robodyn.symbolic.opcount import OpCount, cse_op_count
from robodyn.symbolic.program import Program, Recorder, eliminate_common_subexpressions
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
    symbolic_inertia : bool
        Inertial parameters kept as the barycentric symbols (see :func:`derive`).
    tau_rigid_program : Program or None
        Straight-line form of the rigid-body ``tau`` when ``tau_rigid_form`` holds expressions:
        Kane's ``-(F* + F)`` on its own program; None for Lagrange, whose ``tau`` is
        ``M qdd + C qd + g`` from its programs.
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
    tau_rigid_program: Program | None = field(default=None, repr=False, compare=False)
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
        """Joint-space inertia including reflected rotor inertia ``G^2 J_m`` and, under water,
        the added mass ``M_a``, shape (n, n)."""
        m = _expanded(self.M_rigid_form) + _rotor_matrix(self.robot)
        return sp.ImmutableMatrix(m if self.hydro is None else m + self.hydro.mass_matrix)

    @cached_property
    def g(self) -> sp.ImmutableMatrix:
        """Gravity load (buoyancy included under water): the torques that hold the arm still,
        shape (n, 1)."""
        g = _expanded(self.g_form)
        return g if self.hydro is None else sp.ImmutableMatrix(g + self.hydro.buoyancy)

    @cached_property
    def hydro(self) -> HydroTerms | None:
        """The hydrodynamic terms one by one (added mass, buoyancy, drag, skin friction, lift),
        or None for a robot without ``fluid``/``hydro`` blocks (see :mod:`robodyn.symbolic.hydro`)."""
        return hydro_terms(self.robot, self.q, self.qd, self.qdd)

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
        """Full inverse dynamics: rigid body + rotor inertia + friction (+ every hydrodynamic
        term under water), shape (n, 1)."""
        tau = self.tau_rigid + self.rotor + self.friction
        return sp.ImmutableMatrix(tau if self.hydro is None else tau + self.hydro.tau)

    @cached_property
    def C(self) -> sp.ImmutableMatrix:  # noqa: N802 - the textbook name
        """Coriolis/centrifugal matrix (Christoffel form), shape (n, n)."""
        if isinstance(self.M_rigid_form, Program):
            # differentiate the recursive form: linear in its size, no expression swell
            c = christoffel_program(self.M_rigid_form, self.q, self.qd).expand()
            return c if self.hydro is None else sp.ImmutableMatrix(c + self.hydro.coriolis)
        return christoffel_coriolis(self.M, self.q, self.qd)  # M holds the added mass

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

    def straight_line(self, name: str) -> Program:
        """The formulation's own straight-line form of ``name`` (before CSE).

        Parameters
        ----------
        name : {"M", "C", "g", "tau"}
            ``M`` with rotor inertia (n, n); ``C`` from the Christoffel symbols of this
            formulation's ``M`` program (n, n); ``g`` (n, 1); ``tau`` the full inverse dynamics
            (n, 1): Newton-Euler's recursion, Kane's ``-(F* + F)``, Lagrange's
            ``M qdd + C qd + g``, each plus rotor inertia and friction. Under water every
            output includes its hydrodynamic terms (:attr:`hydro`): ``M_a`` in ``M``, ``C_a``
            in ``C``, buoyancy in ``g``, all of them in ``tau``.

        Returns
        -------
        Program
        """
        if name not in _NUMERIC:
            raise InputError(f"unknown quantity {name!r}; choose one of {', '.join(_NUMERIC)}")
        key = f"straight_line_{name}"
        if key not in self._extra:
            self._extra[key] = self._straight_line(name)
        return self._extra[key]

    def _straight_line(self, name: str) -> Program:
        # under water the hydrodynamic terms (expressions) are added to each output
        h = self.hydro
        if name == "M":
            m = _as_program(self.M_rigid_form)
            out = m.outputs + _rotor_matrix(self.robot)
            return Program(m.assignments, sp.ImmutableMatrix(out if h is None else out + h.mass_matrix))
        if name == "g":
            g = _as_program(self.g_form)
            return g if h is None else Program(g.assignments, sp.ImmutableMatrix(g.outputs + h.buoyancy))
        if name == "C":
            m = self.M_rigid_form
            if isinstance(m, Program):
                c = christoffel_program(m, self.q, self.qd)
                return c if h is None else Program(c.assignments,
                                                   sp.ImmutableMatrix(c.outputs + h.coriolis))
            return Program((), self.C)  # the Christoffel symbols of M, added mass included
        extra = self.rotor + self.friction
        rigid = self.tau_rigid_form if isinstance(self.tau_rigid_form, Program) else self.tau_rigid_program
        if rigid is not None:
            extra = extra if h is None else extra + h.tau
            return Program(rigid.assignments, sp.ImmutableMatrix(rigid.outputs + extra))
        # tau = M qdd + C qd + g + friction from the programs (Lagrange; M has the rotor inertia;
        # under water M, C and g hold the added mass and buoyancy, the fluid forces are added)
        m, c, g = (self.straight_line(k) for k in ("M", "C", "g"))
        (rm, rc, rg), assignments = _merge(m, c, g)
        tau = (m.outputs.xreplace(rm) * sp.Matrix(self.qdd) + c.outputs.xreplace(rc) * sp.Matrix(self.qd)
               + g.outputs.xreplace(rg) + self.friction)
        return Program(tuple(assignments),
                       sp.ImmutableMatrix(tau if h is None else tau + h.velocity_forces))

    def numeric_function(self, name: str) -> Callable[..., np.ndarray]:
        """A NumPy function of ``M``, ``C``, ``g`` or ``tau`` of this formulation.

        The formulation's own straight-line form (:meth:`straight_line`) goes through
        ``sympy.cse`` and is printed once by ``lambdify``: built in seconds for a 7-joint arm and
        evaluated in tens of microseconds, where ``lambdify`` of the expanded expressions
        (``eom.tau``) takes minutes. Use it to compare the formulations numerically on large
        arms; for speed in production use :func:`robodyn.compile_model`.

        Parameters
        ----------
        name : {"M", "C", "g", "tau"}

        Returns
        -------
        callable
            ``M(q, values=None)`` -> (n, n); ``C(q, qd, values=None)`` -> (n, n);
            ``g(q, values=None)`` -> (n,); ``tau(q, qd, qdd, values=None)`` -> (n,) (N m or N).
            ``q``, ``qd``, ``qdd`` are (n,) or a batch (N, n) (results gain a leading N);
            ``values`` maps parameter names to numbers, overriding the robot's defaults (every
            barycentric symbol must be given when ``symbolic_inertia``).
        """
        key = f"numeric_{name}"
        if key not in self._extra:
            self._extra[key] = _NumericFunction(self, name, self.straight_line(name))
        return self._extra[key]

    def numeric(self, values: dict[str, float] | None = None) -> dict[sp.Symbol, float]:
        """Substitution map of the robot's parameters: defaults overridden by ``values``."""
        merged = {**self.robot.parameters, **(values or {})}
        return {sp.Symbol(k, real=True): float(v) for k, v in merged.items()}

    def _reserved(self) -> set[str]:
        return {s.name for s in self.q + self.qd + self.qdd} | set(self.robot.parameters)


_NUMERIC = ("M", "C", "g", "tau")


def _as_program(form: sp.ImmutableMatrix | Program) -> Program:
    return form if isinstance(form, Program) else Program((), sp.ImmutableMatrix(form))


def _merge(*programs: Program) -> tuple[list[dict[sp.Symbol, sp.Symbol]],
                                         list[tuple[sp.Symbol, sp.Expr]]]:
    """One assignment list for several programs; intermediates renamed apart where they clash.

    Returns the renaming of each program's symbols (a symbol defined identically by two programs
    is kept once) and the merged assignments.
    """
    defined: dict[sp.Symbol, sp.Expr] = {}
    out: list[tuple[sp.Symbol, sp.Expr]] = []
    renames = []
    for prog in programs:
        rename: dict[sp.Symbol, sp.Symbol] = {}
        for sym, expr in prog.assignments:
            expr = expr.xreplace(rename)
            if sym in defined and defined[sym] == expr:
                continue
            new = sym
            k = 1
            while new in defined:
                k += 1
                new = sp.Symbol(f"{sym.name}__{k}", real=True)
            if new != sym:
                rename[sym] = new
            defined[new] = expr
            out.append((new, expr))
        renames.append(rename)
    return renames, out


class _NumericFunction:
    """``M``, ``C``, ``g`` or ``tau`` of one formulation as a lambdified straight-line program."""

    def __init__(self, eom: EquationsOfMotion, name: str, prog: Program) -> None:
        self.name, self.n, self.shape = name, eom.dof, prog.outputs.shape
        self.defaults = {k: float(v) for k, v in eom.robot.parameters.items()}
        self.inputs = {"M": 1, "g": 1, "C": 2, "tau": 3}[name]
        joints = [list(v) for v in (eom.q, eom.qd, eom.qdd)[: self.inputs]]
        prog = prog.pruned()
        free = set(prog.outputs.free_symbols)
        for _, e in prog.assignments:
            free |= e.free_symbols
        free -= {s for s, _ in prog.assignments} | {s for v in joints for s in v}
        self.parameters = sorted(s.name for s in free)
        params = [sp.Symbol(p, real=True) for p in self.parameters]
        body, outs = eliminate_common_subexpressions(prog.assignments, list(prog.outputs), "_c")
        # terms printed in their stored order: sorting every Add is half of lambdify's time
        printer = NumPyPrinter({"order": "none", "fully_qualified_modules": False, "inline": True,
                                "allow_unknown_functions": True, "user_functions": {}})
        self._fn = sp.lambdify([*joints, params], outs, modules="numpy", cse=lambda _: (body, outs),
                               docstring_limit=0, printer=printer)

    def __call__(self, *args: np.ndarray, values: Mapping[str, float] | None = None) -> np.ndarray:
        if len(args) != self.inputs:
            names = ("q", "qd", "qdd")[: self.inputs]
            raise TypeError(f"{self.name}({', '.join(names)}, values=None): got {len(args)} arrays")
        arrays = [np.asarray(a, dtype=float) for a in args]
        for label, a in zip(("q", "qd", "qdd"), arrays, strict=False):
            if a.ndim not in (1, 2) or a.shape[-1] != self.n or a.shape[:-1] != arrays[0].shape[:-1]:
                raise InputError(f"{self.name}: {label} must be ({self.n},) or (N, {self.n}) like q, "
                                 f"got {a.shape}")
        merged = {**self.defaults, **(values or {})}
        missing = [p for p in self.parameters if p not in merged]
        if missing:
            raise InputError(f"{self.name}: no value for the parameter(s) {', '.join(missing)}")
        batch = arrays[0].shape[:-1]
        out = self._fn(*(a.T for a in arrays), [float(merged[p]) for p in self.parameters])
        flat = np.stack([np.broadcast_to(np.asarray(v, dtype=float), batch) for v in out], axis=-1)
        shape = (self.n, self.n) if self.name in ("M", "C") else (self.n,)
        return flat.reshape(batch + shape)


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
        raise InputError(f"unknown method {method!r}; choose one of {', '.join(METHODS)}")
    n = robot.dof
    if symbolic_inertia and method != "newton_euler":
        raise InputError(
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
        out = terms.forces.outputs
        # tau = -(F* + F) on Kane's own program
        tau_program = Program(terms.forces.assignments,
                              sp.ImmutableMatrix(-(out[:, 0] + out[:, 1]))).pruned()
    elapsed = time.perf_counter() - start
    eom = EquationsOfMotion(
        robot=robot, method=method, q=q, qd=qd, qdd=qdd,
        M_rigid_form=m_rigid, g_form=g, tau_rigid_form=tau_rigid, derivation_time=elapsed,
        symbolic_inertia=symbolic_inertia,
        tau_rigid_program=tau_program if method == "kane" else None,
    )
    if method == "lagrange":
        # C was already needed for tau: keep it (plus the added mass's Christoffel terms)
        eom.__dict__["C"] = c if eom.hydro is None else sp.ImmutableMatrix(c + eom.hydro.coriolis)
    return eom
