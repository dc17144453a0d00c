"""Hydrodynamic terms against closed forms written independently here."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

import robodyn as rd
from robodyn.robot.yaml_loader import load_yaml_text
from robodyn.symbolic.hydro.quadrature import gauss_legendre

# one uniform solid cylinder pivoted at one end, hanging along -y at q = 0 (angle from the
# vertical), turning about z; gravity along -y
PENDULUM = """\
name: wet_pendulum
parameters: {m: 3.0, L: 0.9, D: 0.08, rho: 1025.0, Ca: 1.0, Cd: 1.1, g: 9.81}
gravity: [0, -g, 0]
fluid: {density: rho}
joints:
  - name: q1
    type: revolute
    origin: {xyz: [0, 0, 0]}
    axis: [0, 0, 1]
    link:
      mass: m
      com: [0, -L/2, 0]
      inertia: {ixx: m*L**2/12, iyy: m*D**2/8, izz: m*L**2/12}
      hydro:
        cylinders: [{radius: D/2, length: L, axis: [0, -1, 0], start: [0, 0, 0]}]
        added_mass: Ca
        drag: Cd
"""


def _numbers(robot: rd.Robot) -> dict[sp.Symbol, float]:
    return robot.defaults()


def test_single_cylinder_equals_the_closed_form_to_1e12() -> None:
    robot = load_yaml_text(PENDULUM, source="pendulum.yaml")
    eom = rd.derive(robot)
    (q,), (qd,), (qdd,) = eom.q, eom.qd, eom.qdd
    s = robot.symbols
    m, L, D, rho, ca, cd, g = (s[k] for k in ("m", "L", "D", "rho", "Ca", "Cd", "g"))
    i_p = m * L**2 / 3
    # (I_p + C_a rho pi D^2 L^3 / 12) qdd + (rho C_d D L^4 / 8) qd |qd| + (m - rho pi D^2 L / 4) g L/2 sin q
    closed = ((i_p + ca * rho * sp.pi * D**2 * L**3 / 12) * qdd
              + rho * cd * D * L**4 / 8 * qd * sp.Abs(qd)
              + (m - rho * sp.pi * D**2 * L / 4) * g * L / 2 * sp.sin(q))
    f_robodyn = sp.lambdify([q, qd, qdd, *s.values()], eom.tau[0])
    f_closed = sp.lambdify([q, qd, qdd, *s.values()], closed)
    rng = np.random.default_rng(1)
    for _ in range(20):
        x = rng.uniform(-3, 3, 3)
        p = rng.uniform(0.5, 2.0, len(s))  # parameters away from their defaults too
        a, b = f_robodyn(*x, *p), f_closed(*x, *p)
        assert abs(a - b) <= 1e-12 * max(1.0, abs(b))
    # the drag term alone: the strip integral, not a drag lumped at mid-link (which is half)
    drag = sp.lambdify([q, qd, *s.values()], eom.hydro.drag[0])
    p = list(robot.parameters.values())
    exact = 1025.0 * 1.1 * 0.08 * 0.9**4 / 8 * 2.0 * 2.0
    lumped = 0.5 * 1025.0 * 1.1 * 0.08 * 0.9 * (0.45 * 2.0) ** 2 * 0.45
    assert drag(0.4, 2.0, *p) == pytest.approx(exact, rel=1e-13)
    assert drag(0.4, 2.0, *p) == pytest.approx(2 * lumped, rel=1e-13)


def test_single_cylinder_equals_the_closed_form_symbolically() -> None:
    robot = load_yaml_text(PENDULUM, source="pendulum.yaml")
    eom = rd.derive(robot)
    (q,), (qd,), (qdd,) = eom.q, eom.qd, eom.qdd
    s = robot.symbols
    m, L, D, rho, ca, cd, g = (s[k] for k in ("m", "L", "D", "rho", "Ca", "Cd", "g"))
    closed = ((m * L**2 / 3 + ca * rho * sp.pi * D**2 * L**3 / 12) * qdd
              + rho * cd * D * L**4 / 8 * qd * sp.Abs(qd)
              + (m - rho * sp.pi * D**2 * L / 4) * g * L / 2 * sp.sin(q))
    # L > 0 (a length); the quadrature's nodes and weights are 17-digit floats: the difference
    # must be nothing but their rounding
    diff = sp.expand(eom.tau[0] - closed).subs(sp.Abs(L), L)
    diff = sp.expand(diff)
    floats = [abs(float(f)) for f in diff.atoms(sp.Float)]
    assert all(f < 1e-15 for f in floats), diff
    assert sp.nsimplify(diff, tolerance=1e-15, rational=True) == 0


def two_link_closed_form(q1: float, q2: float, p: dict[str, float]) -> tuple[np.ndarray, np.ndarray]:
    """M and g of underwater_2r written out by hand (rigid rods + strip added mass + buoyancy)."""
    m1, m2, l1, l2, r1, r2, g, rho, ca = (p[k] for k in ("m1", "m2", "l1", "l2", "r1", "r2", "g",
                                                         "rho", "Ca"))
    i1 = m1 * (3 * r1**2 + l1**2) / 12
    i2 = m2 * (3 * r2**2 + l2**2) / 12
    lc1, lc2 = l1 / 2, l2 / 2
    c2 = np.cos(q2)
    m11 = m1 * lc1**2 + m2 * (l1**2 + lc2**2 + 2 * l1 * lc2 * c2) + i1 + i2
    m12 = m2 * (lc2**2 + l1 * lc2 * c2) + i2
    m22 = m2 * lc2**2 + i2
    # added mass per unit length mu_i = C_a rho pi r_i^2 on the normal velocity; link 2's strip at
    # xi from the elbow moves normal to itself with l1 cos(q2) qd1 + xi (qd1 + qd2)
    mu1, mu2 = ca * rho * np.pi * r1**2, ca * rho * np.pi * r2**2
    a11 = mu1 * l1**3 / 3 + mu2 * (l2 * l1**2 * c2**2 + l1 * c2 * l2**2 + l2**3 / 3)
    a12 = mu2 * (l1 * c2 * l2**2 / 2 + l2**3 / 3)
    a22 = mu2 * l2**3 / 3
    mass = np.array([[m11 + a11, m12 + a12], [m12 + a12, m22 + a22]])
    # gravity with the wet weights (m_i - rho V_i) at the centres (uniform cylinders)
    w1, w2 = m1 - rho * np.pi * r1**2 * l1, m2 - rho * np.pi * r2**2 * l2
    g2 = w2 * lc2 * g * np.cos(q1 + q2)
    grav = np.array([(w1 * lc1 + w2 * l1) * g * np.cos(q1) + g2, g2])
    return mass, grav


def test_two_link_m_and_g_equal_a_closed_form() -> None:
    robot = rd.load("underwater_2r")
    eom = rd.derive(robot)
    subs = robot.defaults()
    f_m = sp.lambdify([eom.q], eom.M.xreplace(subs))
    f_g = sp.lambdify([eom.q], eom.g.xreplace(subs))
    rng = np.random.default_rng(2)
    for q in rng.uniform(-np.pi, np.pi, (10, 2)):
        mass, grav = two_link_closed_form(*q, dict(robot.parameters))
        np.testing.assert_allclose(np.array(f_m(q), dtype=float), mass, rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(np.ravel(f_g(q)), grav, rtol=1e-12, atol=1e-11)


def test_added_mass_is_symmetric_positive_definite() -> None:
    robot = rd.load("underwater_2r")
    eom = rd.derive(robot)
    f = sp.lambdify([eom.q], eom.hydro.mass_matrix.xreplace(robot.defaults()))
    rng = np.random.default_rng(3)
    for q in rng.uniform(-np.pi, np.pi, (20, 2)):
        m = np.array(f(q), dtype=float)
        np.testing.assert_array_equal(m, m.T)
        assert np.linalg.eigvalsh(m).min() > 0


def test_uniform_current_on_a_link_at_rest_gives_the_drag_of_its_normal_component() -> None:
    text = PENDULUM.replace("fluid: {density: rho}", "fluid: {density: rho, current: [0.7, 0.4, 0]}")
    robot = load_yaml_text(text, source="current.yaml")
    eom = rd.derive(robot)
    f = sp.lambdify([eom.q, eom.qd], eom.hydro.drag.xreplace(robot.defaults()))
    rho, cd, d, length = 1025.0, 1.1, 0.08, 0.9
    for q in (0.0, 0.5, -1.2):
        e = np.array([np.sin(q), -np.cos(q), 0.0])  # link axis in the world
        c = np.array([0.7, 0.4, 0.0])
        u_n = -(c - e * (e @ c))  # relative velocity of the link at rest: -c, normal part
        f_per_length = -0.5 * rho * cd * d * u_n * np.linalg.norm(u_n)
        # torque about z of the uniform load: int xi (e x f) d xi = L^2/2 (e x f)_z
        torque = length**2 / 2 * np.cross(e, f_per_length)[2]
        assert float(np.ravel(f([q], [0.0]))[0]) == pytest.approx(-torque, rel=1e-12)


def test_quadrature_converges_to_the_closed_form() -> None:
    # a strip whose normal velocity changes sign inside the span (u_n = A + xi B, A = -0.3 B):
    # integrand xi |u_n| u_n has a kink at xi = 0.3; exact integral by hand
    def integral(points: int) -> float:
        return float(sum(w * xi * abs(xi - 0.3) * (xi - 0.3)
                         for xi, w in gauss_legendre(points, sp.Integer(1))))

    # int_0^1 xi (xi - 0.3) |xi - 0.3| d xi
    x = sp.Symbol("x")
    exact = float(sp.integrate(-x * (x - sp.Rational(3, 10))**2, (x, 0, sp.Rational(3, 10)))
                  + sp.integrate(x * (x - sp.Rational(3, 10))**2, (x, sp.Rational(3, 10), 1)))
    points = np.array([4, 6, 8, 12, 16, 24, 32, 48, 64])
    errors = np.array([abs(integral(n) - exact) for n in points])
    assert errors[-1] < 1e-7
    # algebraic convergence: the fitted rate (documented: about N^-2.5) is faster than N^-2
    slope = np.polyfit(np.log(points), np.log(errors), 1)[0]
    assert slope < -2.0
    # a polynomial integrand (the no-current single-cylinder case) is exact from 2 points
    cubic = sum(w * xi**3 for xi, w in gauss_legendre(2, sp.Integer(1)))
    assert float(cubic) == pytest.approx(0.25, abs=1e-16)
