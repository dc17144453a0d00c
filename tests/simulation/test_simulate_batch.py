"""``simulate`` on a batch of initial states: one ensemble run equals N separate runs.

The reference is ``simulate`` itself, called once per row of ``q0`` (the single-trajectory path,
tested against closed forms and SciPy elsewhere): every array of the batch result must equal
the corresponding single run to 1e-12 relative, for passive runs, each sampled built-in
controller, decimation and a run split in several pieces. Unsupported combinations must raise.
"""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd
from robodyn.robot.errors import SimulationError
from robodyn.simulation import LQR, PD, PID, ComputedTorque, GravityCompensation, quintic, simulate
from robodyn.simulation import simulation as simulation_module

ARRAYS = ("q", "qd", "qdd", "tau", "kinetic", "potential", "energy")
PUMA_Q0 = np.array([0.0, np.pi / 4, -np.pi / 2, 0.0, 0.3, 0.0])
PUMA_Q1 = PUMA_Q0 + np.array([0.8, -0.5, 0.6, 1.0, -0.7, 1.2])


def _starts(model, count, seed=0, spread=0.5):
    rng = np.random.default_rng(seed)
    n = model.dof
    return rng.uniform(-spread, spread, (count, n)), rng.uniform(-0.3, 0.3, (count, n))


def _close(a, b):
    scale = max(float(np.max(np.abs(b))), 1e-300)
    return float(np.max(np.abs(a - b))) <= 1e-12 * scale


def _assert_equals_separate_runs(model, q0, qd0, duration, dt, **kwargs):
    run = simulate(model, q0, qd0, duration, dt, **kwargs)
    count, n = q0.shape
    samples = run.t.size
    assert run.batch == count
    assert run.q.shape == run.qd.shape == run.qdd.shape == run.tau.shape == (count, samples, n)
    assert run.kinetic.shape == run.potential.shape == run.energy.shape == (count, samples)
    assert run.x.shape == (count, samples, 2 * n)
    for i in range(count):
        one = simulate(model, q0[i], None if qd0 is None else qd0[i], duration, dt, **kwargs)
        np.testing.assert_array_equal(run.t, one.t)
        for name in ARRAYS:
            assert _close(getattr(run, name)[i], getattr(one, name)), (name, i)
        assert run.evaluations == one.evaluations
        assert run.controller == one.controller and run.method == one.method
    return run


@pytest.mark.tool("gcc|cc")
@pytest.mark.parametrize("method", ["rk4", "semi_implicit"])
def test_passive_batch_equals_separate_runs(trolley, method):
    q0, qd0 = _starts(trolley, 5, seed=1)
    run = _assert_equals_separate_runs(trolley, q0, qd0, 0.5, 1e-3, method=method)
    # physics, not only agreement: a passive RK4 run conserves energy (planar-arm figures: 1e-9)
    if method == "rk4":
        assert run.energy_drift.shape == (5,) and np.all(run.energy_drift < 1e-6)


@pytest.mark.tool("gcc|cc")
def test_batch_split_in_pieces_and_decimated(trolley, monkeypatch):
    # pieces of 64 // 4 = 16 steps, not aligned with decimate = 3: 100 steps, 34 samples kept
    monkeypatch.setattr(simulation_module, "CHUNK_STEPS", 64)
    q0, qd0 = _starts(trolley, 4, seed=2)
    run = _assert_equals_separate_runs(trolley, q0, qd0, 0.102, 1e-3, decimate=3)
    assert run.t.size == 35
    full = simulate(trolley, q0, qd0, 0.102, 1e-3)
    np.testing.assert_array_equal(run.q, full.q[:, ::3])


@pytest.mark.tool("gcc|cc")
@pytest.mark.parametrize("kind", ["pd", "gravity", "computed_torque", "pid", "lqr"])
def test_controlled_batch_equals_separate_runs(puma_rigid, kind):
    n = puma_rigid.dof
    move = quintic(PUMA_Q0, PUMA_Q1, 0.3)
    controller = {
        "pd": PD(300.0, 30.0, move, tau_limit=80.0),
        "gravity": GravityCompensation(300.0, 30.0, move),
        "computed_torque": ComputedTorque(move, 400.0, 40.0),
        "pid": PID(300.0, 200.0, 30.0, PUMA_Q1),
        "lqr": LQR(np.hstack([np.eye(n) * 200.0, np.eye(n) * 20.0]),
                   np.concatenate([PUMA_Q1, np.zeros(n)]), puma_rigid.gravity(PUMA_Q1)),
    }[kind]
    q0, qd0 = _starts(puma_rigid, 6, seed=3, spread=0.05)
    q0 = q0 + PUMA_Q0
    run = _assert_equals_separate_runs(puma_rigid, q0, qd0, 0.3, 1e-3, controller=controller)
    # the controllers track: every trajectory ends near the target
    assert np.all(np.abs(run.q[:, -1] - PUMA_Q1).max(axis=1) < 0.3)


