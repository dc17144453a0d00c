"""Long runs: the output size is checked before anything is allocated; decimation; pieces."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd
from robodyn.robot.errors import SimulationError
from robodyn.simulation import PD, PID, ComputedTorque, quintic, simulate
from robodyn.simulation import simulation as sim_mod

Q0 = np.array([-1.0, 0.5])


@pytest.mark.parametrize("duration", [1e9, 1e5, 1e4])
def test_a_huge_run_is_refused_before_allocating(planar, duration):
    # 1e9 s at 1 ms was a 7 TiB allocation; now a clear error naming the way out
    with pytest.raises(ValueError, match=r"above max_samples = 1,000,000; keep every k-th step "
                                         r"with decimate=k"):
        simulate(planar, Q0, None, duration, 1e-3)


def test_max_samples_and_decimate_let_a_long_run_through(planar):
    with pytest.raises(ValueError, match="above max_samples = 100"):
        simulate(planar, Q0, None, 1.0, 1e-3, max_samples=100)
    run = simulate(planar, Q0, None, 1.0, 1e-3, max_samples=None)
    assert run.t.size == 1001
    with pytest.raises(ValueError, match="not a whole number of decimate = 3 steps"):
        simulate(planar, Q0, None, 1.0, 1e-3, decimate=3)
    with pytest.raises(ValueError, match="decimate must be a positive integer"):
        simulate(planar, Q0, None, 1.0, 1e-3, decimate=0)


@pytest.mark.parametrize("method", ["rk4", "semi_implicit", "RK45"])
def test_decimated_samples_are_the_full_runs_samples(planar, method):
    ctrl = PD(100.0, 20.0, np.array([0.5, 0.3]))
    full = simulate(planar, Q0, None, 1.0, 1e-3, method, ctrl)
    thin = simulate(planar, Q0, None, 1.0, 1e-3, method, ctrl, decimate=10)
    assert thin.t.size == 101 and thin.decimate == 10
    np.testing.assert_allclose(thin.t, full.t[::10], rtol=0, atol=1e-15)
    # fixed step: the same steps (bit for bit); SciPy: the same solution sampled less often
    tol = 1e-9 if method == "RK45" else 0.0
    np.testing.assert_allclose(thin.q, full.q[::10], rtol=0, atol=tol)
    np.testing.assert_allclose(thin.tau, full.tau[::10], rtol=0, atol=tol * 1e3)
    np.testing.assert_allclose(thin.energy, full.energy[::10], rtol=0, atol=tol * 1e3)


@pytest.mark.parametrize("control", ["sampled", "continuous"])
def test_a_run_split_into_pieces_equals_one_piece(planar, monkeypatch, control):
    """CHUNK_STEPS bounds memory: the result must not depend on where the pieces start."""
    plan = quintic(Q0, np.array([0.5, 1.3]), 0.5, dt=1e-3)
    ctrls = [PD(100.0, 20.0, plan), ComputedTorque(plan, 400.0, 40.0)]
    if control == "sampled":
        # a PID's integral crosses the pieces as a feedforward Ki z
        ctrls.append(PID(100.0, 50.0, 20.0, plan))
    whole = [simulate(planar, Q0, None, 1.0, 1e-3, "rk4", c, control=control) for c in ctrls]
    monkeypatch.setattr(sim_mod, "CHUNK_STEPS", 37)
    for c, ref in zip(ctrls, whole, strict=True):
        for dec in (1, 4):
            run = simulate(planar, Q0, None, 1.0, 1e-3, "rk4", c, control=control, decimate=dec)
            # sums taken in another order: rounding only
            np.testing.assert_allclose(run.q, ref.q[::dec], rtol=0, atol=1e-12, err_msg=c.name)
            np.testing.assert_allclose(run.tau, ref.tau[::dec], rtol=0, atol=1e-9, err_msg=c.name)


def test_rollout_refuses_an_output_it_cannot_hold(planar):
    with pytest.raises(ValueError, match="split the run into several calls"):
        rd.rollout(planar, np.zeros(4), rd.RolloutOptions(10**12, 1e-3))


def test_a_run_that_blows_up_is_a_simulation_error(planar):
    # an explicit step far beyond stability: a ValueError for the CLI, a FloatingPointError as before
    with pytest.raises(SimulationError, match="stopped being finite"):
        simulate(planar, Q0, None, 20.0, 0.5, "rk4", PD(1e6, 0.0, np.zeros(2)))
