"""Integrators: energy conservation, agreement between methods and backends."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd
from robodyn.simulation import LQR, PD, potential_energy, simulate

# a large passive swing: the rods fall from near upright and tumble (chaotic, fast phases)
TROLLEY_Q0 = np.array([0.0, 0.3, -0.2])


def quarter_maxima(err: np.ndarray) -> np.ndarray:
    """Largest |err| in each quarter of the run."""
    return np.array([np.abs(part).max() for part in np.array_split(err, 4)])


def test_potential_energy_gradient_is_the_gravity_load(trolley, aa300, puma):
    rng = np.random.default_rng(0)
    for model in (trolley, aa300, puma):
        q = rng.uniform(-2, 2, (4, model.dof))
        h = 1e-6
        # central differences of V against the compiled g(q)
        grad = np.stack([(potential_energy(model, q + h * e) - potential_energy(model, q - h * e)) / (2 * h)
                         for e in np.eye(model.dof)], axis=1)
        g = model.gravity(q)
        assert np.max(np.abs(grad - g)) <= 1e-6 * max(1.0, np.max(np.abs(g)))
    assert potential_energy(trolley, np.zeros(3)).shape == ()
    assert potential_energy(trolley, np.zeros((5, 3))).shape == (5,)


def test_rk4_conserves_energy_of_passive_double_pendulums(trolley, planar):
    # trolley + double pendulum, no friction: measured relative drift 1.7e-7 over 5 s at 1 ms
    run = simulate(trolley, TROLLEY_Q0, None, 5.0, 1e-3, "rk4")
    assert run.kinetic.max() > 5.0  # it really tumbles (E0 = 4.7 J)
    assert run.energy_drift < 1e-6
    # planar double pendulum: measured 3.4e-10
    run = simulate(planar, np.array([0.3, 0.5]), None, 5.0, 1e-3, "rk4")
    assert run.energy_drift < 1e-8


def test_rk4_energy_error_is_fourth_order(planar):
    drift = [simulate(planar, np.array([0.3, 0.5]), None, 2.0, dt, "rk4").energy_drift
             for dt in (4e-3, 2e-3)]
    # RK4: the error per unit time scales as dt^4 (16x); allow for the chaotic motion
    assert drift[0] / drift[1] > 10.0


def test_semi_implicit_euler_energy_is_bounded_for_a_separable_system(pendulum):
    # one rod: constant M, so H is separable and semi-implicit Euler is symplectic
    run = simulate(pendulum, np.array([0.5]), None, 40.0, 1e-3, "semi_implicit")
    err = run.energy - run.energy[0]
    quarters = quarter_maxima(err)
    # bounded, O(dt), and no secular growth: the last quarter is no worse than the first
    assert quarters.max() / run.kinetic.max() < 5e-3
    assert quarters[-1] <= 1.05 * quarters[0]
    # halving dt halves the oscillation amplitude (first order)
    finer = simulate(pendulum, np.array([0.5]), None, 40.0, 5e-4, "semi_implicit")
    ratio = quarters.max() / np.abs(finer.energy - finer.energy[0]).max()
    assert 1.8 < ratio < 2.2


def test_semi_implicit_euler_on_the_double_pendulum_drifts_at_first_order(planar):
    # M(q) makes H non-separable: the velocity-form update is not symplectic, and the energy error
    # grows with time; it is first order in dt (halving dt halves it)
    errs = []
    for dt in (1e-3, 5e-4):
        run = simulate(planar, np.array([-np.pi / 2 + 0.5, 0.3]), None, 20.0, dt, "semi_implicit")
        errs.append(np.abs(run.energy - run.energy[0]).max() / run.kinetic.max())
    assert errs[0] < 0.05
    assert 1.6 < errs[0] / errs[1] < 2.5


def test_solve_ivp_rk45_agrees_with_c_rk4(trolley):
    # 2 s of tumbling (velocities up to 11 rad/s). Measured against DOP853 at rtol 1e-13: the
    # C RK4's global error is 1.1e-5 at 1 ms, 5.1e-7 at 0.5 ms (ratio 22, 4th order); RK45 at
    # rtol 1e-10 is within 4e-8
    ref = simulate(trolley, TROLLEY_Q0, None, 2.0, 1e-3, "DOP853", rtol=1e-13, atol=1e-13)
    c = simulate(trolley, TROLLEY_Q0, None, 2.0, 1e-3, "rk4")
    ivp = simulate(trolley, TROLLEY_Q0, None, 2.0, 1e-3, "RK45", rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(ivp.t, c.t)
    assert np.max(np.abs(ivp.x - ref.x)) < 1e-6
    assert np.max(np.abs(ivp.x - c.x)) < 5e-5
    half = simulate(trolley, TROLLEY_Q0, None, 2.0, 5e-4, "rk4")
    err_1ms, err_half = np.max(np.abs(c.x - ref.x)), np.max(np.abs(half.x[::2] - ref.x))
    assert err_1ms < 5e-5
    assert err_1ms / err_half > 12.0  # 2^4 = 16
    assert ivp.evaluations > 0


@pytest.mark.parametrize("method", ["DOP853", "Radau", "LSODA"])
def test_other_scipy_methods_run(trolley, method):
    ref = simulate(trolley, TROLLEY_Q0, None, 0.5, 1e-2, "rk4")
    run = simulate(trolley, TROLLEY_Q0, None, 0.5, 1e-2, method, rtol=1e-8, atol=1e-10)
    assert run.method == method
    assert np.max(np.abs(run.q - ref.q)) < 1e-3


def test_numpy_and_c_backends_give_the_same_trajectory(trolley):
    numpy_model = rd.compile_model(trolley.robot, backend="numpy")
    for method in ("rk4", "semi_implicit"):
        a = simulate(trolley, TROLLEY_Q0, None, 1.0, 1e-3, method)
        b = simulate(numpy_model, TROLLEY_Q0, None, 1.0, 1e-3, method)
        assert np.max(np.abs(a.x - b.x)) < 1e-10
        assert np.max(np.abs(a.energy - b.energy)) < 1e-10
    lqr = LQR.about(trolley, np.zeros(3), np.ones(6), 1.0, actuated=[0])
    a = simulate(trolley, np.array([0, 0.1, 0]), None, 1.0, 1e-3, "rk4", lqr)
    b = simulate(numpy_model, np.array([0, 0.1, 0]), None, 1.0, 1e-3, "rk4", lqr)
    assert np.max(np.abs(a.x - b.x)) < 1e-10
    assert np.max(np.abs(a.tau - b.tau)) < 1e-9


def test_trajectory_fields(trolley):
    run = simulate(trolley, TROLLEY_Q0, np.array([0.1, 0, 0]), 0.1, 1e-3, "rk4",
                   PD(1.0, 0.5, np.zeros(3)))
    assert run.t.shape == (101,) and run.q.shape == run.qd.shape == run.qdd.shape == run.tau.shape == (101, 3)
    assert run.energy.shape == (101,)
    np.testing.assert_allclose(run.energy, run.kinetic + run.potential)
    assert (run.method, run.dt, run.controller, run.robot) == ("rk4", 1e-3, "PD", "trolley_double_pendulum")
    with pytest.raises(ValueError):
        run.q[0, 0] = 1.0  # read-only
    # qdd is the forward dynamics at the stored torque
    np.testing.assert_allclose(run.qdd, trolley.forward_dynamics(run.q, run.qd, run.tau), atol=1e-12)
