"""Drive modes (``resonance=``): one lightly damped second-order mode per joint, fitted on what the
identified model leaves (robodyn.identification.resonance).

The response itself is checked against the closed-form step response of the continuous mode;
the choice against simulated PUMA 560 data with known truth: the measured torque of joint 1 is
the description's own torque through a mode at 8 Hz, damping 0.2 (``H tau``, i.e. share 1).
"""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd
from robodyn.identification.resonance import F0_GRID, ZETA_GRID, ResonanceFit, mode_response
from robodyn.robot.errors import IdentificationError
from tests.identification.helpers import fourier, load_quiet

F0, ZETA = 8.0, 0.2  # the plant's mode on joint 1, Hz and damping ratio
DT = 2e-3


def _step_response(t: np.ndarray, f0: float, zeta: float) -> np.ndarray:
    """Unit step response of w^2 / (s^2 + 2 zeta w s + w^2), underdamped, closed form."""
    w = 2 * np.pi * f0
    wd = w * np.sqrt(1 - zeta**2)
    phi = np.arccos(zeta)
    return 1 - np.exp(-zeta * w * t) / np.sqrt(1 - zeta**2) * np.sin(wd * t + phi)


def test_mode_response_is_the_continuous_mode():
    t = np.arange(0.0, 2.0, 1e-4)
    x = (t >= 0.5).astype(float)[:, None]  # at rest on 0, a unit step at 0.5 s
    y = mode_response(t, x, 6.0, 0.15)[:, 0]
    after = t >= 0.5
    # bilinear transform at 10 kHz against the closed form: agrees to the step's sampling
    np.testing.assert_allclose(y[after], _step_response(t[after] - 0.5, 6.0, 0.15), atol=2e-3)
    np.testing.assert_allclose(y[~after], 0.0, atol=1e-12)  # at rest before the step
    # unit static gain: a constant passes unchanged (to the rounding of the filter coefficients at
    # a step 1700 times shorter than the period)
    np.testing.assert_allclose(mode_response(t, np.full((t.size, 2), 3.5), 6.0, 0.15), 3.5, rtol=1e-9)


def test_mode_response_on_irregular_stamps_follows_the_uniform_one():
    rng = np.random.default_rng(0)
    t = np.cumsum(rng.uniform(0.8e-3, 1.2e-3, 3000))
    x = np.sin(2 * np.pi * 3.0 * t)[:, None]
    tu = np.arange(t[0], t[-1], 1e-4)
    ref = np.interp(t, tu, mode_response(tu, np.sin(2 * np.pi * 3.0 * tu)[:, None], 7.0, 0.3)[:, 0])
    np.testing.assert_allclose(mode_response(t, x, 7.0, 0.3)[:, 0], ref, atol=5e-3)


@pytest.fixture(scope="module")
def puma():
    robot = load_quiet("puma560")
    return robot, rd.compile_model(robot)


def _run(model, seed: int, mode: bool, seconds: float = 16.0, noise: float = 0.05) -> rd.Recording:
    """Slow motion plus small 6-9 Hz components (what excites a mode); measured torque of
    joint 1 through the mode when ``mode``."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, seconds, DT)
    q, qd, qdd = fourier(t, model.dof, rng, f0=1.0 / seconds)
    for f in (6.0, 7.5, 9.0):
        a, phase = rng.uniform(1e-3, 2e-3, model.dof), rng.uniform(0, 2 * np.pi, model.dof)
        w = 2 * np.pi * f
        q = q + a * np.sin(w * t[:, None] + phase)
        qd = qd + a * w * np.cos(w * t[:, None] + phase)
        qdd = qdd - a * w * w * np.sin(w * t[:, None] + phase)
    tau = model.inverse_dynamics(q, qd, qdd)
    if mode:
        tau[:, :1] = mode_response(t, tau[:, :1], F0, ZETA)
    clean = tau.copy()
    tau = tau + noise * rng.standard_normal(tau.shape)
    rec = rd.Recording(t=t, q=q, qd=qd, tau=tau, joint_names=model.robot.joint_names,
                       source=f"run{seed}")
    return rec, clean


def _error(pred: np.ndarray, clean: np.ndarray) -> float:
    return float(np.linalg.norm(pred - clean) / np.linalg.norm(clean))


def test_a_mode_is_found_where_the_plant_has_one(puma):
    robot, model = puma
    fit = [_run(model, 1, True)[0], _run(model, 2, True)[0]]
    check, clean = _run(model, 3, True)
    ident = rd.identify(robot, fit, model=model)
    rf = ident.resonance_fit
    assert ident.choices.resonance is True and rf.kept[0]
    # the grid's neighbours of the truth, and the share near 1 (the torque is H tau)
    assert rf.f0[0] in (7.0, 8.0, 10.0) and rf.zeta[0] in (0.1, 0.2, 0.35)
    assert 0.8 < rf.gain[0] < 1.2
    assert "drive modes kept" in ident.choices.summary()
    without = rd.identify(robot, fit, model=model, resonance=False)
    assert without.resonance_fit is None and without.choices.resonance is None
    # joint 1 held out against the noise-free measured torque: the mode takes most of the error
    e_with = _error(ident.predict(check)[:, 0], clean[:, 0])
    e_without = _error(without.predict(check)[:, 0], clean[:, 0])
    assert e_with < 0.5 * e_without


def test_no_mode_changes_a_rigid_plant_much(puma):
    robot, model = puma
    fit = [_run(model, 4, False)[0], _run(model, 5, False)[0]]
    check, clean = _run(model, 6, False)
    auto = rd.identify(robot, fit, model=model)
    plain = rd.identify(robot, fit, model=model, resonance=False)
    # a mode kept on noise alone has a share near 0 and leaves the prediction as it was
    if auto.resonance_fit is not None:
        assert np.max(np.abs(auto.resonance_fit.gain)) < 0.2
    assert _error(auto.predict(check), clean) < 1.02 * _error(plain.predict(check), clean)


def test_joints_without_a_mode_keep_the_plain_prediction():
    t = np.arange(0.0, 1.0, 1e-3)
    wide = np.column_stack([np.sin(2 * np.pi * 5 * t), np.cos(2 * np.pi * 5 * t)])
    plain = 0.5 * wide
    fit = ResonanceFit(np.array([8.0, np.nan]), np.array([0.2, np.nan]), np.array([0.5, 0.0]), 20.0)
    out = fit.combine(t, wide, plain)
    np.testing.assert_array_equal(out[:, 1], plain[:, 1])
    expected = wide[:, 0] + 0.5 * (mode_response(t, wide[:, :1], 8.0, 0.2)[:, 0] - wide[:, 0])
    np.testing.assert_allclose(out[:, 0], expected, rtol=0, atol=1e-15)
    assert F0_GRID[0] > 0 and 0 < min(ZETA_GRID) and max(ZETA_GRID) < 1


def test_bad_resonance_option_is_refused(puma):
    robot, model = puma
    with pytest.raises(IdentificationError, match="resonance: expected False, True or 'auto'"):
        rd.identify(robot, _run(model, 7, False, seconds=4.0)[0], resonance="maybe", model=model)
