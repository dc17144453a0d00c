"""State-noise propagation through the analytic derivatives, against Monte Carlo."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd
from robodyn.identification.pipeline import nominal_standard
from robodyn.identification.state_noise import state_noise_std, torque_variance
from robodyn.robot.errors import IdentificationError
from tests.identification.helpers import load_quiet

S_Q, S_QD, S_QDD = np.array([2e-3, 1e-3]), np.array([0.05, 0.08]), np.array([0.6, 0.4])


@pytest.fixture(scope="module")
def arm():
    robot = load_quiet("planar_2r")
    return robot, rd.compile_model(robot)


def test_propagated_variance_matches_monte_carlo(arm):
    """Perturb the state with independent Gaussian noise, evaluate tau, compare variances."""
    robot, model = arm
    rng = np.random.default_rng(0)
    states = [rng.uniform(-2, 2, (5, 2)) for _ in range(3)]
    var = torque_variance(model, *states, S_Q, S_QD, S_QDD)
    draws = 40000  # relative standard error of a variance: sqrt(2 / draws) = 0.7 %
    for k in range(5):
        q, qd, qdd = (s[k] for s in states)
        noisy = [x + rng.standard_normal((draws, 2)) * s
                 for x, s in ((q, S_Q), (qd, S_QD), (qdd, S_QDD))]
        mc = model.inverse_dynamics(*noisy).var(axis=0)
        print(k, var[k], mc, var[k] / mc - 1)
        np.testing.assert_allclose(var[k], mc, rtol=0.05)


def test_regressor_derivatives_give_the_same_variance(arm):
    """(dY/dx) p of the description's parameters equals the model's own derivatives."""
    robot, model = arm
    rng = np.random.default_rng(1)
    states = [rng.uniform(-2, 2, (20, 2)) for _ in range(3)]
    a = torque_variance(model, *states, S_Q, S_QD, S_QDD)
    b = torque_variance(model, *states, S_Q, S_QD, S_QDD, standard=nominal_standard(robot))
    np.testing.assert_allclose(b, a, rtol=1e-10, atol=1e-14)


def test_state_noise_option_is_validated():
    with pytest.raises(IdentificationError, match=r"state_noise: expected 3 entries"):
        state_noise_std((0.1, 0.2), 2)
    with pytest.raises(IdentificationError, match=r"state_noise.s_qd: must be finite and >= 0"):
        state_noise_std((0.1, -1.0, 0.0), 2)
    with pytest.raises(IdentificationError, match=r"state_noise.s_q: expected a scalar or shape \(2,\)"):
        state_noise_std(([0.1, 0.1, 0.1], 0.0, 0.0), 2)


def _noisy_velocity_log(model, seed, s_qd):
    from tests.identification.helpers import fourier

    rng = np.random.default_rng(seed)
    t = np.arange(0.0, 20.0, 0.01)
    q, qd, qdd = fourier(t, model.dof, rng)
    tau = model.inverse_dynamics(q, qd, qdd)
    return rd.Recording(t=t, q=q, qd=qd + rng.normal(0.0, s_qd, qd.shape), qdd=qdd,
                        tau=tau + rng.normal(0.0, 0.05, tau.shape), source=f"noisy-qd-{seed}")


def test_state_noise_weighting_reduces_the_parameter_error(arm):
    """Velocity noise 0.3 rad/s (exact q, qdd; torque noise 0.05 N m), four seeds: the
    errors-in-variables weighting against WLS with per-joint residual weights. Measured error
    ratios 0.16, 0.40, 0.29, 0.65 (seeds 0-3) on the inertial base parameters."""
    robot, model = arm
    state = (0.0, 0.3, 0.0)
    ratios = []
    for seed in range(4):
        rec = _noisy_velocity_log(model, seed, state[1])
        errs = []
        for w in ("residual", "state-noise"):
            ident = rd.identify(robot, rec, method="wls", cutoff=None, regularization=None,
                                model=model, weights=w, state_noise=state)
            true = ident.relations.to_base(nominal_standard(robot))
            inertial = ident.relations.independent % 15 < 10
            errs.append(np.linalg.norm((ident.base_parameters.values - true)[inertial])
                        / np.abs(true[inertial]).max())
        ratios.append(errs[1] / errs[0])
    print("error ratio state-noise / residual weights:", np.round(ratios, 3))
    assert max(ratios) < 1.0  # better on every seed
    assert np.mean(ratios) < 0.6


def test_state_noise_weighting_options_are_checked(arm):
    robot, model = arm
    rec = _noisy_velocity_log(model, 0, 0.1)
    with pytest.raises(IdentificationError, match=r"state_noise: weights='state-noise' needs"):
        rd.identify(robot, rec, cutoff=None, model=model, weights="state-noise")
    with pytest.raises(IdentificationError, match=r"weights: expected one of"):
        rd.identify(robot, rec, cutoff=None, model=model, weights="eiv")
