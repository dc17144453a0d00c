"""Textbook form of an underwater arm's equations, each hydrodynamic term shown on its own.

As the thesis's chapter 7 prints them::

    (M + M_A) qdd + (C + C_A) qd + tau_Ac + g + g_B + tau_D + tau_F + tau_L + friction = tau

* ``M``, ``C``, ``g``: the rigid body (rotor inertia included in ``M``);
* ``M_A``, ``C_A``: added mass, from link-frame Jacobians (so a planar arm's added mass is a
  function of the relative joint angles only, as compact as its rigid inertia);
* ``tau_Ac``: the added mass's terms in a current (printed when the current is not zero; see
  :mod:`robodyn.symbolic.hydro.added_mass`);
* ``g_B``: buoyancy;
* ``tau_D``: normal drag. The normal relative velocity of each cylinder is defined once, as a
  function of the arc length ``s`` in the link frame (``v_n2(s) = (l1 cos(q2) + s) qd1 + s qd2``
  for the elbow link of a planar arm), and ``tau_D`` is written as the integral over ``s``
  (the model evaluates it with the Gauss-Legendre rule stated with it)::

      tau_D_j = sum_cylinders 1/2 rho C_d D int_0^L |u_n(s)| u_n(s) . d u_n(s)/d qd_j ds

  (``d u_n / d qd_j`` is the normal part of the partial velocity ``J_j(s)``, and ``u_n`` is
  normal, so this equals ``J_j(s) . f(s)``.)
* ``tau_L``: lift, ``-1/2 rho C_L D int |u_n| (e x u_n) . d u_n/d qd_j ds`` (zero for an arm
  moving in a plane: the lift is then normal to that plane);
* ``tau_F``: axial skin friction (uniform along a cylinder: closed form).

Every coefficient is simplified by a trigonometric pass on expressions that are already short, so
a two- or three-joint arm renders in seconds. :meth:`UnderwaterTextbook.evaluate` turns the
printed objects themselves into numbers (each integral by the model's own quadrature rule).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import sympy as sp

from robodyn import spatial as S
from robodyn.robot.errors import InputError
from robodyn.robot.hydro import fluid_of, hydro_of
from robodyn.symbolic.coriolis import christoffel_coriolis
from robodyn.symbolic.hydro.added_mass import added_mass_matrix, current_energy_terms, current_torque
from robodyn.symbolic.hydro.geometry import CylinderMotion, cylinder_motion
from robodyn.symbolic.hydro.quadrature import gauss_legendre

if TYPE_CHECKING:
    from robodyn.symbolic.eom import EquationsOfMotion

__all__ = ["Line", "Section", "UnderwaterTextbook", "underwater_textbook"]

#: ``(coefficient, rate monomial)`` pairs; the value of a line is their sum.
Terms = tuple[tuple[sp.Expr, sp.Expr], ...]

#: Arc length along a cylinder, m.
S_SYMBOL = sp.Symbol("s", real=True, nonnegative=True)
_AXES = "xyz"


@dataclass(frozen=True)
class Line:
    """One printed equation ``name[index] = sum of terms``.

    Attributes
    ----------
    name : str
        ``M``, ``C``, ``g``, ``friction``, ``M_A``, ``C_A``, ``g_B``, ``tau_D``, ``tau_F``,
        ``tau_L`` (with a 0-based ``index``), or a defined function such as ``v_n2(s)`` (empty
        index; ``terms`` then give its value as an expression of ``s``).
    index : tuple of int
    terms : tuple of (Expr, Expr)
    mirror : bool
        Off-diagonal entry of a symmetric matrix (printed ``M12 = M21``).
    """

    name: str
    index: tuple[int, ...]
    terms: Terms
    mirror: bool = False

    @property
    def value(self) -> sp.Expr:
        """The printed expression (may hold integrals and the functions ``v_n..(s)``)."""
        return sp.Add(*(c * d for c, d in self.terms))


@dataclass(frozen=True)
class Section:
    """A titled group of lines."""

    title: str
    lines: tuple[Line, ...]


@dataclass(frozen=True)
class UnderwaterTextbook:
    """The textbook form of an underwater arm.

    Attributes
    ----------
    sections : tuple of Section
        In printing order: rigid M, C, g (and friction when present), then M_A, C_A, g_B, the
        normal relative velocities, tau_D, tau_F, tau_L.
    functions : dict
        Each printed function (``v_n2(s)`` ...) to its value, an expression of ``s`` (m), q and qd.
    rules : dict
        Each printed integral's upper limit ``L`` (an expression) to the Gauss-Legendre nodes and
        weights the model uses on ``[0, L]``.
    """

    sections: tuple[Section, ...]
    functions: dict[sp.Function, sp.Expr]
    rules: dict[sp.Integral, tuple[tuple[sp.Expr, sp.Expr], ...]]

    def line(self, name: str, *index: int) -> Line:
        """The line ``name[index]`` (0-based)."""
        for section in self.sections:
            for ln in section.lines:
                if ln.name == name and ln.index == tuple(index):
                    return ln
        raise KeyError(f"no printed line {name}{index}")

    def evaluate(self, expr: sp.Expr) -> sp.Expr:
        """A printed expression with each integral replaced by the model's quadrature sum and
        each ``v_n..(s)`` by its definition: what the compiled model computes.

        Parameters
        ----------
        expr : sympy.Expr
            A :attr:`Line.value`.

        Returns
        -------
        sympy.Expr
            In q, qd, qdd and the named parameters only.
        """
        def quadrature(integral: sp.Integral) -> sp.Expr:
            body = integral.function
            return sp.Add(*(w * body.subs(S_SYMBOL, x) for x, w in self.rules[integral]))

        out = expr.replace(lambda e: isinstance(e, sp.Integral), quadrature)
        for f, value in self.functions.items():
            out = out.replace(f.func, sp.Lambda(S_SYMBOL, value))
        return out


def _linear_simplify(expr: sp.Expr, variables: Sequence[sp.Expr]) -> sp.Expr:
    """``expr`` (linear in ``variables``) with each coefficient simplified by ``trigsimp``."""
    expr = sp.expand(expr)
    out = sp.Integer(0)
    rest = expr
    for v in variables:
        coeff = expr.coeff(v)
        if coeff != 0:
            out += sp.factor_terms(sp.trigsimp(coeff)) * v
            rest -= coeff * v
    rest = sp.expand(rest)
    return out + (sp.factor_terms(sp.trigsimp(rest)) if rest != 0 else 0)


def _tidy(expr: sp.Expr, rates: Sequence[sp.Symbol]) -> Terms:
    """Terms grouped by products of the joint rates, each coefficient trig-simplified."""
    groups: dict[sp.Expr, sp.Expr] = {}
    for term in sp.Add.make_args(sp.expand(expr)):
        coeff, dep = term.as_independent(*rates, as_Add=False)
        groups[dep] = groups.get(dep, sp.Integer(0)) + coeff
    out = []
    for dep in sorted(groups, key=lambda d: (d == 1, sp.default_sort_key(d))):
        coeff = sp.factor_terms(sp.trigsimp(groups[dep]))
        if coeff != 0:
            out.append((coeff, dep))
    return tuple(out) or ((sp.Integer(0), sp.Integer(1)),)


def _matrix_lines(name: str, mat: sp.MatrixBase, rates: Sequence[sp.Symbol], *,
                  symmetric: bool = False) -> tuple[Line, ...]:
    rows, cols = mat.shape
    if cols == 1:
        return tuple(Line(name, (i,), _tidy(mat[i, 0], rates)) for i in range(rows))
    return tuple(Line(name, (i, j), _tidy(mat[i, j], rates), symmetric and i != j)
                 for i in range(rows) for j in range(i if symmetric else 0, cols))


def _simplified(motion: CylinderMotion) -> CylinderMotion:
    """The cylinder's link-frame Jacobians with each entry trig-simplified."""
    def simp(m: sp.MatrixBase) -> sp.ImmutableMatrix:
        return sp.ImmutableMatrix(m.applyfunc(lambda e: sp.factor_terms(sp.trigsimp(sp.expand(e)))))

    return dataclasses.replace(motion, j_start=simp(motion.j_start), j_bend=simp(motion.j_bend))


