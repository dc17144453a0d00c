"""Ensemble simulation: N trajectories in one C call equal N separate simulations.

The ensemble integrates a block of trajectories per vector loop (one ``state_derivative`` over
the block per RK4 stage); each trajectory must come out as its own ``integrate`` call gives it
(to 1e-12, and in fact bit for bit, since a state's arithmetic does not depend on its lane),
for any number of threads, and the NumPy backend's ensemble must agree with the C one.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

import robodyn as rd
from robodyn.robot.errors import SimulationError


@pytest.fixture(scope="module")
def trolley():
    return rd.compile_model(rd.load("trolley_double_pendulum"))


@pytest.fixture(scope="module")
def puma():
    return rd.compile_model(rd.load("puma560"))


def _x0(model, count, seed=0):
    rng = np.random.default_rng(seed)
    n = model.dof
    return np.hstack([rng.uniform(-1.0, 1.0, (count, n)), rng.uniform(-0.5, 0.5, (count, n))])


def _close(a, b):
    scale = max(float(np.max(np.abs(b))), 1e-300)
    return float(np.max(np.abs(a - b))) <= 1e-12 * scale


@pytest.mark.tool("gcc|cc")
@pytest.mark.parametrize("method", ["rk4", "semi_implicit"])
@pytest.mark.parametrize("count", [1, 7, 16, 17, 37])
def test_passive_ensemble_equals_separate_runs(trolley, method, count):
    x0 = _x0(trolley, count, seed=count)
    options = rd.RolloutOptions(400, 1e-3, method)
    xs, taus = rd.rollout(trolley, x0, options)
    assert xs.shape == (count, 401, 2 * trolley.dof) and taus.shape == (count, 400, trolley.dof)
    for i in range(count):
        x1, tau1 = rd.rollout(trolley, x0[i], options)
        assert _close(xs[i], x1) and _close(taus[i], tau1)
        np.testing.assert_array_equal(xs[i], x1)  # the same bits, not only close


@pytest.mark.tool("gcc|cc")
@pytest.mark.parametrize("mode", ["feedback", "gravity", "computed_torque"])
def test_controlled_ensemble_equals_separate_runs_on_any_thread_count(puma, mode):
    n, steps, dt = puma.dof, 300, 1e-3
    t = dt * np.arange(steps)
    reference = np.hstack([0.3 * np.sin(np.outer(t, np.arange(1, n + 1))),
                           0.3 * np.cos(np.outer(t, np.arange(1, n + 1))) * np.arange(1, n + 1)])
    law = rd.FeedbackLaw(mode, reference=reference, gain=np.hstack([np.diag(np.full(n, 400.0)),
                                                                    np.diag(np.full(n, 40.0))]),
                         feedforward=np.full((steps, n), 0.1), integral_gain=np.full(n, 5.0))
    options = rd.RolloutOptions(steps, dt, tau_limit=np.full(n, 150.0))
    x0 = _x0(puma, 21, seed=4)
    xs, taus = rd.rollout(puma, x0, options, law)
    for i in range(len(x0)):
        x1, tau1 = rd.rollout(puma, x0[i], options, law)
        assert _close(xs[i], x1) and _close(taus[i], tau1)
    xs2, taus2 = rd.rollout(puma, x0, replace(options, threads=2), law)
    np.testing.assert_array_equal(xs2, xs)
    np.testing.assert_array_equal(taus2, taus)


def test_numpy_backend_ensemble_agrees_with_c():
    robot = rd.load("trolley_double_pendulum")
    c_model, np_model = rd.compile_model(robot), rd.compile_model(robot, backend="numpy")
    x0 = _x0(c_model, 3, seed=9)
    xs_np, _ = rd.rollout(np_model, x0, rd.RolloutOptions(50, 1e-3))
    xs_c, _ = rd.rollout(c_model, x0, rd.RolloutOptions(50, 1e-3))
    assert _close(xs_c, xs_np)


def test_ensemble_bad_input_and_failed_trajectory(trolley):
    x0 = _x0(trolley, 4)
    with pytest.raises(ValueError, match=r"x0 must have shape \(4, 6\)"):
        rd.rollout(trolley, x0[:, :5], rd.RolloutOptions(10, 1e-3))
    with pytest.raises(ValueError, match="sampled"):
        rd.rollout(trolley, x0, rd.RolloutOptions(10, 1e-3, control="continuous"))
    before = x0.copy()
    bad = x0.copy()
    bad[2, 3:] = 1e200  # velocities that overflow in the first steps
    with pytest.raises(SimulationError, match="1 of 4 trajectories.*trajectory 2") as info:
        rd.rollout(trolley, bad, rd.RolloutOptions(10, 1e-3))
    assert info.value.trajectory == 2
    rd.rollout(trolley, x0, rd.RolloutOptions(10, 1e-3))
    np.testing.assert_array_equal(x0, before)
