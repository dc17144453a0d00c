"""The one description of the fixed-step schemes and the sampled law (robodyn.codegen.fixed_step),
checked against closed forms and against the generated C that is emitted from it."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import expm

import robodyn as rd
from robodyn.codegen.c_simulation import simulation_source
from robodyn.codegen.fixed_step import RK4, law, semi_implicit_step
from robodyn.simulation import LQR, PD, PID, ComputedTorque, GravityCompensation, quintic


def _classical_rk4(f, x, h):
    """Classical RK4 written out (Kutta 1901), independent of the tableau."""
    k1 = f(x)
    k2 = f(x + 0.5 * h * k1)
    k3 = f(x + 0.5 * h * k2)
    k4 = f(x + h * k3)
    return x + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)


def test_rk4_tableau_step_is_classical_rk4():
    rng = np.random.default_rng(0)
    a = rng.normal(size=(4, 4))

    def f(x):
        return np.sin(a @ x) - 0.3 * x

    x = rng.normal(size=4)
    got = RK4.step((x,), 0.05, lambda i, s: (f(s[0]),))[0]
    np.testing.assert_allclose(got, _classical_rk4(f, x, 0.05), rtol=1e-15, atol=1e-15)
    assert RK4.stages == 4 and sum(RK4.weights) == RK4.denominator  # weights sum to 1


def test_rk4_local_error_is_fifth_order_on_a_linear_system():
    a = np.array([[0.0, 1.0], [-4.0, -0.4]])
    x = np.array([1.0, -0.5])
    errs = []
    for h in (0.04, 0.02):
        step = RK4.step((x,), h, lambda i, s: (a @ s[0],))[0]
        errs.append(np.linalg.norm(step - expm(a * h) @ x))
    # local error O(h^5): halving h divides it by about 2^5
    assert 25.0 < errs[0] / errs[1] < 40.0


def test_stage_rows_sample_the_right_times():
    seen = []
    RK4.step((np.zeros(1),), 1.0, lambda i, s: (seen.append(RK4.rows[i]) or np.zeros(1),))
    assert seen == [0, 1, 1, 2]  # t, t + h/2, t + h/2, t + h in half steps


def test_semi_implicit_euler_uses_the_new_velocity():
    x = np.array([1.0, 2.0, 0.5, -1.0])
    got = semi_implicit_step(x, 0.1, np.array([3.0, 4.0]))
    qd = np.array([0.5 + 0.3, -1.0 + 0.4])
    np.testing.assert_allclose(got, np.concatenate([[1.0, 2.0] + 0.1 * qd, qd]), rtol=1e-15)


def test_law_modes_are_their_closed_forms(planar):
    rng = np.random.default_rng(1)
    x, z = rng.normal(size=4), rng.normal(size=2)
    inputs = {"feedforward": rng.normal(size=(3, 2)), "reference": rng.normal(size=(3, 4)),
              "gain": rng.normal(size=(2, 4)), "integral_gain": rng.normal(size=2), "tau_limit": None}
    q, qd = x[:2], x[2:]
    terms = {"mass_matrix": planar.mass_matrix(q), "gravity": planar.gravity(q),
             "bias": planar.inverse_dynamics(q, qd, np.zeros(2))}
    v = inputs["feedforward"][1] + inputs["gain"] @ (inputs["reference"][1] - x) + inputs["integral_gain"] * z
    expected = {0: v, 1: v + terms["gravity"], 2: terms["mass_matrix"] @ v + terms["bias"]}
    for mode, want in expected.items():
        got = law(inputs, 1, x, z, mode, lambda name, q_, qd_: terms[name])
        np.testing.assert_allclose(got, want, rtol=1e-13, atol=1e-13)
    limited = law({**inputs, "tau_limit": np.array([0.1, 0.2])}, 1, x, z, 0, None)
    np.testing.assert_allclose(limited, np.clip(v, [-0.1, -0.2], [0.1, 0.2]))


def test_generated_c_carries_the_tableau():
    src = simulation_source(2, "rd_", True, True)
    # every stage step and the weighted sum, in the text the tableau gives
    for a_text in ("0.5 * dt * k1[i]", "0.5 * dt * k2[i]", "dt * k3[i]"):
        assert a_text in src
    assert "dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])" in src
    assert "dt / 6.0 * (r1[i] + 2.0 * r2[i] + 2.0 * r3[i] + r4[i])" in src


def _controllers(planar):
    traj = quintic(np.array([-0.4, 0.2]), np.array([0.5, 0.3]), 1.0)
    lqr = LQR(np.array([[3.0, 0.5, 1.0, 0.2], [0.4, 2.0, 0.1, 0.7]]), np.array([0.3, -0.2, 0.0, 0.0]),
              np.array([1.5, -0.5]))
    return [PD(20.0, 4.0, np.array([0.5, 0.3])), PID(20.0, 5.0, 4.0, traj),
            GravityCompensation(np.array([30.0, 10.0]), 3.0, traj),
            ComputedTorque(traj, 100.0, 20.0), lqr]


@pytest.mark.tool("gcc|cc")
def test_each_controller_law_equals_the_generated_c_law(planar):
    """Controller.law (the NumPy description) against the torque the generated C integrator
    applies at its first step from the controller's sampled inputs."""
    x0 = np.array([-0.3, 0.1, 0.2, -0.4])
    t = np.array([0.25])
    for ctrl in _controllers(planar):
        _, tau = rd.rollout(planar, x0, rd.RolloutOptions(1, 0.01, "rk4"), ctrl.sampled(planar, t))
        z = 0.01 * ctrl.position_error(0.25, x0[:2]) if ctrl.has_integral else None
        got = ctrl.law(planar, 0.25, x0, z)
        np.testing.assert_allclose(got, tau[0], rtol=1e-12, atol=1e-12, err_msg=ctrl.name)
