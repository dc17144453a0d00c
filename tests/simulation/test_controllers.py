"""Built-in controllers: set-point convergence, computed-torque tracking, LQR, callables."""

from __future__ import annotations

import numpy as np
import pytest

from robodyn.simulation import (
    LQR,
    PD,
    PID,
    ComputedTorque,
    GravityCompensation,
    linearize,
    quintic,
    simulate,
)
from robodyn.studies.balance import balance_double_pendulum

Q_REF = np.array([0.5, 0.3])
Q_START = np.array([-1.0, 0.5])
PUMA_Q0 = np.array([0.0, np.pi / 4, -np.pi / 2, 0.0, 0.3, 0.0])
PUMA_Q1 = PUMA_Q0 + np.array([0.8, -0.5, 0.6, 1.0, -0.7, 1.2])


@pytest.mark.parametrize("method", ["rk4", "RK45"])
def test_pd_settles_where_the_spring_holds_gravity(planar, method):
    run = simulate(planar, Q_START, None, 10.0, 1e-3, method, PD(200.0, 40.0, Q_REF))
    q = run.q[-1]
    # PD alone sags: the equilibrium solves Kp (q_ref - q) = g(q) (0.086 rad off here)
    assert np.abs(q - Q_REF).max() > 0.05
    assert np.abs(200.0 * (Q_REF - q) - planar.gravity(q)).max() < 1e-8
    assert np.abs(run.qd[-1]).max() < 1e-8


@pytest.mark.parametrize("method", ["rk4", pytest.param("RK45", marks=pytest.mark.slow)])
def test_pid_and_gravity_compensation_reach_the_set_point(planar, method):
    for ctrl in (PID(200.0, 300.0, 40.0, Q_REF), GravityCompensation(200.0, 40.0, Q_REF)):
        run = simulate(planar, Q_START, None, 10.0, 1e-3, method, ctrl)
        # measured: 2e-11 (PID), 5e-15 (gravity compensation)
        assert np.abs(run.q[-1] - Q_REF).max() < 1e-9, ctrl.name
        assert np.abs(run.qd[-1]).max() < 1e-9


def test_computed_torque_tracks_a_quintic_of_the_puma(puma_rigid):
    # the sampled law (torque held over each step, as a digital controller) makes the open-loop
    # (Kp = Kd = 0) error first order in dt: measured 4.5e-3, 2.3e-3, 1.1e-3 rad at 4, 2, 1 ms
    errors = []
    for dt in (4e-3, 2e-3, 1e-3):
        plan = quintic(PUMA_Q0, PUMA_Q1, 1.0, dt=dt)
        run = simulate(puma_rigid, PUMA_Q0, None, 1.0, dt, "rk4", ComputedTorque(plan, 0.0, 0.0))
        errors.append(np.abs(run.q - plan.q).max())
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    assert np.all((ratios > 1.8) & (ratios < 2.2)), errors
    # feedback shrinks it (measured 4.4e-5 rad at 1 ms with Kp = 400, Kd = 40)
    plan = quintic(PUMA_Q0, PUMA_Q1, 1.0, dt=1e-3)
    run = simulate(puma_rigid, PUMA_Q0, None, 1.0, 1e-3, "rk4", ComputedTorque(plan, 400.0, 40.0))
    assert np.abs(run.q - plan.q).max() < 1e-4
    # evaluated continuously, the law tracks to integration accuracy (measured 5e-11 rad)
    run = simulate(puma_rigid, PUMA_Q0, None, 1.0, 1e-3, "DOP853", ComputedTorque(plan, 0.0, 0.0),
                   rtol=1e-11, atol=1e-12)
    assert np.abs(run.q - plan.q).max() < 1e-8
    # and its torque is the inverse dynamics of the plan
    np.testing.assert_allclose(run.tau, puma_rigid.inverse_dynamics(plan.q, plan.qd, plan.qdd),
                               atol=1e-6 * np.abs(run.tau).max())


