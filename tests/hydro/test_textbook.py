"""``robodyn derive underwater_2link --format text|latex``: each hydrodynamic term printed on its
own, compact, and (evaluated as printed) summing to the compiled model's inverse dynamics."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

import robodyn as rd
from robodyn.cli import main
from robodyn.symbolic.hydro.textbook import underwater_textbook
from robodyn.symbolic.render import render_latex, render_text

# every effect on: a current along x and some lift (zero torque in the plane, see below)
WET = {"vc": 0.3, "CL": 0.2}


@pytest.fixture(scope="module")
def eom() -> rd.EquationsOfMotion:
    return rd.derive(rd.load("underwater_2link"))


def test_alias_loads_the_two_link_arm() -> None:
    assert rd.load("underwater_2link").description_hash == rd.load("underwater_2r").description_hash


def test_printed_terms_sum_to_the_compiled_tau(eom: rd.EquationsOfMotion) -> None:
    book = underwater_textbook(eom)
    n = eom.dof
    qv, qdv, qddv = (sp.Matrix(v) for v in (eom.q, eom.qd, eom.qdd))

    def mat(name: str, rows: int, cols: int) -> sp.Matrix:
        out = sp.zeros(rows, cols)
        for i in range(rows):
            for j in range(cols):
                key = (i, j) if cols > 1 else (i,)
                if cols > 1 and name in ("M", "M_A") and i > j:
                    key = (j, i)  # printed upper triangle
                out[i, j] = book.evaluate(book.line(name, *key).value)
        return out

    # (M + M_A) qdd + (C + C_A) qd + tau_Ac + g + g_B + tau_D + tau_L, each from its printed lines
    total = ((mat("M", n, n) + mat("M_A", n, n)) * qddv + (mat("C", n, n) + mat("C_A", n, n)) * qdv
             + mat("tau_Ac", n, 1) + mat("g", n, 1) + mat("g_B", n, 1) + mat("tau_D", n, 1)
             + mat("tau_L", n, 1))
    assert not any(isinstance(e, sp.Integral) for e in total.atoms(sp.Integral))
    f = sp.lambdify([qv, qdv, qddv], total.xreplace(eom.numeric(WET)), "numpy")
    model = rd.compile_model(eom.robot, parameters=WET)
    states = np.random.default_rng(11).uniform(-2, 2, (8, 3, n))
    for q, qd, qdd in states:
        ref = model.inverse_dynamics(q, qd, qdd)
        np.testing.assert_allclose(np.ravel(np.array(f(q, qd, qdd), dtype=float)), ref,
                                   rtol=1e-11, atol=1e-9)
    # the drag is not zero there: the printed integrals carry it
    drag = sp.lambdify([qv, qdv], mat("tau_D", n, 1).xreplace(eom.numeric(WET)), "numpy")
    assert np.abs(np.array(drag(states[0, 0], states[0, 1]), dtype=float)).max() > 1.0


def test_printed_added_mass_equals_a_closed_form(eom: rd.EquationsOfMotion) -> None:
    book = underwater_textbook(eom)
    s = eom.robot.symbols
    l1, l2, r1, r2, rho, ca = (s[k] for k in ("l1", "l2", "r1", "r2", "rho", "Ca"))
    c2 = sp.cos(eom.q[1])
    # strip theory by hand: mu_i = C_a rho pi r_i^2; link 1's strip at x moves normal with x qd1,
    # link 2's at x with (l1 cos q2 + x) qd1 + x qd2
    mu1, mu2 = ca * rho * sp.pi * r1**2, ca * rho * sp.pi * r2**2
    closed = {
        (0, 0): mu1 * l1**3 / 3 + mu2 * (l1**2 * c2**2 * l2 + l1 * c2 * l2**2 + l2**3 / 3),
        (0, 1): mu2 * (l1 * c2 * l2**2 / 2 + l2**3 / 3),
        (1, 1): mu2 * l2**3 / 3,
    }
    for (i, j), ref in closed.items():
        printed = book.line("M_A", i, j).value
        assert sp.expand(printed - ref) == 0
        # as compact as the rigid inertia: no base angle, cos(q2) at most squared
        assert eom.q[0] not in printed.free_symbols
        assert sp.count_ops(printed) <= sp.count_ops(sp.expand(ref))


def test_text_shows_each_term_separately_and_compactly(eom: rd.EquationsOfMotion) -> None:
    text = render_text(eom)
    book = underwater_textbook(eom)
    for name in ("M_A11", "M_A12", "M_A22", "C_A11", "g_B1", "g_B2", "tau_D1", "tau_D2",
                 "tau_L1", "v_n1(s)", "v_n2(s)", "M11", "g1"):
        assert f"\n{name} = " in text
    # the printed text is the str of the objects evaluated above
    assert f"tau_D2 = {sp.sstr(book.line('tau_D', 1).value, full_prec=False)}" in text
    assert "Integral(" in text and "6-point Gauss-Legendre" in text
    assert "sqrt(" not in text  # no expanded quadrature of |v_n|
    assert "sin(q1)**" not in text and "cos(q1)**" not in text  # no uncollapsed sin^2 + cos^2
    assert len(text) < 6000


def test_latex_document_compiles_its_terms(eom: rd.EquationsOfMotion) -> None:
    tex = render_latex(eom)
    for piece in (r"\mathbf{M}^{\mathrm{A}}_{11}", r"\tau^{\mathrm{D}}_{1}", r"\int\limits_{0}^{l_{2}}",
                  r"v_{n2}{\left(s \right)} &=", r"\mathbf{g}^{\mathrm{B}}_{2}"):
        assert piece in tex
    assert tex.count(r"\begin{align*}") == tex.count(r"\end{align*}")


def test_cli_derive_prints_the_textbook_form(tmp_path) -> None:
    out = tmp_path / "uw.txt"
    assert main(["derive", "underwater_2link", "--format", "text", "-o", str(out)]) == 0
    assert "\ntau_D1 = " in out.read_text()


def test_dry_robot_textbook_is_unchanged() -> None:
    text = render_text(rd.derive(rd.load("planar_2r")))
    assert "M_A" not in text and "\ntau1 = " in text


FOUR_JOINTS = """\
name: wet_4r
gravity: [0, -9.81, 0]
fluid: {density: 1000, current: [0.2, 0.1, 0]}
joints:
""" + "".join(f"""\
  - name: j{k}
    type: revolute
    dh: {{a: 0.4, alpha: 0, d: 0, theta: 0}}
    link:
      mass: 2
      com: [-0.2, 0, 0]
      inertia: {{ixx: 0.01, iyy: 0.03, izz: 0.03}}