def _rule_text(points: int) -> str:
    nodes = gauss_legendre(points, sp.Integer(1))
    xs = ", ".join(f"{float(x):.6g}" for x, _ in nodes)
    ws = ", ".join(f"{float(w):.6g}" for _, w in nodes)
    return f"{points}-point Gauss-Legendre rule on [0, L]: s_k/L = ({xs}), w_k/L = ({ws})"


def underwater_textbook(eom: EquationsOfMotion) -> UnderwaterTextbook:
    """The textbook form of ``eom`` with every hydrodynamic term separate.

    Parameters
    ----------
    eom : EquationsOfMotion
        Of a robot with a ``fluid`` block (``eom.hydro`` is not None).

    Returns
    -------
    UnderwaterTextbook
    """
    hydro = eom.hydro
    if hydro is None:
        raise InputError(f"{eom.robot.name}: no fluid block, so no hydrodynamic terms to print")
    robot, n = eom.robot, eom.dof
    q, qd = list(eom.q), list(eom.qd)
    fluid = fluid_of(robot)
    assert fluid is not None
    kin = eom.kinematics
    s = S_SYMBOL
    m_a, b_c, k_c = sp.zeros(n, n), sp.zeros(n, 1), sp.Integer(0)
    drag, skin, lift = sp.zeros(n, 1), sp.zeros(n, 1), sp.zeros(n, 1)
    functions: dict[sp.Function, sp.Expr] = {}
    rules: dict[sp.Integral, tuple[tuple[sp.Expr, sp.Expr], ...]] = {}
    velocity_lines: list[Line] = []
    notes: list[str] = []
    for i, h in enumerate(hydro_of(robot)):
        if h is None:
            continue
        for c, cyl in enumerate(h.cylinders):
            motion = _simplified(cylinder_motion(robot, kin, i, cyl, q))
            m_a += added_mass_matrix(fluid, h, cyl, motion)
            b, k = current_energy_terms(fluid, h, cyl, motion)
            b_c, k_c = b_c + b, k_c + k
            # u_n(s) = P (J_s qd - R^T c) + s J_b qd   (link frame)
            p = sp.eye(3) - cyl.axis * cyl.axis.T
            current = sp.Matrix(motion.to_link(fluid.current))
            u = p * (motion.j_start * sp.Matrix(qd) - current) + s * motion.j_bend * sp.Matrix(qd)
            u = u.applyfunc(lambda e: _linear_simplify(e, [*qd, s]))
            tag = f"{i + 1}" + (chr(ord("a") + c) if len(h.cylinders) > 1 else "")
            nonzero = [k for k in range(3) if u[k] != 0]
            comps = sp.zeros(3, 1)
            for k in nonzero:
                f = sp.Function(f"v_n{tag}" + (f"_{_AXES[k]}" if len(nonzero) > 1 else ""))(s)
                functions[f] = u[k]
                comps[k] = f
                velocity_lines.append(Line(f.func.__name__ + "(s)", (), _tidy(u[k], qd)))
            if not nonzero:
                continue
            notes.append(f"v_n{tag}: cylinder {c + 1} of link {i + 1}, "
                         + ", ".join(f"link-frame {_AXES[k]}" for k in nonzero))
            # |u_n| (a single component k: |u_k|)
            speed = (sp.Abs(comps[nonzero[0]]) if len(nonzero) == 1
                     else sp.sqrt(sum(comps[k] ** 2 for k in nonzero)))
            # d u_n / d qd_j: the normal partial velocity (free of qd)
            partial = [u.diff(v).applyfunc(lambda e: sp.factor_terms(sp.trigsimp(e))) for v in qd]
            e_x = S.skew(cyl.axis)
            for j in range(n):
                along = (comps.T * partial[j])[0, 0]
                if h.drag != 0 and along != 0:
                    integral = sp.Integral(speed * along, (s, 0, cyl.length))
                    rules[integral] = tuple(gauss_legendre(h.quadrature, cyl.length))
                    # tau_D_j += 1/2 rho C_d D int |u_n| u_n . du_n/dqd_j ds
                    drag[j] += fluid.density * h.drag * cyl.radius * integral
                across = sp.expand((e_x * comps).T * partial[j])[0, 0]
                if h.lift != 0 and across != 0:
                    integral = sp.Integral(speed * across, (s, 0, cyl.length))
                    rules[integral] = tuple(gauss_legendre(h.quadrature, cyl.length))
                    # tau_L_j -= 1/2 rho C_L D int |u_n| (e x u_n) . du_n/dqd_j ds
                    lift[j] -= fluid.density * h.lift * cyl.radius * integral
            if h.skin_friction != 0:
                e = sp.Matrix(cyl.axis)
                # u_a = a . (J_s qd - R^T c);  tau_F = L J_s^T a (1/2 rho C_f pi D |u_a| u_a)
                u_a = _linear_simplify((e.T * (motion.j_start * sp.Matrix(qd) - current))[0, 0],
                                       qd)
                force = fluid.density * h.skin_friction * sp.pi * cyl.radius * sp.Abs(u_a) * u_a
                skin += cyl.length * motion.j_start.T * e * force
    tau_c = current_torque(b_c, k_c, q, qd)
    sections = _sections(eom, m_a, tau_c, drag, skin, lift, tuple(velocity_lines), notes)
    return UnderwaterTextbook(tuple(sections), functions, rules)


