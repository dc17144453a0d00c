"""The local correction of the residual (``local=``, robodyn.identification.local_residual).

Against known truth: a smooth function of the states the correction must recover where the data
were and leave alone far from them, pure noise it must not keep, and a simulated PUMA 560 whose
measured torque holds a term the description cannot express (``A sin(3 q_1) cos(2 q_2)`` on
joints 1 and 2), fitted on 1.4 periods of a periodic excitation and predicted on the rest of the
second period (states the fit visited) and on another trajectory.
"""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd
from robodyn.identification.local_residual import (
    LENGTH_GRID,
    RIDGE_GRID,
    LocalResidualFit,
    fit_local_residual,
)
from robodyn.robot.errors import IdentificationError
from tests.identification.helpers import fourier, load_quiet


def _states(t: np.ndarray, period: float) -> np.ndarray:
    """A periodic path in 6 state columns, (N, 6)."""
    w = 2 * np.pi / period
    return np.column_stack([np.sin(w * t), np.cos(2 * w * t), np.sin(3 * w * t + 1),
                            np.cos(w * t + 0.3), np.sin(2 * w * t + 2), np.cos(5 * w * t)])


def _smooth(x: np.ndarray) -> np.ndarray:
    """A residual that is a smooth function of the states, (N, 2)."""
    return np.column_stack([0.3 * np.sin(2 * x[:, 0]) * x[:, 1], 0.2 * np.cos(x[:, 2] + x[:, 3])])


def test_recovers_a_smooth_residual_and_vanishes_far_from_the_data():
    rng = np.random.default_rng(0)
    t = np.arange(0.0, 20.0, 0.01)  # two periods
    x = _states(t, 10.0)
    truth = _smooth(x)
    fit, scores = fit_local_residual([x], [truth + 0.02 * rng.standard_normal(truth.shape)], "auto")
    assert fit is not None and scores["local"] < 0.5  # kept: the held-out blocks show it
    assert fit.length in LENGTH_GRID and fit.ridge in RIDGE_GRID
    # on the path (a phase between the samples): the smooth function, to 10 % of its size
    tc = np.arange(0.005, 10.0, 0.01)
    xc = _states(tc, 10.0)
    err = np.linalg.norm(fit.correction(xc) - _smooth(xc)) / np.linalg.norm(_smooth(xc))
    assert err < 0.1
    # 30 standard deviations away every kernel value is below exp(-450 / 2^2): the correction
    # is bounded by that times the sum of the weights' magnitudes
    far = xc + 30.0 * x.std(axis=0)
    bound = np.exp(-0.5 * 30.0**2 / max(LENGTH_GRID) ** 2) * np.abs(fit.weights).sum(axis=0)
    assert np.all(np.abs(fit.correction(far)) <= bound + 1e-300)
    assert np.max(np.abs(fit.correction(far))) < 1e-12


def test_long_recordings_are_thinned_evenly(monkeypatch):
    import robodyn.identification.local_residual as local

    monkeypatch.setattr(local, "MAX_ROWS", 1500)  # two recordings of 2000 rows: 750 rows each
    t = np.arange(0.0, 20.0, 0.01)
    x1, x2 = _states(t, 10.0), _states(t + 0.005, 10.0)
    fit, _ = fit_local_residual([x1, x2], [_smooth(x1), _smooth(x2)], True)
    assert fit is not None and len(fit.inducing) == min(local.INDUCING, 1500)
    xc = _states(np.arange(0.0025, 10.0, 0.01), 10.0)
    err = np.linalg.norm(fit.correction(xc) - _smooth(xc)) / np.linalg.norm(_smooth(xc))
    assert err < 0.1


def test_noise_alone_is_not_kept():
    rng = np.random.default_rng(1)
    t = np.arange(0.0, 20.0, 0.01)
    x = _states(t, 10.0)
    fit, scores = fit_local_residual([x], [0.05 * rng.standard_normal((t.size, 2))], "auto")
    assert fit is None and scores["local"] > 0.99  # no setting predicts white noise


