"""Sampled computed torque on the PUMA 560 exported to URDF (no rotor inertia): a stiff wrist.

The export drops the rotor inertia (URDF has no field for it): joint 6 keeps 4e-5 kg m^2 of link
inertia against 0.216 N m s of viscous friction, a mode of b/m = 5.5e3 1/s in the dynamics under a
held torque. RK4 at 1 ms (|lambda| dt = 5.5 > 2.785) cannot integrate that mode: the sampled run
diverged at t = 0.204 s. The physics does not: the same zero-order-hold loop integrated exactly is
stable (spectral radius of the one-step map 0.998, against 1.08 with one RK4 step).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import robodyn as rd
from robodyn.export.urdf import to_urdf
from robodyn.robot.errors import SimulationError
from robodyn.simulation import ComputedTorque, quintic, simulate

Q1 = np.array([0.8, -0.6, 0.9, 0.5, -0.7, 1.0])
KP, KD = 100.0, 20.0


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        path = tmp_path_factory.mktemp("urdf") / "puma560.urdf"
        path.write_text(to_urdf(rd.load("puma560")))
        return rd.compile_model(rd.load(path))


@pytest.fixture(scope="module")
def plan():
    return quintic(np.zeros(6), Q1, 1.0, dt=1e-3)


def test_the_sampled_run_names_the_stiff_mode_and_the_fix(exported, plan):
    wrist = exported.robot.joint_names[5]
    with pytest.raises(SimulationError) as info:
        simulate(exported, np.zeros(6), None, 1.0, 1e-3, "rk4", ComputedTorque(plan, KP, KD))
    msg = str(info.value)
    assert "step 204 (t = 0.204 s)" in msg
    assert f"mostly joint '{wrist}'" in msg and "numerical, not a physical" in msg
    # |lambda| = b6 / m6 = 0.2158 / 4e-5 = 5.4e3 1/s (the linearisation: 5.5e3 1/s)
    rate = float(msg.split("mode of ")[1].split(" 1/s")[0])
    assert 5.0e3 < rate < 6.0e3
    assert "substeps >= 6" in msg and "control='continuous'" in msg


def _one_step_map(model, step, x0):
    """Jacobian of x_k -> x_k+1 of the sampled loop regulating to rest (central differences)."""
    n = model.dof

    def law(x):
        # tau = M(q) (-Kp q - Kd qd) + h(q, qd)
        return model.mass_matrix(x[:n]) @ (-KP * x[:n] - KD * x[n:]) + model.inverse_dynamics(
            x[:n], x[n:], np.zeros(n))

    jac = np.empty((2 * n, 2 * n))
    for i in range(2 * n):
        e = np.zeros(2 * n)
        e[i] = 1e-7
        jac[:, i] = (step(x0 + e, law(x0 + e)) - step(x0 - e, law(x0 - e))) / 2e-7
    return jac


@pytest.mark.slow
def test_the_zero_order_hold_loop_is_stable_and_one_rk4_step_is_not(exported):
    dt, n = 1e-3, exported.dof
    x0 = np.concatenate([[0.1, -0.1, 0.1, 0.1, -0.1, 0.1], np.zeros(n)])

    def rk4(x, tau):
        return rd.rollout(exported, x, rd.RolloutOptions(1, dt), rd.FeedbackLaw(feedforward=tau[None]))[0][-1]

    def exact(x, tau):
        sol = solve_ivp(lambda t, y: exported.state_derivative(y, tau), (0.0, dt), x,
                        method="Radau", rtol=1e-12, atol=1e-14)
        return sol.y[:, -1]

    radius = {name: np.abs(np.linalg.eigvals(_one_step_map(exported, step, x0))).max()
              for name, step in (("rk4", rk4), ("exact", exact))}
    # measured: 1.079 (RK4) and 0.9982 (exact)
    assert radius["rk4"] > 1.05
    assert radius["exact"] < 0.999


def test_substeps_integrate_the_held_torque_and_track_as_the_physics_allows(exported, plan):
    runs = {k: simulate(exported, np.zeros(6), None, 1.0, 1e-3, "rk4", ComputedTorque(plan, KP, KD),
                        substeps=k) for k in (8, 16)}
    err = {k: np.abs(r.q - plan.at(r.t)[0]).max(axis=0) for k, r in runs.items()}
    # converged in the substeps: the exact zero-order-hold response
    assert np.abs(runs[8].q - runs[16].q).max() < 1e-3 * err[16].max()
    # the arm joints track to 0.1-0.5 mrad; the wrist's time constant m6/b6 = 0.19 ms is shorter
    # than the 1 ms hold, so a torque computed for a constant acceleration over the step moves it
    # about m6 / (b6 dt) = 0.19 of the way: 0.19 rad behind (measured 0.185; 1.3e-2 at 10 kHz)
    assert np.all(err[16][:3] < 1e-3)
    assert 0.1 < err[16][5] < 0.3
    # the continuous-time law cancels the friction at every stage: RK4's error only
    cont = simulate(exported, np.zeros(6), None, 1.0, 1e-3, "rk4", ComputedTorque(plan, KP, KD),
                    control="continuous")
    assert np.abs(cont.q - plan.at(cont.t)[0]).max() < 1e-9