def test_continuous_computed_torque_in_c_tracks_to_fourth_order(puma):
    # the law evaluated at every RK4 stage, in C, on the full PUMA (rotor inertia and Coulomb
    # friction, which the law cancels exactly): the open-loop error is RK4's own, falling ~16x
    # per halving of dt (measured 1.8e-9, 1.1e-10, 6.7e-12 rad at 4, 2, 1 ms over 2 s)
    errors = []
    for dt in (4e-3, 2e-3, 1e-3):
        plan = quintic(PUMA_Q0, PUMA_Q1, 1.0, dt=dt)
        run = simulate(puma, PUMA_Q0, None, 1.0, dt, "rk4", ComputedTorque(plan, 0.0, 0.0),
                       control="continuous")
        errors.append(np.abs(run.q - plan.q).max())
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    assert np.all((ratios > 12) & (ratios < 20)), errors
    assert errors[-1] < 1e-10
    # tau[k] is the law at the start of step k: the inverse dynamics of the plan (away from
    # qd = 0, where Coulomb friction switches on a 1e-12 rad/s velocity difference)
    moving = np.abs(plan.qd) > 1e-6
    ref = puma.inverse_dynamics(plan.q, plan.qd, plan.qdd)
    np.testing.assert_allclose(run.tau[moving], ref[moving], atol=1e-7 * np.abs(run.tau).max())


def test_continuous_control_agrees_between_c_numpy_and_a_callable(planar):
    import dataclasses

    import robodyn as rd

    twin = rd.compile_model(planar.robot, backend="numpy")
    pid = PID(np.array([150.0, 80.0]), np.array([60.0, 20.0]), np.array([30.0, 12.0]),
              quintic(Q_START, Q_REF, 0.6, dt=1e-3))
    a = simulate(planar, Q_START, None, 1.0, 2e-3, "rk4", pid, control="continuous")
    b = simulate(twin, Q_START, None, 1.0, 2e-3, "rk4", pid, control="continuous")
    assert np.max(np.abs(a.x - b.x)) < 1e-12
    # the error integral is extra RK4 state: against SciPy integrating the same ODE tightly, the
    # error is fourth order (measured 3.0e-5, 1.6e-6, 9.4e-8 at 4, 2, 1 ms; sampled: 3e-2, 8e-3)
    c = simulate(planar, Q_START, None, 1.0, 1e-3, "DOP853", pid, rtol=1e-13, atol=1e-14)
    errors = []
    for dt in (4e-3, 2e-3, 1e-3):
        run = simulate(planar, Q_START, None, 1.0, dt, "rk4", pid, control="continuous")
        errors.append(np.abs(run.x - c.x[:: int(round(dt / 1e-3))]).max())
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    assert np.all((ratios > 12) & (ratios < 22)), errors
    pd = PD(150.0, 30.0, Q_REF)
    law = dataclasses.replace(pd)
    d = simulate(planar, Q_START, None, 1.0, 2e-3, "rk4", pd, control="continuous")
    e = simulate(planar, Q_START, None, 1.0, 2e-3, "rk4", lambda t, q, qd: law(t, q, qd),
                 control="continuous")
    assert np.max(np.abs(d.x - e.x)) < 1e-12
    with pytest.raises(ValueError, match="needs method='rk4'"):
        simulate(planar, Q_START, None, 1.0, 2e-3, "semi_implicit", pd, control="continuous")
    with pytest.raises(ValueError, match="unknown control"):
        simulate(planar, Q_START, None, 1.0, 2e-3, "rk4", pd, control="zoh")


def test_python_callable_equals_the_builtin_controller(planar):
    pd = PD(np.array([150.0, 80.0]), np.array([30.0, 12.0]), Q_REF)

    def law(t, q, qd):
        return np.array([150.0, 80.0]) * (Q_REF - q) - np.array([30.0, 12.0]) * qd

    for method in ("rk4", "semi_implicit", "RK45"):
        a = simulate(planar, Q_START, None, 2.0, 1e-3, method, pd)
        b = simulate(planar, Q_START, None, 2.0, 1e-3, method, law)
        assert np.max(np.abs(a.x - b.x)) < 1e-10, method
        assert np.max(np.abs(a.tau - b.tau)) < 1e-8, method
    assert b.controller == "law"
    # a built-in controller called directly is the same law
    gc = GravityCompensation(150.0, 30.0, Q_REF, model=planar)
    a = simulate(planar, Q_START, None, 1.0, 1e-3, "rk4", GravityCompensation(150.0, 30.0, Q_REF))
    b = simulate(planar, Q_START, None, 1.0, 1e-3, "rk4", lambda t, q, qd: gc(t, q, qd))
    assert np.max(np.abs(a.x - b.x)) < 1e-10