def test_a_missing_target_teaches_nothing():
    t = np.arange(0.0, 20.0, 0.01)
    x = _states(t, 10.0)
    r = _smooth(x)
    r[:, 1] = np.nan  # a joint without a sensor
    fit, _ = fit_local_residual([x], [r], True)
    assert fit is not None
    np.testing.assert_array_equal(fit.weights[:, 1], 0.0)


@pytest.fixture(scope="module")
def puma():
    robot = load_quiet("puma560")
    return robot, rd.compile_model(robot)


def _run(model, seed: int, seconds: float, period: float) -> tuple[rd.Recording, np.ndarray]:
    """A periodic excitation (period ``period``) and its torque with the term the description
    lacks, measured with noise; and the noise-free torque."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, seconds, 5e-3)
    q, qd, qdd = fourier(t, model.dof, rng, f0=1.0 / period, amplitude=0.6)
    tau = model.inverse_dynamics(q, qd, qdd)
    extra = 2.0 * np.sin(3 * q[:, 0]) * np.cos(2 * q[:, 1])
    tau[:, 0] += extra
    tau[:, 1] += 0.5 * extra
    noisy = tau + 0.05 * np.random.default_rng(seed + 100).standard_normal(tau.shape)
    return rd.Recording(t=t, q=q, qd=qd, tau=noisy, joint_names=model.robot.joint_names,
                        source=f"run{seed}"), tau


def _error(pred: np.ndarray, clean: np.ndarray) -> float:
    return float(np.linalg.norm(pred - clean) / np.linalg.norm(clean))


@pytest.mark.slow
def test_a_repeated_trajectory_gets_the_correction_new_motion_the_model(puma):
    robot, model = puma
    rec, clean = _run(model, 1, 20.0, 10.0)  # two periods
    cut = int(0.7 * len(rec.t))
    fit = rd.Recording(t=rec.t[:cut], q=rec.q[:cut], qd=rec.qd[:cut], tau=rec.tau[:cut],
                       joint_names=rec.joint_names, source="first 70 %")
    rest = rd.Recording(t=rec.t[cut:], q=rec.q[cut:], qd=rec.qd[cut:], tau=rec.tau[cut:],
                        joint_names=rec.joint_names, source="last 30 %")
    auto = rd.identify(robot, fit, model=model)
    plain = rd.identify(robot, fit, model=model, local=False)
    assert auto.choices.local is True and auto.local_fit is not None
    assert plain.local_fit is None and plain.choices.local is None
    assert "local correction of the residual kept" in auto.choices.summary()
    # the rest of the second period: states the fit visited; most of the missing term recovered
    assert _error(auto.predict(rest), clean[cut:]) < 0.5 * _error(plain.predict(rest), clean[cut:])
    # another trajectory, elsewhere in the state space: the model's prediction, nearly unchanged
    other, _ = _run(model, 2, 10.0, 10.0)
    correction = auto.predict(other) - plain.predict(other)
    assert np.linalg.norm(correction) < 0.05 * np.linalg.norm(plain.predict(other))


def test_bad_local_option_is_refused(puma):
    robot, model = puma
    rec, _ = _run(model, 3, 4.0, 4.0)
    with pytest.raises(IdentificationError, match="local: expected False, True or 'auto'"):
        rd.identify(robot, rec, local="sometimes", model=model)


def test_the_fit_is_frozen_data():
    fit = LocalResidualFit(np.zeros(3), np.ones(3), np.zeros((1, 3)), np.ones((1, 1)), 1.0, 1e-4)
    with pytest.raises(AttributeError):
        fit.length = 2.0  # type: ignore[misc]
    np.testing.assert_allclose(fit.correction(np.zeros((2, 3))), 1.0)  # k(x, x) = 1