@pytest.mark.tool("gcc|cc")
def test_batch_of_one_keeps_the_batch_axis_and_members(planar):
    q0 = np.array([[0.3, -0.2]])
    run = simulate(planar, q0, None, 0.05, 1e-3)
    one = simulate(planar, q0[0], None, 0.05, 1e-3)
    assert run.q.shape == (1, 51, 2) and run.energy.shape == (1, 51)
    assert one.q.shape == (51, 2) and one.batch is None and isinstance(one.energy_drift, float)
    member = run.member(0)
    assert member.q.shape == (51, 2)
    for name in ARRAYS:
        assert _close(getattr(member, name), getattr(one, name))
    assert member.energy_drift == pytest.approx(one.energy_drift, rel=1e-6, abs=1e-15)
    with pytest.raises(IndexError, match="out of range"):
        run.member(1)
    with pytest.raises(ValueError, match="single run"):
        one.member(0)


@pytest.mark.tool("gcc|cc")
def test_batch_result_is_read_only_and_input_untouched(planar):
    q0 = np.array([[0.3, -0.2], [0.1, 0.4]])
    qd0 = np.array([[0.0, 0.1], [0.2, 0.0]])
    before = (q0.copy(), qd0.copy())
    run = simulate(planar, q0, qd0, 0.02, 1e-3, threads=2)
    np.testing.assert_array_equal(q0, before[0])
    np.testing.assert_array_equal(qd0, before[1])
    with pytest.raises(ValueError):
        run.q[0, 0, 0] = 1.0
    # the thread count does not change a bit
    np.testing.assert_array_equal(run.q, simulate(planar, q0, qd0, 0.02, 1e-3).q)


def test_numpy_backend_batch_equals_its_separate_runs():
    model = rd.compile_model(rd.load("planar_2r"), backend="numpy")
    q0, qd0 = _starts(model, 3, seed=5)
    _assert_equals_separate_runs(model, q0, qd0, 0.01, 1e-3, controller=PD(50.0, 5.0, [0.2, 0.1]))


@pytest.mark.tool("gcc|cc")
@pytest.mark.parametrize(("kwargs", "match"), [
    ({"method": "RK45"}, r"method='RK45' \(solve_ivp"),
    ({"control": "continuous"}, "control='continuous'"),
    ({"substeps": 2}, "substeps=2"),
    ({"controller": lambda t, q, qd: -q}, "Python callable controller"),
])
def test_unsupported_batch_combinations_raise(planar, kwargs, match):
    q0 = np.zeros((3, 2))
    with pytest.raises(ValueError, match="batch of initial states.*" + match):
        simulate(planar, q0, None, 0.01, 1e-3, **kwargs)


@pytest.mark.tool("gcc|cc")
def test_controller_with_its_own_model_is_refused_in_a_batch(planar):
    other = rd.compile_model(rd.load("planar_2r"), parameters={"m1": 1.2, "m2": 1.2})
    ctrl = GravityCompensation(100.0, 10.0, [0.1, 0.2], model=other)
    with pytest.raises(ValueError, match="batch of initial states.*its own model"):
        simulate(planar, np.zeros((2, 2)), None, 0.01, 1e-3, controller=ctrl)


@pytest.mark.tool("gcc|cc")
def test_bad_batch_shapes_and_values(planar):
    with pytest.raises(ValueError, match=r"q0 must have shape \(N, 2\)"):
        simulate(planar, np.zeros((3, 3)), None, 0.01, 1e-3)
    with pytest.raises(ValueError, match=r"q0 must have shape \(N, 2\)"):
        simulate(planar, np.zeros((0, 2)), None, 0.01, 1e-3)
    with pytest.raises(ValueError, match=r"qd0 must have shape \(3, 2\), got \(2,\)"):
        simulate(planar, np.zeros((3, 2)), np.zeros(2), 0.01, 1e-3)
    with pytest.raises(ValueError, match=r"qd0 must have shape \(2,\)"):
        simulate(planar, np.zeros(2), np.zeros((3, 2)), 0.01, 1e-3)
    bad = np.zeros((3, 2))
    bad[1, 0] = np.nan
    with pytest.raises(ValueError, match=r"q0 contains non-finite values \(row 1\)"):
        simulate(planar, bad, None, 0.01, 1e-3)
    # max_samples counts the samples of every trajectory: 4 x 11 > 40
    with pytest.raises(ValueError, match=r"keeps 4 x 11 samples.*max_samples = 40"):
        simulate(planar, np.zeros((4, 2)), None, 0.01, 1e-3, max_samples=40)
    assert simulate(planar, np.zeros((4, 2)), None, 0.01, 1e-3, max_samples=44).q.shape == (4, 11, 2)


@pytest.mark.tool("gcc|cc")
def test_a_diverging_trajectory_is_named(trolley):
    q0, qd0 = _starts(trolley, 4, seed=6)
    qd0 = qd0.copy()
    qd0[2] = 1e200  # overflows in the first steps
    with pytest.raises(SimulationError, match="1 of 4 trajectories.*trajectory 2"):
        simulate(trolley, q0, qd0, 0.01, 1e-3)
