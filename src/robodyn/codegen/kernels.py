"""The functions every code generator emits, as language-neutral straight-line programs.

A :class:`Kernel` is one generated function: named array arguments in, named arrays out, and a
body of scalar assignments (after parameter folding and common-subexpression elimination). The
printers of :mod:`robodyn.codegen` only translate kernels; what is computed is decided here.

Kernels (``n`` joints, all arrays row-major)::

    inverse_dynamics(q, qd, qdd) -> tau (n)       M qdd + C qd + g + friction (rotor included)

Under water (a robot with hydro blocks) ``M`` includes the added mass, ``C qd`` its Christoffel
terms, ``g`` the buoyancy, and the inverse and forward dynamics also drag, skin friction and lift
(see :mod:`robodyn.symbolic.hydro`); ``|u|`` is printed as ``sqrt(u . u)``, without branches.
    mass_matrix(q)               -> M (n, n)      composite-rigid-body algorithm + G^2 J_m
    gravity(q)                   -> g (n)
    coriolis(q, qd)              -> c (n)         C(q, qd) qd
    forward_dynamics(q, qd, tau) -> qdd (n)       Cholesky of M, unrolled: no general inverse
    state_derivative(x, u)       -> xd (2 n)      x = [q; qd], u = tau
    forward_kinematics(q)        -> T (4, 4)      end-effector pose in the base frame
    jacobian(q)                  -> J (6, n)      [v; omega] of the tool origin, base frame
    regressor(q, qd, qdd)        -> Y (n, 15 n)   Y @ params == tau

Derivative kernels (:data:`DERIVATIVE_KERNEL_NAMES`, built on request), by differentiation of the
recorded programs: adjoints for the dynamics' derivatives (n outputs, 2 n directions,
:mod:`robodyn.symbolic.reverse_mode`), forward mode for the regressor's (15 n^2 outputs,
:mod:`robodyn.symbolic.forward_mode`)::

    inverse_dynamics_derivatives(q, qd, qdd) -> dtau (n, 2 n)      [d tau/dq, d tau/dqd]
    forward_dynamics_derivatives(q, qd, tau) -> dqdd (n, 3 n)      [d qdd/dq, d qdd/dqd, d qdd/dtau]
    regressor_derivatives(q, qd, qdd)        -> dY (15 n^2, 3 n)   [dY/dq, dY/dqd, dY/dqdd]
                                                  (:data:`REGRESSOR_DERIVATIVE_KERNEL_NAMES`)

``d qdd/dx = -M^-1 d tau/dx`` at ``qdd = FD(q, qd, tau)`` (differentiating ``tau(q, qd, qdd) = u``)
and ``d qdd/dtau = M^-1``, both by the Cholesky factor of the forward dynamics. Coulomb
friction's step contributes nothing (exact away from ``qd = 0``); viscous friction, rotor
inertia and the hydrodynamic terms are differentiated like the rest.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, fields
from typing import Any

import sympy as sp

from robodyn.codegen import optimize as opt
from robodyn.robot.errors import InputError
from robodyn.robot.model import Robot
from robodyn.symbolic import crba, forward_mode, reverse_mode
from robodyn.symbolic import newton_euler as ne
from robodyn.symbolic.hydro.terms import HydroTerms, hydro_terms
from robodyn.symbolic.kinematics import end_effector_jacobian, forward_kinematics, joint_symbols
from robodyn.symbolic.program import Recorder
from robodyn.symbolic.regressor import friction_columns, reflected_rotor_inertia, regressor


@dataclass(frozen=True)
class Argument:
    """A named array argument of a kernel.

    Attributes
    ----------
    name : str
        Array name in the generated code (``q``, ``tau``, ``M``).
    shape : tuple of int
        ``(n,)`` or ``(rows, cols)``; stored row-major (C, NumPy) or indexed ``(i, j)``.
    entries : tuple of Expr
        Row-major entries: the scalar symbols an input is unpacked into, or the expressions an
        output is assigned from.
    """

    name: str
    shape: tuple[int, ...]
    entries: tuple[sp.Expr, ...]

    @property
    def size(self) -> int:
        """Number of scalars."""
        out = 1
        for d in self.shape:
            out *= d
        return out


@dataclass(frozen=True)
class Kernel:
    """One generated function: ``outputs = f(inputs)`` through a straight-line ``body``.

    Attributes
    ----------
    name : str
    summary : str
        One line for the generated docstring/comment.
    inputs, outputs : tuple of Argument
    body : tuple of (Symbol, Expr)
        Scalar assignments in evaluation order.
    """

    name: str
    summary: str
    inputs: tuple[Argument, ...]
    outputs: tuple[Argument, ...]
    body: tuple[tuple[sp.Symbol, sp.Expr], ...]

    @property
    def locals(self) -> tuple[sp.Symbol, ...]:
        """Every scalar the body assigns."""
        return tuple(s for s, _ in self.body)

    def used_inputs(self) -> list[tuple[Argument, int, sp.Symbol]]:
        """Input scalars some assignment or output needs.

        Returns
        -------
        list of (Argument, int, Symbol)
            The input argument, the scalar's row-major index in it and the scalar's symbol, in
            the order of ``inputs`` and their entries (unused scalars left out).
        """
        used: set[sp.Basic] = set()
        for _, e in self.body:
            used |= e.free_symbols
        for arg in self.outputs:
            for e in arg.entries:
                used |= sp.sympify(e).free_symbols
        return [(a, k, s) for a in self.inputs for k, s in enumerate(a.entries) if s in used]


@dataclass(frozen=True)
class KernelSet:
    """All kernels of one robot with numeric parameters.

    Attributes
    ----------
    robot_name : str
    description_hash : str
        Hash of the robot description the code was generated from.
    dof : int
    parameters : tuple of (str, float)
        The parameter values folded into the code.
    kernels : tuple of Kernel
    runtime_parameters : tuple of str
        Named parameters left as runtime inputs: every kernel then takes a last input ``p``
        holding their values in this order (empty: all parameters folded).
    """

    robot_name: str
    description_hash: str
    dof: int
    parameters: tuple[tuple[str, float], ...]
    kernels: tuple[Kernel, ...]
    runtime_parameters: tuple[str, ...] = ()

    def __getitem__(self, name: str) -> Kernel:
        for k in self.kernels:
            if k.name == name:
                return k
        raise KeyError(f"no kernel named {name!r}; have {', '.join(k.name for k in self.kernels)}")

    @property
    def names(self) -> tuple[str, ...]:
        """Kernel names in generation order."""
        return tuple(k.name for k in self.kernels)


KERNEL_NAMES = ("inverse_dynamics", "mass_matrix", "gravity", "coriolis", "forward_dynamics",
                "state_derivative", "forward_kinematics", "jacobian", "regressor")

#: Kernels built only when asked for by name (larger: 2 n or 3 n directions).
DERIVATIVE_KERNEL_NAMES = ("inverse_dynamics_derivatives", "forward_dynamics_derivatives")

#: The regressor's derivatives (15 n^2 x 3 n entries: large), built apart from the others.
REGRESSOR_DERIVATIVE_KERNEL_NAMES = ("regressor_derivatives",)


@functools.lru_cache(maxsize=256)  # every model call asks (2 us a call otherwise)
def kernel_signature(name: str, n: int) -> tuple[tuple[tuple[str, int], ...], tuple[int, ...]]:
    """``((input name, width), ...), output shape`` of kernel ``name`` for ``n`` joints."""
    q, qd, qdd, tau = ("q", n), ("qd", n), ("qdd", n), ("tau", n)
    table: dict[str, tuple[tuple[tuple[str, int], ...], tuple[int, ...]]] = {
        "inverse_dynamics": ((q, qd, qdd), (n,)),
        "mass_matrix": ((q,), (n, n)),
        "gravity": ((q,), (n,)),
        "coriolis": ((q, qd), (n,)),
        "forward_dynamics": ((q, qd, tau), (n,)),
        "state_derivative": ((("x", 2 * n), ("u", n)), (2 * n,)),
        "forward_kinematics": ((q,), (4, 4)),
        "jacobian": ((q,), (6, n)),
        "regressor": ((q, qd, qdd), (n, 15 * n)),
        "inverse_dynamics_derivatives": ((q, qd, qdd), (n, 2 * n)),
        "forward_dynamics_derivatives": ((q, qd, tau), (n, 3 * n)),
        "regressor_derivatives": ((q, qd, qdd), (15 * n * n, 3 * n)),
    }
    if name not in table:
        raise InputError(f"unknown kernel {name!r}; choose from "
                         f"{', '.join(KERNEL_NAMES + DERIVATIVE_KERNEL_NAMES)}, "
                         "regressor_derivatives")
    return table[name]


def build_kernels(robot: Robot, parameters: Mapping[str, float] | None = None,
                  names: Sequence[str] = KERNEL_NAMES,
                  runtime: Sequence[str] = ()) -> KernelSet:
    """Straight-line programs of every generated function for ``robot``.

    Parameters
    ----------
    robot : Robot
    parameters : mapping of str to float, optional
        Overrides of the robot's parameter defaults (every named parameter must end up numeric).
    names : sequence of str
        Which kernels to build (default: all of :data:`KERNEL_NAMES`).
    runtime : sequence of str
        Named parameters kept symbolic: every kernel gains a last input ``p`` (P,) holding
        their values in this order (their symbols are renamed ``prm1_``, ``prm2_``, ...).

    Returns
    -------
    KernelSet
    """
    unknown = [k for k in (*(parameters or {}), *runtime) if k not in robot.parameters]
    if unknown:
        raise InputError(f"robot {robot.name!r} has no parameter(s) {', '.join(unknown)}; "
                         f"it has {', '.join(robot.parameters) or 'none'}")
    runtime = tuple(runtime)
    if len(set(runtime)) != len(runtime):
        raise InputError(f"runtime parameters named twice: {', '.join(runtime)}")
    merged = {**robot.parameters, **(parameters or {})}
    values = {sp.Symbol(k, real=True): float(v) for k, v in merged.items() if k not in runtime}
    # runtime parameters: renamed (a parameter may share a name with an output array, e.g. g)
    prm = [sp.Symbol(f"prm{i + 1}_", real=True) for i in range(len(runtime))]
    rename_prm = {sp.Symbol(k, real=True): s for k, s in zip(runtime, prm, strict=True)}
    n = robot.dof
    q, qd, qdd = joint_symbols(n)
    u = sp.symbols(f"u1:{n + 1}", real=True)
    inputs = {"q": _arg("q", q), "qd": _arg("qd", qd), "qdd": _arg("qdd", qdd), "tau": _arg("tau", u)}
    reserved = {s.name for s in (*q, *qd, *qdd, *u)} | set(merged) | set(KERNEL_NAMES)
    reserved |= {"q", "qd", "qdd", "tau", "M", "g", "c", "T", "J", "Y", "xd", "u", "qdd_out"}
    reserved |= {"dtau", "dqdd", "dY", "p", *DERIVATIVE_KERNEL_NAMES, *(s.name for s in prm)}
    reserved |= set(REGRESSOR_DERIVATIVE_KERNEL_NAMES)

    hyd = _pi_as_number(hydro_terms(robot, q, qd, qdd))
    builders = _builders(robot, q, qd, qdd, u, inputs, hyd)
    kernels = []
    for name in names:
        if name not in builders:
            raise InputError(f"unknown kernel {name!r}; choose from "
                             f"{', '.join(KERNEL_NAMES + DERIVATIVE_KERNEL_NAMES)}, "
                             "regressor_derivatives")
        kernels.append(_kernel(name, builders[name], reserved, prm, rename_prm, values))
    params = tuple((k, float(v)) for k, v in sorted(merged.items()) if k not in runtime)
    return KernelSet(robot.name, robot.description_hash, n, params, tuple(kernels), runtime)


_Builder = tuple[str, tuple[Argument, ...], str, tuple[int, ...], Callable[[Recorder], Sequence[sp.Expr]]]


def _builders(robot: Robot, q: Sequence[sp.Symbol], qd: Sequence[sp.Symbol], qdd: Sequence[sp.Symbol],
              u: Sequence[sp.Symbol], inputs: dict[str, Argument], hyd: Any) -> dict[str, _Builder]:
    """Per kernel: summary, inputs, output name and shape, and the recorder of its outputs."""
    n = len(q)

    def fd_outputs(rec: Recorder) -> list[sp.Expr]:
        return _forward_dynamics(robot, q, qd, u, rec, hyd)

    return {
        "inverse_dynamics": (
            "Inverse dynamics tau = M(q) qdd + C(q, qd) qd + g(q) + friction(qd), N m or N",
            (inputs["q"], inputs["qd"], inputs["qdd"]), "tau", (n,),
            lambda rec: list(_tau_full(robot, q, qd, qdd, rec, hyd))),
        "mass_matrix": (
            "Joint-space inertia matrix M(q) including reflected rotor inertia",
            (inputs["q"],), "M", (n, n),
            lambda rec: list(_mass_matrix(robot, q, rec, hyd))),
        "gravity": (
            "Gravity load g(q): the joint torques that hold the arm still",
            (inputs["q"],), "g", (n,),
            lambda rec: list(_plus(ne.gravity_torque(robot, q, rec), hyd and hyd.buoyancy))),
        "coriolis": (
            "Coriolis and centrifugal torques C(q, qd) qd",
            (inputs["q"], inputs["qd"]), "c", (n,),
            lambda rec: list(_plus(ne.inverse_dynamics(robot, q, qd, [0] * n, rec, with_gravity=False),
                                   hyd and hyd.coriolis * sp.Matrix(qd)))),
        "forward_dynamics": (
            "Forward dynamics qdd = M^-1 (tau - C qd - g - friction) by Cholesky of M",
            (inputs["q"], inputs["qd"], inputs["tau"]), "qdd", (n,), fd_outputs),
        "state_derivative": (
            "State derivative xd = [qd; qdd] of x = [q; qd] under joint torques u",
            (_arg("x", (*q, *qd)), _arg("u", u)), "xd", (2 * n,),
            lambda rec: [*qd, *fd_outputs(rec)]),
        "forward_kinematics": (
            "Pose of the end effector (tool frame) in the base frame, 4x4 homogeneous",
            (inputs["q"],), "T", (4, 4),
            lambda rec: list(forward_kinematics(robot, q, rec).end_effector)),
        "jacobian": (
            "Geometric Jacobian [v; omega] of the tool origin in the base frame",
            (inputs["q"],), "J", (6, n),
            lambda rec: list(end_effector_jacobian(robot, forward_kinematics(robot, q, rec)))),
        "regressor": (
            "Regressor Y(q, qd, qdd) with Y @ params == tau (15 parameters per joint)",
            (inputs["q"], inputs["qd"], inputs["qdd"]), "Y", (n, 15 * n),
            lambda rec: list(regressor(robot, q, qd, qdd, rec))),
        "inverse_dynamics_derivatives": (
            "Derivatives [d tau/dq, d tau/dqd] of the inverse dynamics (Coulomb step: 0)",
            (inputs["q"], inputs["qd"], inputs["qdd"]), "dtau", (n, 2 * n),
            lambda rec: _tau_derivatives(robot, q, qd, qdd, rec, hyd)),
        "forward_dynamics_derivatives": (
            "Derivatives [d qdd/dq, d qdd/dqd, d qdd/dtau] of the forward dynamics",
            (inputs["q"], inputs["qd"], inputs["tau"]), "dqdd", (n, 3 * n),
            lambda rec: _qdd_derivatives(robot, q, qd, u, rec, hyd)),
        "regressor_derivatives": (
            "Derivatives of the regressor: row (i 15 n + c) holds [dY_ic/dq, dY_ic/dqd, dY_ic/dqdd]",
            (inputs["q"], inputs["qd"], inputs["qdd"]), "dY", (15 * n * n, 3 * n),
            lambda rec: _regressor_derivatives(robot, q, qd, qdd, rec)),
    }


def _kernel(name: str, builder: _Builder, reserved: set[str], prm: Sequence[sp.Symbol],
            rename_prm: dict[sp.Symbol, sp.Symbol], values: dict[sp.Symbol, float]) -> Kernel:
    """One kernel: its outputs recorded, runtime parameters renamed, folded, CSE, ordered depth first
    from the outputs (:func:`robodyn.codegen.optimize.depth_first`), safe names."""
    summary, ins, out_name, shape, build = builder
    rec = Recorder(reserved)
    outs = build(rec)
    assignments = rec.assignments
    if prm:
        ins = (*ins, _arg("p", prm))
        assignments = [(s, e.xreplace(rename_prm)) for s, e in assignments]
        outs = [sp.sympify(o).xreplace(rename_prm) for o in outs]
    body, outs = opt.fold_parameters(assignments, outs, values)
    body, outs = opt.eliminate_common_subexpressions(body, outs)
    # each output's inputs computed just before it: short live ranges (fewer register spills)
    body = opt.depth_first(body, outs)
    rename = opt.safe_names(body, reserved)
    if rename:
        body = [(rename.get(s, s), e.xreplace(rename)) for s, e in body]
        outs = [sp.sympify(o).xreplace(rename) for o in outs]
    return Kernel(name, summary, ins, (Argument(out_name, shape, tuple(outs)),), tuple(body))


def _arg(name: str, symbols: Sequence[sp.Symbol]) -> Argument:
    return Argument(name, (len(symbols),), tuple(symbols))


def _friction(robot: Robot, qd: Sequence[sp.Expr]) -> list[sp.Expr]:
    out = []
    for joint, qdj in zip(robot.joints, qd, strict=True):
        fr = joint.friction
        coeffs = (fr.viscous, fr.coulomb_positive, fr.coulomb_negative, fr.offset)
        # tau_f = Fv qd + Fc+ H(qd) - Fc- H(-qd) + offset
        out.append(sum((c * col for c, col in zip(coeffs, friction_columns(qdj), strict=True)),
                       sp.Integer(0)))
    return out


def _pi_as_number(hyd: HydroTerms | None) -> HydroTerms | None:
    """The terms with ``pi`` as a double (generated C has no portable ``M_PI``)."""
    if hyd is None:
        return None
    pi = {sp.pi: sp.Float(math.pi, 17)}
    return HydroTerms(*(getattr(hyd, f.name).xreplace(pi) for f in fields(hyd)))


def _plus(a: Sequence[sp.Expr], b: sp.MatrixBase | None) -> list[sp.Expr]:
    """``a + b`` entrywise (``a`` alone when ``b`` is None)."""
    return list(a) if b is None else [x + y for x, y in zip(a, b, strict=True)]


def _hydro_tau(hyd: HydroTerms, qd: Sequence[sp.Expr], qdd: Sequence[sp.Expr]) -> sp.Matrix:
    # tau_h = M_a qdd + C_a qd + g_B + tau_d + tau_f + tau_L
    return (hyd.mass_matrix * sp.Matrix(qdd) + hyd.coriolis * sp.Matrix(qd) + hyd.buoyancy
            + hyd.velocity_forces)


def _tau_full(robot: Robot, q: Sequence[sp.Symbol], qd: Sequence[sp.Expr], qdd: Sequence[sp.Expr],
              rec: Recorder, hyd: HydroTerms | None = None) -> list[sp.Expr]:
    rigid = ne.inverse_dynamics(robot, q, qd, qdd, rec)
    fric = _friction(robot, qd)
    # tau = tau_rigid + G^2 J_m qdd + tau_f
    tau = [rigid[j] + reflected_rotor_inertia(robot, j) * qdd[j] + fric[j] for j in range(robot.dof)]
    return _plus(tau, None if hyd is None else _hydro_tau(hyd, qd, qdd))


def _mass_matrix(robot: Robot, q: Sequence[sp.Symbol], rec: Recorder,
                 hyd: HydroTerms | None = None) -> sp.Matrix:
    m = sp.Matrix(crba.mass_matrix(robot, q, rec))
    for j in range(robot.dof):
        # M_jj += G_j^2 J_m,j
        m[j, j] += reflected_rotor_inertia(robot, j)
    # M += M_a (added mass, under water)
    return m if hyd is None else m + hyd.mass_matrix


def _forward_dynamics(robot: Robot, q: Sequence[sp.Symbol], qd: Sequence[sp.Symbol],
                      tau: Sequence[sp.Symbol], rec: Recorder,
                      hyd: HydroTerms | None = None) -> list[sp.Expr]:
    """qdd by an unrolled Cholesky factorisation ``M = L L^T`` and two triangular solves."""
    return _forward_dynamics_factored(robot, q, qd, tau, rec, hyd)[0]


def _forward_dynamics_factored(
        robot: Robot, q: Sequence[sp.Symbol], qd: Sequence[sp.Symbol], tau: Sequence[sp.Symbol],
        rec: Recorder, hyd: HydroTerms | None = None,
) -> tuple[list[sp.Expr], dict[tuple[int, int], sp.Expr], list[sp.Expr]]:
    """``qdd``, the Cholesky factor ``L`` of ``M`` ({(i, j): L_ij}) and ``1 / L_jj``."""
    n = robot.dof
    m = _mass_matrix(robot, q, rec, hyd)
    # b = tau - (C qd + g + friction): inverse dynamics at qdd = 0
    rec.prefix = "h_"
    bias = _tau_full(robot, q, qd, [0] * n, rec, hyd)
    rec.prefix = ""
    b = [rec.scalar(tau[j] - bias[j], f"b{j + 1}") for j in range(n)]
    lower, inv_diag = _cholesky(m, rec)
    return _cholesky_solve(lower, inv_diag, b, rec, "y{i}", "qddot{i}"), lower, inv_diag


def _cholesky(m: sp.MatrixBase, rec: Recorder) -> tuple[dict[tuple[int, int], sp.Expr], list[sp.Expr]]:
    """Unrolled ``M = L L^T``: ``({(i, j): L_ij}, [1 / L_jj])``."""
    n = m.shape[0]
    lower: dict[tuple[int, int], sp.Expr] = {}
    inv_diag: list[sp.Expr] = []
    for j in range(n):
        # L_jj = sqrt(M_jj - sum_k L_jk^2)
        d = m[j, j] - sum((lower[j, k] ** 2 for k in range(j)), sp.Integer(0))
        ljj = rec.scalar(sp.sqrt(d), f"L{j + 1}_{j + 1}")
        inv_diag.append(rec.scalar(1 / ljj, f"iL{j + 1}"))
        lower[j, j] = ljj
        for i in range(j + 1, n):
            # L_ij = (M_ij - sum_k L_ik L_jk) / L_jj
            s = m[i, j] - sum((lower[i, k] * lower[j, k] for k in range(j)), sp.Integer(0))
            lower[i, j] = rec.scalar(s * inv_diag[j], f"L{i + 1}_{j + 1}")
    return lower, inv_diag


def _cholesky_solve(lower: dict[tuple[int, int], sp.Expr], inv_diag: Sequence[sp.Expr],
                    b: Sequence[sp.Expr], rec: Recorder, y_name: str, x_name: str) -> list[sp.Expr]:
    """``x = M^-1 b`` by ``L y = b``, ``L^T x = y``; locals named ``y_name``/``x_name`` (``{i}``)."""
    n = len(b)
    y: list[sp.Expr] = []
    for i in range(n):
        # L y = b
        y.append(rec.scalar((b[i] - sum((lower[i, k] * y[k] for k in range(i)), sp.Integer(0)))
                            * inv_diag[i], y_name.format(i=i + 1)))
    x: list[sp.Expr] = [sp.Integer(0)] * n
    for i in reversed(range(n)):
        # L^T x = y
        x[i] = rec.scalar((y[i] - sum((lower[k, i] * x[k] for k in range(i + 1, n)), sp.Integer(0)))
                          * inv_diag[i], x_name.format(i=i + 1))
    return x


def _tau_derivatives(robot: Robot, q: Sequence[sp.Symbol], qd: Sequence[sp.Symbol],
                     qdd: Sequence[sp.Symbol], rec: Recorder,
                     hyd: HydroTerms | None = None) -> list[sp.Expr]:
    """``[d tau/dq, d tau/dqd]`` (n, 2 n) row-major, by adjoints over the tau program (n outputs,
    2 n directions: reverse mode is the cheaper, :mod:`robodyn.symbolic.reverse_mode`)."""
    tau = _tau_full(robot, q, qd, qdd, rec, hyd)
    d = reverse_mode.jacobian(list(rec.assignments), tau, [*q, *qd], rec)
    return list(d)


def _regressor_derivatives(robot: Robot, q: Sequence[sp.Symbol], qd: Sequence[sp.Symbol],
                           qdd: Sequence[sp.Symbol], rec: Recorder) -> list[sp.Expr]:
    """``d Y / d [q, qd, qdd]`` (15 n^2, 3 n) row-major, by forward mode over the Y program.

    Row ``i 15 n + c`` is entry ``Y[i, c]``. Friction's step columns (Coulomb, offset) have
    derivative 0 (exact away from ``qd = 0``).
    """
    y = list(regressor(robot, q, qd, qdd, rec))
    d = forward_mode.jacobian(list(rec.assignments), y, [*q, *qd, *qdd], rec)
    return list(d)


def _qdd_derivatives(robot: Robot, q: Sequence[sp.Symbol], qd: Sequence[sp.Symbol],
                     tau: Sequence[sp.Symbol], rec: Recorder,
                     hyd: HydroTerms | None = None) -> list[sp.Expr]:
    """``[d qdd/dq, d qdd/dqd, d qdd/dtau]`` (n, 3 n) row-major.

    ``tau(q, qd, qdd) = u`` defines ``qdd``; its derivative gives ``M dqdd = du - dtau/dq dq -
    dtau/dqd dqd``, so ``d qdd/dx = -M^-1 d tau/dx`` at ``qdd = FD(q, qd, u)`` and ``d qdd/du =
    M^-1``, each column solved with the Cholesky factor the forward dynamics computes anyway.
    """
    n = robot.dof
    qdd, lower, inv_diag = _forward_dynamics_factored(robot, q, qd, tau, rec, hyd)
    rec.prefix = "i_"
    full = _tau_full(robot, q, qd, qdd, rec, hyd)
    rec.prefix = ""
    # qdd is held fixed: d tau/dx at constant qdd
    held = [s for s in qdd if isinstance(s, sp.Symbol)]
    d = reverse_mode.jacobian(list(rec.assignments), full, [*q, *qd], rec, constants=held)
    columns = []
    for k in range(2 * n):
        # M dqdd/dx_k = -dtau/dx_k
        columns.append(_cholesky_solve(lower, inv_diag, [-d[i, k] for i in range(n)], rec,
                                       f"dy{{i}}_{k + 1}", f"dqdd{{i}}_{k + 1}"))
    for k in range(n):
        # M dqdd/dtau_k = e_k
        e = [sp.Integer(int(i == k)) for i in range(n)]
        columns.append(_cholesky_solve(lower, inv_diag, e, rec, f"my{{i}}_{k + 1}",
                                       f"minv{{i}}_{k + 1}"))
    return [columns[k][i] for i in range(n) for k in range(3 * n)]