def _sections(eom: EquationsOfMotion, m_a: sp.Matrix, tau_c: sp.Matrix, drag: sp.Matrix,
              skin: sp.Matrix, lift: sp.Matrix, velocity_lines: tuple[Line, ...],
              notes: list[str]) -> list[Section]:
    """The printed sections: rigid M, C, g (and friction), then M_A, C_A, tau_Ac (when a
    current can flow), g_B, v_n(s), tau_D, tau_F (when any), tau_L."""
    hydro, robot, n = eom.hydro, eom.robot, eom.dof
    q, qd = list(eom.q), list(eom.qd)
    rates = qd + list(eom.qdd)
    c_a = christoffel_coriolis(sp.ImmutableMatrix(m_a), q, qd)
    m_rigid = sp.ImmutableMatrix(eom.M - hydro.mass_matrix)
    c_rigid = sp.ImmutableMatrix(eom.C - hydro.coriolis)
    g_rigid = sp.ImmutableMatrix(eom.g - hydro.buoyancy)
    sections = [
        Section("rigid-body inertia matrix M(q) (symmetric, rotor inertia included)",
                _matrix_lines("M", m_rigid, rates, symmetric=True)),
        Section("rigid-body Coriolis and centrifugal matrix C(q, qd) (Christoffel symbols)",
                _matrix_lines("C", c_rigid, rates)),
        Section("gravity load g(q)", _matrix_lines("g", g_rigid, rates)),
    ]
    if any(f != 0 for f in eom.friction):
        sections.append(Section("joint friction", _matrix_lines("friction", eom.friction, rates)))
    sections += [
        Section("added mass M_A(q) (symmetric; strip theory along each cylinder)",
                _matrix_lines("M_A", m_a, rates, symmetric=True)),
        Section("added-mass Coriolis and centrifugal matrix C_A(q, qd) (Christoffel symbols of "
                "M_A)", _matrix_lines("C_A", c_a, rates)),
    ]
    if any(x != 0 for x in tau_c):
        sections.append(Section(
            "added mass in the current tau_Ac(q, qd) (the motion relative to the water: "
            "T_A = 1/2 qd^T M_A qd - qd^T b(q) + 1/2 k(q), tau_Ac = (db/dq^T - db/dq) qd - "
            "1/2 dk/dq; the last term is the Munk moment)",
            _matrix_lines("tau_Ac", tau_c, rates)))
    sections += [
        Section("buoyancy g_B(q) (rho V g at each centre of buoyancy)",
                _matrix_lines("g_B", hydro.buoyancy, rates)),
        Section("normal velocity relative to the current, in each link frame, at arc length s "
                "(m) along each cylinder: " + "; ".join(notes), velocity_lines),
    ]
    points = sorted({h.quadrature for h in hydro_of(robot) if h is not None})
    rule = "; ".join(_rule_text(k) for k in points)
    sections.append(Section(
        "drag tau_D(q, qd) = sum over cylinders of 1/2 rho C_d D int_0^L |v_n(s)| v_n(s) . "
        f"dv_n(s)/dqd_j ds; the model evaluates each integral by the {rule}",
        tuple(Line("tau_D", (j,), ((drag[j], sp.Integer(1)),)) for j in range(n))))
    if any(x != 0 for x in skin):
        sections.append(Section("axial skin friction tau_F(q, qd) (uniform along each cylinder)",
                                tuple(Line("tau_F", (j,), _tidy(skin[j], qd)) for j in range(n))))
    sections.append(Section(
        "lift tau_L(q, qd) = -sum over cylinders of 1/2 rho C_L D int_0^L |v_n(s)| (e x v_n(s)) . "
        "dv_n(s)/dqd_j ds (same rule)",
        tuple(Line("tau_L", (j,), ((lift[j], sp.Integer(1)),)) for j in range(n))))
    return sections