def test_torque_limits_are_respected(planar):
    run = simulate(planar, Q_START, None, 2.0, 1e-3, "rk4", GravityCompensation(500.0, 50.0, Q_REF),
                   tau_limit=np.array([20.0, 8.0]))
    assert np.all(np.abs(run.tau) <= np.array([20.0, 8.0]) + 1e-12)
    assert np.any(np.abs(run.tau[:, 0]) == 20.0)  # it saturates
    ctrl = PD(500.0, 50.0, Q_REF, tau_limit=5.0)
    for method in ("rk4", "RK45"):
        run = simulate(planar, Q_START, None, 0.5, 1e-3, method, ctrl)
        assert np.all(np.abs(run.tau) <= 5.0 + 1e-12)


def test_linearisation_matches_finite_differences(trolley, puma):
    rng = np.random.default_rng(3)
    for model in (trolley, puma):
        n = model.dof
        q, qd, u = rng.uniform(-1, 1, (3, n))
        lin = linearize(model, q, qd, u)
        x0, h = np.concatenate([q, qd]), 1e-6
        f = model.state_derivative
        a = np.stack([(f(x0 + h * e, u) - f(x0 - h * e, u)) / (2 * h) for e in np.eye(2 * n)], axis=1)
        b = np.stack([(f(x0, u + h * e) - f(x0, u - h * e)) / (2 * h) for e in np.eye(n)], axis=1)
        assert np.abs(lin.A - a).max() < 1e-6 * np.abs(a).max()
        assert np.abs(lin.B - b).max() < 1e-6 * np.abs(b).max()
    assert linearize(trolley, np.zeros(3)).is_equilibrium


def test_lqr_balances_the_trolley_double_inverted_pendulum(trolley, tmp_path):
    q_w = np.diag([10.0, 100.0, 100.0, 1.0, 10.0, 10.0])
    lqr = LQR.about(trolley, np.zeros(3), q_w, 1.0, actuated=[0])
    # Riccati residual A^T P + P A - P B R^-1 B^T P + Q = 0 (R = 1), relative to its largest term,
    # P symmetric positive definite, K = R^-1 B^T P on the actuated joint, stable closed loop
    lin, p = lqr.linearization, lqr.P
    b = lin.B[:, [0]]
    terms = (lin.A.T @ p, p @ lin.A, p @ b @ b.T @ p, q_w)
    residual = terms[0] + terms[1] - terms[2] + terms[3]
    assert np.abs(residual).max() < 1e-9 * max(np.abs(term).max() for term in terms)
    np.testing.assert_allclose(p, p.T, rtol=0, atol=1e-12 * np.abs(p).max())
    assert np.linalg.eigvalsh(p).min() > 0
    np.testing.assert_allclose(lqr.K[0], (b.T @ p).ravel(), rtol=1e-12, atol=0)
    assert np.all(lqr.closed_loop_poles.real < 0)
    assert np.all(lqr.K[1:] == 0)  # only the trolley pushes
    # perturbed start: rod 1 tilted 0.1 rad, rod 2 bent back 0.05 rad
    res = balance_double_pendulum(trolley, (0.0, 0.1, -0.05), figure=tmp_path / "balance.png")
    assert res.upright
    assert res.final_tilt < 1e-3  # measured 7.1e-4 rad after 5 s
    assert abs(res.final_position) < 0.01
    assert np.all(res.simulation.tau[:, 1:] == 0)
    assert res.figure is not None and res.figure.stat().st_size > 0
    # without control it falls
    fall = simulate(trolley, np.array([0.0, 0.1, -0.05]), None, 2.0, 1e-3, "rk4")
    assert np.abs(fall.q[:, 1]).max() > 1.0
    # a force limit too small to recover loses it
    assert not balance_double_pendulum(trolley, (0.0, 0.3, 0.0), tau_limit=3.0).upright


def test_pid_callable_accumulates_its_integral(planar):
    pid = PID(200.0, 300.0, 40.0, Q_REF)
    run = simulate(planar, Q_START, None, 10.0, 1e-3, "rk4", lambda t, q, qd: pid(t, q, qd))
    assert np.abs(run.q[-1] - Q_REF).max() < 1e-6
    builtin = simulate(planar, Q_START, None, 10.0, 1e-3, "rk4", PID(200.0, 300.0, 40.0, Q_REF))
    # the callable sums e_k (t_k - t_k-1), the C loop e_k dt from k = 0: the same limit
    assert np.abs(run.q - builtin.q).max() < 0.01
    pid.reset()
    np.testing.assert_allclose(pid(0.0, Q_REF, np.zeros(2)), 0.0)
