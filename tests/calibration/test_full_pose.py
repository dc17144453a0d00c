"""Several targets per pose together with a measured orientation (full poses).

The truth is the perturbed robot's tool frame (``robot_frames``): each reflector at its offset in
that frame, and the frame's rotation as the measured orientation, one per pose (a 6-DoF probe
carrying the reflectors). The error models' multi-target code is not used to make the data.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from robodyn.calibration import calibrate
from robodyn.calibration.held_out import validate, validate_orientation
from robodyn.cli import main
from robodyn.studies.calibration_study import perturbed_robot, robot_frames
from tests.calibration.helpers import TRACKER, poses, robot
from tests.calibration.test_nongeometric import TARGETS, measured

SIGMA, SIGMA_ROT = 5e-5, 1e-4  # m per coordinate; rad per axis


def _small_rotations(rng, n, sigma):
    """Rotations exp([w]) with w ~ N(0, sigma^2 I), shape (n, 3, 3)."""
    w = rng.normal(0, sigma, (n, 3))
    out = np.zeros((n, 3, 3))
    for i, v in enumerate(w):
        a = np.linalg.norm(v)
        k = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]]) / (a if a else 1)
        out[i] = np.eye(3) + np.sin(a) * k + (1 - np.cos(a)) * k @ k
    return out


@pytest.fixture(scope="module")
def full():
    r = robot("puma560")
    true = perturbed_robot(r, 7, base=TRACKER, target=(0.0, 0.0, 0.0))
    q, q_test = poses("puma560", 120, 31), poses("puma560", 60, 32)
    return r, true, q, q_test


def test_noise_free_full_poses_with_three_targets_are_fitted_exactly(full):
    r, true, q, q_test = full
    cal = calibrate(r, q, measured(true, q, TARGETS), "s-model",
                    orientations=robot_frames(true, q)[:, :3, :3])
    assert cal.converged and cal.rotation_residuals.shape == (len(q), 3)
    assert np.abs(cal.rotation_residuals).max() < 1e-10
    assert validate(cal, q_test, measured(true, q_test, TARGETS)).rms < 1e-9
    assert validate_orientation(cal, q_test, robot_frames(true, q_test)[:, :3, :3]).rms < 1e-10
    # the targets' layout on the tool (the model's last link frame may turn about the last axis
    # against the true one: compare what does not depend on the frame)
    d, t = cal.target_offsets()[1:] - cal.target_offsets()[0], TARGETS[1:] - TARGETS[0]
    np.testing.assert_allclose(d @ d.T, t @ t.T, atol=1e-12)


def test_multi_target_oriented_jacobian_matches_finite_differences(full):
    r, true, q, _ = full
    cal = calibrate(r, q, measured(true, q, TARGETS), "s-model",
                    orientations=robot_frames(true, q)[:, :3, :3])
    em, p = cal.model, cal.params + 1e-3  # away from the solution
    ev = em.evaluate(p, q[:5])
    h = 1e-7
    for k in range(em.n_params):
        dp = np.zeros_like(p)
        dp[k] = h
        a, b = em.evaluate(p + dp, q[:5], derivatives=False), em.evaluate(p - dp, q[:5], derivatives=False)
        np.testing.assert_allclose(ev.jac_param[:, :3, k], (a.position - b.position) / (2 * h), atol=1e-7,
                                   err_msg=em.names[k])
        # rotation: (R+ R-^T) ~ exp(2 h [w]) in the world frame
        d = np.einsum("nij,nkj->nik", a.rotation, b.rotation)
        w = 0.5 * np.stack((d[:, 2, 1] - d[:, 1, 2], d[:, 0, 2] - d[:, 2, 0], d[:, 1, 0] - d[:, 0, 1]), 1)
        np.testing.assert_allclose(ev.jac_param[:, 3:, k], w / (2 * h), atol=1e-7, err_msg=em.names[k])


def test_orientation_residuals_fit_and_held_out_at_their_noise(full):
    r, true, q, q_test = full
    rng = np.random.default_rng(33)

    def data(qq):
        frames = robot_frames(true, qq)
        y = measured(true, qq, TARGETS) + rng.normal(0, SIGMA, (len(qq), 3, 3))
        return y, _small_rotations(rng, len(qq), SIGMA_ROT) @ frames[:, :3, :3]

    y, rot = data(q)
    y_test, rot_test = data(q_test)
    cal = calibrate(r, q, y, "s-model", sigma=SIGMA, orientations=rot, sigma_rot=SIGMA_ROT)
    assert 0.7 < cal.variance_factor < 1.3
    # a rotation vector of three N(0, s^2) components has RMS length sqrt(3) s
    fit_rms = np.sqrt(np.mean(np.sum(cal.rotation_residuals**2, axis=1)))
    assert 0.8 * np.sqrt(3) * SIGMA_ROT < fit_rms < 1.05 * np.sqrt(3) * SIGMA_ROT
    held = validate_orientation(cal, q_test, rot_test)
    assert np.sqrt(3) * SIGMA_ROT * 0.8 < held.rms < 1.3 * np.sqrt(3) * SIGMA_ROT
    assert validate(cal, q_test, y_test).rms < 1.3 * np.sqrt(3) * SIGMA
    # its own uncertainty option: declared 100x too small, the orientation dominates the fit and
    # the variance factor says so
    with pytest.warns(RuntimeWarning, match="variance factor"):
        tight = calibrate(r, q, y, "s-model", sigma=SIGMA, orientations=rot, sigma_rot=SIGMA_ROT / 100)
    assert np.sqrt(np.mean(np.sum(tight.rotation_residuals**2, axis=1))) < fit_rms
    assert "orientation after:" in cal.summary()


def test_cli_full_poses_with_two_targets_report_orientation_fit_and_held_out(full, tmp_path, capsys):
    r, true, q, q_test = full
    rng = np.random.default_rng(34)

    def write(path, qq):
        frames = robot_frames(true, qq)
        y = measured(true, qq, TARGETS[:2]) + rng.normal(0, SIGMA, (len(qq), 2, 3))
        rot = _small_rotations(rng, len(qq), SIGMA_ROT) @ frames[:, :3, :3]
        # quaternion (w, x, y, z) of each rotation, w >= 0
        w = 0.5 * np.sqrt(np.maximum(1 + np.trace(rot, axis1=1, axis2=2), 0))
        quat = np.stack((w, (rot[:, 2, 1] - rot[:, 1, 2]) / (4 * w), (rot[:, 0, 2] - rot[:, 2, 0]) / (4 * w),
                         (rot[:, 1, 0] - rot[:, 0, 1]) / (4 * w)), 1)
        cols = [*r.joint_names, "x", "y", "z", "x2", "y2", "z2", "qw", "qx", "qy", "qz"]
        np.savetxt(path, np.hstack((qq, y.reshape(len(qq), 6), quat)), delimiter=",",
                   header=",".join(cols), comments="", fmt="%.17g")

    write(tmp_path / "fit.csv", q)
    write(tmp_path / "held.csv", q_test)
    assert main(["calibrate", "puma560", "--data", str(tmp_path / "fit.csv"), "--targets", "2",
                 "--validate", str(tmp_path / "held.csv"), "--sigma-rot", "0.1", "-o",
                 str(tmp_path / "o")]) == 0
    out = capsys.readouterr().out
    assert "orientation after:" in out and "orientation after calibration:" in out
    report = json.loads((tmp_path / "o" / "puma560_calibrated_report.json").read_text())
    assert report["orientation_after_rad"]["rms"] < 1.05 * np.sqrt(3) * SIGMA_ROT
    assert report["validation"]["orientation_after_rad"]["rms"] < 1.3 * np.sqrt(3) * SIGMA_ROT
    assert report["validation"]["after_m"]["rms"] < 1.3 * np.sqrt(3) * SIGMA
