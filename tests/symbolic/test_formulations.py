"""The three formulations against closed forms and against each other."""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest
import sympy as sp

import robodyn as rd
from tests.numeric_eval import evaluator, random_states

METHODS = ("newton_euler", "lagrange", "kane")


@cache
def eom_of(name: str, method: str) -> rd.EquationsOfMotion:
    return rd.derive(rd.load(name), method=method)


# --- seed eqs. 2.46-2.47: trolley with an inverted pendulum -------------------------------------


@pytest.mark.parametrize("method", METHODS)
def test_trolley_pendulum_reproduces_seed_equations_exactly(method):
    eom = eom_of("trolley_pendulum", method)
    big_m, m, ell, g = (sp.Symbol(s, real=True) for s in ("M", "m", "l", "g"))
    _, th = eom.q
    _, thd = eom.qd
    xdd, thdd = eom.qdd
    # F - (M+m) x'' - (m l/2) cos(th) th'' + (m l/2) sin(th) th'^2 = 0          (2.46)
    force = (big_m + m) * xdd + m * ell / 2 * sp.cos(th) * thdd - m * ell / 2 * sp.sin(th) * thd**2
    # (m g l/2) sin(th) - (m l/2) cos(th) x'' - (m l^2/3) th'' = 0 (unactuated)  (2.47)
    torque = m * ell / 2 * sp.cos(th) * xdd + m * ell**2 / 3 * thdd - m * g * ell / 2 * sp.sin(th)
    assert sp.simplify(eom.tau[0] - force) == 0
    assert sp.simplify(eom.tau[1] - torque) == 0


# --- planar two-link arm: textbook closed form (Spong, Hutchinson & Vidyasagar) -----------------


def planar_2r_closed_form(q, qd, p):
    m1, m2, l1, l2, g = p["m1"], p["m2"], p["l1"], p["l2"], p["g"]
    lc1, lc2 = l1 / 2, l2 / 2
    i1, i2 = m1 * l1**2 / 12, m2 * l2**2 / 12
    c1, c2, c12 = np.cos(q[0]), np.cos(q[1]), np.cos(q[0] + q[1])
    s2 = np.sin(q[1])
    m11 = m1 * lc1**2 + m2 * (l1**2 + lc2**2 + 2 * l1 * lc2 * c2) + i1 + i2
    m12 = m2 * (lc2**2 + l1 * lc2 * c2) + i2
    m22 = m2 * lc2**2 + i2
    h = -m2 * l1 * lc2 * s2
    c = np.array([[h * qd[1], h * (qd[0] + qd[1])], [-h * qd[0], 0.0]])
    gv = np.array([(m1 * lc1 + m2 * l1) * g * c1 + m2 * lc2 * g * c12, m2 * lc2 * g * c12])
    return np.array([[m11, m12], [m12, m22]]), c, gv


@pytest.mark.parametrize("method", METHODS)
def test_planar_2r_matches_textbook_closed_form(method):
    eom = eom_of("planar_2r", method)
    params = dict(eom.robot.parameters)
    f_m, f_c, f_g = (evaluator(eom, x) for x in (eom.M, eom.C, eom.g))
    for q, qd, _ in random_states(2, 10, seed=1):
        m_ref, c_ref, g_ref = planar_2r_closed_form(q, qd, params)
        np.testing.assert_allclose(f_m(q), m_ref, rtol=0, atol=1e-12)
        np.testing.assert_allclose(f_c(q, qd), c_ref, rtol=0, atol=1e-12)
        np.testing.assert_allclose(f_g(q).ravel(), g_ref, rtol=0, atol=1e-12)


# --- agreement of the three formulations on every built-in robot ---------------------------------

SMALL = ("trolley_pendulum", "trolley_double_pendulum", "planar_2r")


@pytest.mark.parametrize("name", SMALL)
def test_formulations_agree_symbolically_on_small_robots(name):
    ref = eom_of(name, "newton_euler")
    for method in ("lagrange", "kane"):
        other = eom_of(name, method)
        for a, b in ((ref.M, other.M), (ref.g, other.g), (ref.tau, other.tau)):
            diff = (a - b).applyfunc(lambda e: sp.simplify(sp.expand_trig(e)))
            assert diff == sp.zeros(*a.shape), f"{name}: newton_euler vs {method}"


