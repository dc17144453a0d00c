"""Runtime parameters: a batch of parameter sets in one call equals models compiled with each set.

``compile_model(robot, runtime_parameters=...)`` keeps named parameters as kernel inputs. The
reference for every check is independent of that code path: a separate model compiled with the
values folded in as constants (a different generated program), one per parameter set.
"""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd
from robodyn.robot.errors import DescriptionError
from robodyn.simulation.controllers import ComputedTorque, GravityCompensation

pytestmark = pytest.mark.tool("gcc|cc")

ROBOT = "trolley_double_pendulum"  # parameters M (trolley mass: also the name of an output), m1, ...
SETS = np.array([[1.0, 0.5, 0.5, 0.5, 0.5, 9.81],
                 [2.5, 0.3, 0.9, 0.7, 0.4, 9.81],
                 [0.7, 1.2, 0.2, 0.3, 0.8, 3.71]])


@pytest.fixture(scope="module")
def robot():
    return rd.load(ROBOT)


@pytest.fixture(scope="module")
def runtime(robot):
    return rd.compile_model(robot, runtime_parameters=True)


@pytest.fixture(scope="module")
def folded(robot, runtime):
    """One model per parameter set, compiled with the values as constants (the reference)."""
    return [rd.compile_model(robot, parameters=dict(zip(runtime.runtime_parameters, row, strict=True)))
            for row in SETS]


def _close(a, b, rtol=1e-12):
    scale = max(float(np.max(np.abs(b))), 1e-300)
    return float(np.max(np.abs(np.asarray(a) - np.asarray(b)))) <= rtol * scale


def _states(n, count, seed=0):
    rng = np.random.default_rng(seed)
    return rng.uniform(-1, 1, (count, n)), rng.uniform(-1, 1, (count, n)), rng.uniform(-2, 2, (count, n))


def test_names_in_description_order(robot, runtime):
    assert runtime.runtime_parameters == tuple(robot.parameters)
    assert runtime.runtime_parameters[0] == "M"


@pytest.mark.parametrize("count", [1, 7, 16, 17])
def test_kernels_per_state_parameters_equal_folded_models(runtime, folded, count):
    n = runtime.dof
    q, qd, qdd = _states(n, count)
    which = np.arange(count) % len(SETS)
    p = SETS[which]
    tau = runtime.inverse_dynamics(q, qd, qdd, parameters=p)
    mass = runtime.mass_matrix(q, parameters=p)
    qddf = runtime.forward_dynamics(q, qd, tau, parameters=p)
    grav = runtime.gravity(q, parameters=p)
    reg = runtime.regressor(q, qd, qdd, parameters=p)
    for k in range(count):
        ref = folded[which[k]]
        assert _close(tau[k], ref.inverse_dynamics(q[k], qd[k], qdd[k]))
        assert _close(mass[k], ref.mass_matrix(q[k]))
        assert _close(qddf[k], ref.forward_dynamics(q[k], qd[k], tau[k]))
        assert _close(grav[k], ref.gravity(q[k]))
        assert _close(reg[k], ref.regressor(q[k], qd[k], qdd[k]))
    # forward dynamics inverts the inverse dynamics with each state's own parameters
    assert _close(qddf, qdd, 1e-10)


def test_threads_give_the_same_bits(runtime):
    q, qd, qdd = _states(runtime.dof, 103, seed=3)
    p = SETS[np.arange(103) % 3]
    one = runtime.inverse_dynamics(q, qd, qdd, parameters=p)
    two = runtime.inverse_dynamics(q, qd, qdd, parameters=p, threads=2)
    assert np.array_equal(one, two)


def test_one_set_mapping_and_defaults(robot, runtime, folded):
    q, qd, qdd = _states(runtime.dof, 5, seed=1)
    values = dict(zip(runtime.runtime_parameters, SETS[1], strict=True))
    assert _close(runtime.inverse_dynamics(q, qd, qdd, parameters=values),
                  folded[1].inverse_dynamics(q, qd, qdd))
    assert _close(runtime.with_parameters(values).inverse_dynamics(q, qd, qdd),
                  folded[1].inverse_dynamics(q, qd, qdd))
    # partial mapping: the others keep their defaults (SETS[0] are the description's defaults)
    assert runtime.parameters == dict(zip(runtime.runtime_parameters, SETS[0], strict=True))
    assert _close(runtime.inverse_dynamics(q, qd, qdd), folded[0].inverse_dynamics(q, qd, qdd))
    part = runtime.inverse_dynamics(q, qd, qdd, parameters={"M": 2.5})
    assert not _close(part, folded[0].inverse_dynamics(q, qd, qdd))
    rows = [values] * 5
    assert _close(runtime.inverse_dynamics(q, qd, qdd, parameters=rows),
                  folded[1].inverse_dynamics(q, qd, qdd))


