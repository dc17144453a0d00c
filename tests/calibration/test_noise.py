"""Noisy synthetic data: held-out accuracy against the noise, statistics, uncertainties, robustness."""

from __future__ import annotations

import math
from dataclasses import replace
from functools import cache

import numpy as np
import pytest
import sympy as sp

import robodyn as rd
from robodyn.calibration import calibrate, validate
from robodyn.calibration.solve import fit
from robodyn.studies.calibration_study import perturbed_robot, robot_frames, robot_positions
from tests.calibration.helpers import TARGET, TRACKER, poses, robot, symbolic_fk

SIGMA = 5e-5  # m per coordinate: a laser tracker


@cache
def data(seed: int = 0, n: int = 100, n_test: int = 200):
    """True PUMA with generic errors, noisy training and held-out measurements."""
    r = robot("puma560")
    true = perturbed_robot(r, seed, base=TRACKER, target=TARGET)
    rng = np.random.default_rng(seed + 100)
    q, q_test = poses("puma560", n, seed + 1), poses("puma560", n_test, seed + 2)
    clean, clean_test = robot_positions(true, q), robot_positions(true, q_test)
    y = clean + rng.normal(0, SIGMA, clean.shape)
    y_test = clean_test + rng.normal(0, SIGMA, clean_test.shape)
    return true, q, clean, y, q_test, clean_test, y_test


@pytest.mark.parametrize("model", ("hayati", "s-model", "poe"))
def test_held_out_rms_within_1_3_of_the_noise(model):
    _, q, _, y, q_test, _, y_test = data()
    cal = calibrate(robot("puma560"), q, y, model, sigma=SIGMA)
    noise_rms = SIGMA * math.sqrt(3)  # RMS length of a 3-D noise vector
    held = validate(cal, q_test, y_test)
    assert cal.before.rms > 10 * noise_rms
    assert held.rms < 1.3 * noise_rms
    assert 0.7 < cal.variance_factor < 1.3


def test_standard_dh_stays_above_the_noise_on_the_puma():
    _, q, _, y, q_test, _, y_test = data()
    cal = calibrate(robot("puma560"), q, y, "dh", sigma=SIGMA)
    assert validate(cal, q_test, y_test).rms > 2 * SIGMA * math.sqrt(3)


@pytest.mark.slow
def test_before_and_after_statistics_match_an_independent_recomputation():
    _, q, _, y, _, _, _ = data()
    cal = calibrate(robot("puma560"), q, y, "hayati", sigma=SIGMA)
    after_points = symbolic_fk(cal.robot)(q)[:, :3, 3]
    before_points = symbolic_fk(cal.before_robot)(q)[:, :3, 3]
    for predicted, stats in ((before_points, cal.before), (after_points, cal.after)):
        d = np.linalg.norm(y - predicted, axis=1)
        assert stats.count == len(q)
        assert stats.mean == pytest.approx(d.sum() / len(d), rel=1e-9)
        assert stats.rms == pytest.approx(math.sqrt((d**2).sum() / len(d)), rel=1e-9)
        assert stats.max == pytest.approx(d.max(), rel=1e-9)
        assert stats.std == pytest.approx(math.sqrt(((d - d.mean()) ** 2).sum() / (len(d) - 1)), rel=1e-6)
    np.testing.assert_allclose(cal.residuals, y - after_points, atol=1e-12)


def test_standard_uncertainties_cover_the_truth():
    # true values of the identified parameters: the same model fitted to noise-free data
    _, q, clean, y, _, _, _ = data()
    cal = calibrate(robot("puma560"), q, y, "hayati", sigma=SIGMA)
    free = [cal.model.index(n) for n in cal.parameter_names]
    true = fit(cal.model, cal.params, free, q, clean, sigma=SIGMA).params[free]
    z = (cal.values - true) / cal.std
    # about 95 % of |z| below 1.96 for a right covariance; 27 parameters, correlated
    assert np.mean(np.abs(z) < 1.96) > 0.8
    assert np.max(np.abs(z)) < 4.5


def test_robust_loss_resists_gross_outliers():
    _, q, _, y, q_test, clean_test, _ = data()
    y = y.copy()
    bad = np.arange(0, len(y), 12)  # 9 of 100 poses with a 5 mm blunder
    y[bad] += np.array([5e-3, -4e-3, 3e-3])
    plain = calibrate(robot("puma560"), q, y, "hayati", sigma=SIGMA)
    robust = calibrate(robot("puma560"), q, y, "hayati", sigma=SIGMA, loss="soft_l1")
    err_plain = validate(plain, q_test, clean_test).rms
    err_robust = validate(robust, q_test, clean_test).rms
    assert err_robust < 0.2 * err_plain
    assert err_robust < 2 * SIGMA * math.sqrt(3)


@pytest.mark.parametrize("turn", (0.0, 2.0))
def test_orientation_measurements_are_used(turn):
    # a target frame turned by `turn` rad about an oblique axis: its orientation is unknown
    r = robot("puma560")
    axis = np.array([1.0, -2.0, 0.5]) / np.linalg.norm([1.0, -2.0, 0.5])
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    turned = np.eye(4)
    turned[:3, :3] = np.eye(3) + math.sin(turn) * k + (1 - math.cos(turn)) * k @ k
    true = perturbed_robot(r, 31, base=TRACKER, target=TARGET)
    true = replace(true, tool=sp.ImmutableMatrix(np.array(true.tool, dtype=float) @ turned))
    q, q_test = poses("puma560", 100, 32), poses("puma560", 50, 33)
    rng = np.random.default_rng(5)
    frames = robot_frames(true, q)  # rotations too (checked against SymPy in test_kinematics)
    y = frames[:, :3, 3] + rng.normal(0, SIGMA, (100, 3))
    rots = []
    for f in frames[:, :3, :3]:
        w = rng.normal(0, 1e-4, 3)
        kw = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
        u, _, vt = np.linalg.svd((np.eye(3) + kw) @ f)
        rots.append(u @ vt)
    cal = calibrate(r, q, y, "s-model", sigma=SIGMA, orientations=np.array(rots), sigma_rot=1e-4)
    assert cal.converged
    assert np.sqrt(np.mean(cal.rotation_residuals**2)) < 2e-4
    assert validate(cal, q_test, robot_frames(true, q_test)[:, :3, 3]).rms < SIGMA * math.sqrt(3)
    # the target frame's orientation is identified
    pred = cal.predict_frames(q_test[:5])[:, :3, :3]
    np.testing.assert_allclose(pred, symbolic_fk(true)(q_test[:5])[:, :3, :3], atol=1e-4)


def test_before_robot_is_the_nominal_kinematics():
    _, q, _, y, _, _, _ = data()
    cal = calibrate(robot("puma560"), q, y, "poe", sigma=SIGMA)
    nominal = robot("puma560")
    for a, b in zip(cal.before_robot.joints[1:], nominal.joints[1:], strict=True):
        np.testing.assert_allclose(np.array(a.pre, dtype=float), np.array(b.pre.evalf(), dtype=float),
                                   atol=1e-12)
    assert isinstance(cal.before_robot, rd.Robot)