""" for k in range(1, 5)) + """\
      hydro:
        cylinders: [{radius: 0.04, length: 0.4, axis: [1, 0, 0], start: [-0.4, 0, 0]}]
        quadrature: 3
"""


def test_large_arm_listing_includes_the_hydrodynamic_torques() -> None:
    from robodyn.robot.yaml_loader import load_yaml_text
    from robodyn.symbolic.render import _layout

    eom = rd.derive(load_yaml_text(FOUR_JOINTS, source="wet_4r.yaml"))
    layout = _layout(eom)  # the recursive listing: assignments in order, then tau1..tau4
    title, rows = layout.sections[0]
    rng = np.random.default_rng(3)
    x = rng.uniform(-2, 2, (3, 4))
    values: dict[sp.Symbol, float] = dict(zip([*eom.q, *eom.qd, *eom.qdd], x.ravel(), strict=True))
    tau = np.zeros(4)
    for row in rows:
        value = float(sp.Add(*(c * d for c, d in row.terms)).xreplace(values))
        if row.index:
            tau[row.index[0]] = value
        else:
            values[sp.Symbol(row.lhs, real=True)] = value
    ref = np.array([float(e.xreplace(values)) for e in eom.tau])
    np.testing.assert_allclose(tau, ref, rtol=1e-12)
    # and the fluid is in it: without the hydro rows tau would differ
    hydro = np.array([float(e.xreplace(values)) for e in eom.hydro.tau])
    assert np.abs(hydro).max() > 0.1
    assert "\ntau4 = " in render_text(eom)