@pytest.mark.parametrize("method", ["rk4", "semi_implicit"])
def test_ensemble_with_parameter_sets_equals_separate_models(runtime, folded, method):
    count, n = 20, runtime.dof
    q, qd, _ = _states(n, count, seed=2)
    x0 = np.hstack([q, 0.3 * qd])
    which = np.arange(count) % 3
    gain = np.hstack([np.diag([-5.0, 40.0, 40.0]), np.diag([-2.0, 5.0, 5.0])])
    law = rd.FeedbackLaw("gravity", gain=gain)
    xs, taus = rd.rollout(runtime, x0, rd.RolloutOptions(300, 1e-3, method, threads=2), law,
                          SETS[which])
    for k in range(count):
        # a model-based law (gravity compensation) with each trajectory's own parameters
        x_ref, tau_ref = rd.rollout(folded[which[k]], x0[k], rd.RolloutOptions(300, 1e-3, method), law)
        assert _close(xs[k], x_ref)
        assert _close(taus[k], tau_ref)


def test_numpy_backend_ensemble_matches_c(robot, runtime):
    numpy_model = rd.compile_model(robot, "numpy", runtime_parameters=True)
    x0 = np.hstack(_states(runtime.dof, 4, seed=5)[:2])
    p = SETS[[0, 1, 2, 1]]
    x_c, _ = rd.rollout(runtime, x0, rd.RolloutOptions(40, 1e-3), parameters=p)
    x_np, _ = rd.rollout(numpy_model, x0, rd.RolloutOptions(40, 1e-3), parameters=p)
    assert _close(x_np, x_c)


def test_simulate_batch_with_parameters_equals_single_runs(runtime, folded):
    count = 6
    rng = np.random.default_rng(4)
    q0 = rng.uniform(-0.5, 0.5, (count, runtime.dof))
    which = np.arange(count) % 3
    ctrl = ComputedTorque(np.zeros(runtime.dof), kp=25.0, kd=10.0)
    run = rd.simulate(runtime, q0, None, 0.4, 1e-3, controller=ctrl, parameters=SETS[which])
    for k in range(count):
        ref = rd.simulate(folded[which[k]], q0[k], None, 0.4, 1e-3, controller=ctrl)
        for name in ("q", "qd", "qdd", "tau", "kinetic", "potential"):
            assert _close(getattr(run, name)[k], getattr(ref, name)), name
    # a single run with one set
    hold = GravityCompensation(kp=20.0, kd=5.0, q_ref=np.zeros(3))
    one = rd.simulate(runtime, q0[1], None, 0.4, 1e-3, controller=hold, parameters=SETS[1])
    ref = rd.simulate(folded[1], q0[1], None, 0.4, 1e-3, controller=hold)
    assert _close(one.q, ref.q)


def test_bad_parameter_input_is_named(robot, runtime):
    q = np.zeros((4, runtime.dof))
    with pytest.raises(ValueError, match=r"'mass' is not a runtime parameter"):
        runtime.gravity(q, parameters={"mass": 1.0})
    with pytest.raises(ValueError, match=r"shape \(6,\) or \(N, 6\)"):
        runtime.gravity(q, parameters=np.ones((4, 5)))
    with pytest.raises(ValueError, match="3 parameter sets for a batch of 4"):
        runtime.gravity(q, parameters=SETS)
    bad = np.tile(SETS[0], (4, 1))
    bad[2, 2] = np.nan
    with pytest.raises(ValueError, match=r"parameter 'm2' is not finite \(nan\) in row 2"):
        runtime.gravity(q, parameters=bad)
    negative = np.tile(SETS[0], (2, 1))
    negative[1, 1] = -1.0
    with pytest.raises(DescriptionError, match="row 1"):
        rd.rollout(runtime, np.zeros((2, 2 * runtime.dof)), rd.RolloutOptions(5, 1e-3), parameters=negative)
    # one bad set among many (the vectorised screen finds it, the description's check names it)
    many = np.tile(SETS[1], (100, 1))
    many[57, 2] = -0.1
    with pytest.raises(DescriptionError, match=r"row 57.*mass of link .* is negative"):
        rd.rollout(runtime, np.zeros((100, 2 * runtime.dof)), rd.RolloutOptions(5, 1e-3), parameters=many)
    folded_model = rd.compile_model(robot)
    with pytest.raises(ValueError, match="compiled with runtime parameters"):
        folded_model.gravity(q, parameters={"M": 1.0})
    with pytest.raises(ValueError, match="no parameter"):
        rd.compile_model(robot, runtime_parameters=["M", "rho"])
    with pytest.raises(ValueError, match="declares no named parameters"):
        rd.compile_model(rd.load("puma560"), runtime_parameters=True)


def test_user_input_not_modified(runtime):
    p = SETS[np.arange(5) % 3].copy()
    before = p.copy()
    q, qd, qdd = _states(runtime.dof, 5)
    runtime.inverse_dynamics(q, qd, qdd, parameters=p)
    rd.rollout(runtime, np.hstack([q, qd]), rd.RolloutOptions(3, 1e-3), parameters=p)
    assert np.array_equal(p, before)