# kinova_gen3 (7 joints, general URDF origins) has its own agreement test,
# test_kinova_formulations.py: its expanded equations are too large for lambdify.
ALL = ("trolley_pendulum", "trolley_double_pendulum", "planar_2r", "aa300", "puma560",
       "puma560_akb")
#: The same, the six-joint arms marked slow (13-16 s each: make quick leaves them to the full suite)
ALL_MARKED = tuple(pytest.param(n, marks=pytest.mark.slow) if n.startswith("puma560") else n for n in ALL)


@pytest.mark.parametrize("name", ALL_MARKED)
def test_formulations_agree_numerically(name):
    eoms = [eom_of(name, m) for m in METHODS]
    fns = [(evaluator(e, e.M), evaluator(e, e.g), evaluator(e, e.tau), evaluator(e, e.C))
           for e in eoms]
    n = eoms[0].dof
    for q, qd, qdd in random_states(n, 5, seed=2):
        ref = [fn(q, qd, qdd) for fn in fns[0]]
        for other in fns[1:]:
            for r, f in zip(ref, other, strict=True):
                val = f(q, qd, qdd)
                scale = max(np.abs(r).max(), 1.0)
                np.testing.assert_allclose(val, r, rtol=0, atol=1e-10 * scale)


# --- structural properties -------------------------------------------------------------------


@pytest.mark.parametrize("name", ALL)
def test_regressor_times_parameters_is_tau(name):
    eom = eom_of(name, "newton_euler")
    f_y = evaluator(eom, eom.Y)
    f_p = evaluator(eom, eom.params)
    f_tau = evaluator(eom, eom.tau)
    p = f_p(np.zeros(eom.dof)).ravel()
    assert p.shape == (15 * eom.dof,)
    for q, qd, qdd in random_states(eom.dof, 5, seed=3):
        ref = f_tau(q, qd, qdd).ravel()
        np.testing.assert_allclose(f_y(q, qd, qdd) @ p, ref, rtol=1e-10,
                                   atol=1e-10 * max(1.0, np.abs(ref).max()))


@pytest.mark.parametrize("name", ALL)
def test_mass_matrix_spd_and_mdot_minus_2c_skew(name):
    eom = eom_of(name, "newton_euler")
    f_m, f_c = evaluator(eom, eom.M), evaluator(eom, eom.C)
    # dM/dt = sum_k dM/dq_k qd_k, evaluated symbolically from M itself
    mdot = sum((eom.M.diff(qk) * qdk for qk, qdk in zip(eom.q, eom.qd, strict=True)),
               sp.zeros(eom.dof, eom.dof))
    f_mdot = evaluator(eom, mdot)
    for q, qd, _ in random_states(eom.dof, 5, seed=4):
        m = f_m(q)
        np.testing.assert_allclose(m, m.T, atol=1e-12 * np.abs(m).max())
        assert np.linalg.eigvalsh(m).min() > 0
        n = f_mdot(q, qd) - 2 * f_c(q, qd)
        np.testing.assert_allclose(n, -n.T, atol=1e-10 * max(1.0, np.abs(n).max()))


def test_newton_euler_velocity_terms_equal_c_times_qd():
    """C from Christoffel symbols against NE's own velocity terms (tau with qdd = 0, no gravity)."""
    eom = eom_of("puma560", "newton_euler")
    f_tau, f_g, f_c = evaluator(eom, eom.tau_rigid), evaluator(eom, eom.g), evaluator(eom, eom.C)
    for q, qd, _ in random_states(6, 5, seed=5):
        z = np.zeros(6)
        ref = f_tau(q, qd, z).ravel() - f_g(q).ravel()
        np.testing.assert_allclose(f_c(q, qd) @ qd, ref, atol=1e-10 * max(1, np.abs(ref).max()))


def test_unknown_method_is_rejected():
    with pytest.raises(ValueError, match="unknown method 'hamilton'.*newton_euler, lagrange, kane"):
        rd.derive(rd.load("planar_2r"), method="hamilton")
