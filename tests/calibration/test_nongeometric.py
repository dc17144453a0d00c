"""Non-geometric terms (compliance, transmission errors) and several targets per pose.

The truth is written independently of the error models' non-geometric code: the link angles are
``q - c * g(q) + k q + a cos q + b sin q + a' cos(G q) + b' sin(G q)`` with ``g`` from
``rd.compile_model(robot).gravity``, and the targets are the true robot's tool frame applied to
each target offset.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import robodyn as rd
from robodyn.calibration import calibrate, validate
from robodyn.studies.calibration_study import perturbed_robot, robot_frames
from tests.calibration.helpers import TRACKER, poses, robot

#: Target offsets on the flange (three reflectors), m.
TARGETS = np.array([[0.031, -0.018, 0.076], [-0.045, 0.052, 0.060], [0.060, 0.040, 0.030]])


def true_terms(r: rd.Robot, seed: int = 5) -> dict[str, float]:
    """Compliance (rad/(N m)), ratio error and harmonic amplitudes (rad) of a plausible arm."""
    rng = np.random.default_rng(seed)
    out = {}
    for j in r.joints:
        out[f"{j.name}.compliance"] = float(rng.uniform(2e-6, 8e-6))
        out[f"{j.name}.ratio"] = float(rng.normal(0, 2e-4))
        for h in ("cos1", "sin1", "motor_cos1", "motor_sin1"):
            out[f"{j.name}.{h}"] = float(rng.normal(0, 1e-4 if "motor" not in h else 2e-5))
    return out


def link_angles(r: rd.Robot, q: np.ndarray, terms: dict[str, float]) -> np.ndarray:
    """True link angles for readings ``q`` (N, n): the deflection and transmission errors added."""
    g = rd.compile_model(r).gravity(q)
    gear = np.array([float(j.drive.gear_ratio.xreplace(r.defaults())) for j in r.joints])
    out = q.copy()
    for i, j in enumerate(r.joints):
        c = terms.get(f"{j.name}.compliance", 0.0)
        qi = q[:, i]
        out[:, i] += (-c * g[:, i] + terms.get(f"{j.name}.ratio", 0.0) * qi
                      + terms.get(f"{j.name}.cos1", 0.0) * np.cos(qi)
                      + terms.get(f"{j.name}.sin1", 0.0) * np.sin(qi)
                      + terms.get(f"{j.name}.motor_cos1", 0.0) * np.cos(gear[i] * qi)
                      + terms.get(f"{j.name}.motor_sin1", 0.0) * np.sin(gear[i] * qi))
    return out


def measured(true: rd.Robot, q_link: np.ndarray, targets: np.ndarray) -> np.ndarray:
    """Noise-free positions (N, K, 3) of ``targets`` (K, 3) on the true robot's tool frame."""
    frames = robot_frames(true, q_link)
    return np.einsum("nij,kj->nki", frames[:, :3, :3], targets) + frames[:, None, :3, 3]


@pytest.fixture(scope="module")
def puma_truth():
    r = robot("puma560")
    true = perturbed_robot(r, 7, base=TRACKER, target=(0.0, 0.0, 0.0))
    return r, true, true_terms(r)


@pytest.mark.filterwarnings("ignore:calibration of puma560. the variance factor")
def test_compliance_and_harmonics_recovered_from_noise_free_data(puma_truth):
    r, true, terms = puma_truth
    q, q_test = poses("puma560", 150, 11), poses("puma560", 60, 12)
    y = measured(true, link_angles(r, q, terms), TARGETS)
    cal = calibrate(r, q, y, "s-model", nongeometric=("compliance", "harmonics"))
    assert cal.converged
    found = {p.name: p.value for p in cal.parameters}
    unid = {u.name for u in cal.unidentifiable}
    checked = 0
    for name, value in terms.items():
        if name in found:
            assert found[name] == pytest.approx(value, rel=1e-6, abs=1e-12), name
            checked += 1
        else:
            assert name in unid, f"{name} neither identified nor reported unidentifiable"
    # joint 1 is vertical (no gravity torque) so its compliance cannot be seen: reported, not fitted
    assert "q1.compliance" in unid
    assert checked >= 25
    for name in ("q2.compliance", "q3.compliance", "q1.cos1", "q6.motor_sin1", "q3.ratio"):
        assert name in found
    # all targets' offsets recovered (in the model's last frame, so compared by their distances)
    off = cal.target_offsets()
    np.testing.assert_allclose(np.linalg.norm(off[:, None] - off[None], axis=2),
                               np.linalg.norm(TARGETS[:, None] - TARGETS[None], axis=2), atol=1e-9)
    y_test = measured(true, link_angles(r, q_test, terms), TARGETS)
    pred = cal.predict(q_test)
    assert pred.shape == y_test.shape == (60, 3, 3)
    assert np.abs(pred - y_test).max() < 1e-9
    assert validate(cal, q_test, y_test).max < 1e-9


@pytest.mark.filterwarnings("ignore:calibration of puma560. the variance factor")
def test_cached_numbers_calibrate_as_the_robot_itself(puma_truth, tmp_path, monkeypatch):
    """``robodyn calibrate`` passes the robot's numbers read from the cache (no SymPy before the
    solve): the same fit, bit for bit, with compliance (masses, gravity) and harmonics (gear
    ratios) read from them, and the same calibrated description after it."""
    from robodyn.robot.numbers_cache import load_numbers

    monkeypatch.setenv("ROBODYN_CACHE", str(tmp_path))
    r, true, terms = puma_truth
    load_numbers("puma560")
    numbers = load_numbers("puma560")
    assert numbers.loader is not None and len(list(tmp_path.glob("rd_robot_*.json"))) == 1
    q = poses("puma560", 150, 11)
    y = measured(true, link_angles(r, q, terms), TARGETS)
    kw = {"nongeometric": ("compliance", "harmonics")}
    a, b = calibrate(r, q, y, "s-model", **kw), calibrate(numbers, q, y, "s-model", **kw)
    np.testing.assert_array_equal(a.params, b.params)
    assert b.parameters == a.parameters
    assert b.robot.description_hash == a.robot.description_hash
    assert b.before_robot.description_hash == a.before_robot.description_hash
    found = {p.name: p.value for p in b.parameters}
    assert found["q2.compliance"] == pytest.approx(terms["q2.compliance"], rel=1e-6)
    assert found["q6.motor_sin1"] == pytest.approx(terms["q6.motor_sin1"], rel=1e-6, abs=1e-12)


def test_geometric_model_cannot_absorb_the_terms(puma_truth):
    r, true, terms = puma_truth
    q = poses("puma560", 150, 11)
    y = measured(true, link_angles(r, q, terms), TARGETS)
    cal = calibrate(r, q, y, "s-model", sigma=1e-5)
    assert cal.after.rms > 1e-5  # 0.01 mm: the non-geometric errors stay in the residuals


@pytest.mark.filterwarnings("ignore:calibration of puma560. the variance factor")
def test_single_target_shape_and_multi_target_first_column_agree(puma_truth):
    r, true, _ = puma_truth
    q = poses("puma560", 60, 3)
    y = measured(true, q, TARGETS)
    one = calibrate(r, q, y[:, 0], "hayati")
    both = calibrate(r, q, y, "hayati")
    assert one.predict(q).shape == (60, 3) and one.residuals.shape == (60, 3)
    assert both.predict(q).shape == (60, 3, 3) and both.residuals.shape == (60, 3, 3)
    assert np.abs(both.predict(q)[:, 0] - one.predict(q)).max() < 1e-9
    assert both.before_residuals.shape == (60, 3, 3)


def test_gravity_shaped_basis_without_masses():
    """A description without masses: the documented point-mass basis, checked by a closed form."""
    r = robot("puma560")
    massless = dataclasses.replace(r, links=tuple(dataclasses.replace(link, mass=0 * link.mass)
                                                  for link in r.links))
    from robodyn.calibration.nominal import robot_geometry
    from robodyn.calibration.nongeometric import build_nongeometric, nominal_frames

    ng = build_nongeometric(massless, ("compliance",), nominal_frames(robot_geometry(massless)))
    assert ng.torque_source == "gravity-shaped basis"
    q = poses("puma560", 5, 4)
    tau = ng.torque(q)
    # finite-difference oracle: potential V = sum_k 9.81 z_k of unit masses at the joint origins
    # after joint 1 and the tool; tau = dV/dq
    def potential(qq):
        from robodyn.calibration.kinematics import evaluate
        from robodyn.calibration.models import build_model

        chain = build_model("hayati", robot_geometry(massless), orientation=True)
        ev, rec = evaluate(chain.ops, chain.initial, qq, derivatives=False, frames_after=chain.joint_ops)
        z = sum(f[:, 2, 3] for f in rec[1:]) + ev.position[:, 2]
        return 9.81 * z

    h = 1e-6
    for j in range(6):
        dq = np.zeros(6)
        dq[j] = h
        fd = (potential(q + dq) - potential(q - dq)) / (2 * h)
        np.testing.assert_allclose(tau[:, j], fd, atol=1e-6)


def test_bad_input_messages():
    r = robot("puma560")
    q = poses("puma560", 20, 1)
    y = np.zeros((20, 2, 3))
    with pytest.raises(ValueError, match="unknown non-geometric term 'backlash'"):
        calibrate(r, q, y + np.arange(20)[:, None, None] * 0.01, nongeometric=("backlash",))
    with pytest.raises(ValueError, match=r"points must have shape \(N, 3\) or \(N, K, 3\)"):
        calibrate(r, q, np.zeros((20, 2, 4)))
    # several targets with orientations are fine (test_full_pose.py); one orientation per pose
    with pytest.raises(ValueError, match=r"orientations must have shape \(20, 3, 3\); got \(40, 3, 3\)"):
        calibrate(r, q, np.zeros((20, 2, 3)), orientations=np.broadcast_to(np.eye(3), (40, 3, 3)))


@pytest.mark.filterwarnings("ignore:calibration of puma560. the variance factor")
def test_millimetres_declared_as_metres_is_detected(puma_truth):
    r, true, _ = puma_truth
    q = poses("puma560", 30, 3)
    y = measured(true, q, TARGETS[:1])[:, 0]
    with pytest.raises(ValueError, match="look like millimetres.*length_unit='mm'"):
        calibrate(r, q, y * 1e3, "hayati")
    # the same data declared as mm (and readings in degrees) give the SI calibration exactly
    ref = calibrate(r, q, y, "hayati")
    mm = calibrate(r, np.degrees(q), y * 1e3, "hayati", length_unit="mm", angle_unit="deg",
                   sigma=5e-2)
    np.testing.assert_allclose(mm.params, ref.params, atol=1e-9)
    assert mm.after.rms == pytest.approx(ref.after.rms, abs=1e-12)


def test_sigma_warning_when_variance_factor_contradicts_it(puma_truth):
    r, true, _ = puma_truth
    q = poses("puma560", 60, 3)
    y = measured(true, q, TARGETS[:1])[:, 0] + np.random.default_rng(0).normal(0, 5e-4, (60, 3))
    with pytest.warns(RuntimeWarning, match="sigma is wrong by a factor of about"):
        calibrate(r, q, y, "hayati", sigma=5e-5)


def test_noise_level_reached_only_with_the_terms(puma_truth):
    """Simulated tracker data with compliance and transmission errors in the truth."""
    r, true, terms = puma_truth
    sigma = 5e-5
    rng = np.random.default_rng(21)
    q, q_test = poses("puma560", 300, 31), poses("puma560", 200, 32)
    y = measured(true, link_angles(r, q, terms), TARGETS) + rng.normal(0, sigma, (300, 3, 3))
    y_test = measured(true, link_angles(r, q_test, terms), TARGETS) + rng.normal(0, sigma, (200, 3, 3))
    noise = sigma * math.sqrt(3)
    combined = calibrate(r, q, y, "s-model", sigma=sigma, nongeometric=("compliance", "harmonics"))
    with pytest.warns(RuntimeWarning, match="variance factor"):
        geometric = calibrate(r, q, y, "s-model", sigma=sigma)
    held_c = validate(combined, q_test, y_test).rms
    held_g = validate(geometric, q_test, y_test).rms
    print(f"held-out RMS: combined {held_c * 1e3:.4f} mm ({held_c / noise:.3f} x noise), "
          f"geometric only {held_g * 1e3:.4f} mm ({held_g / noise:.3f} x noise)")
    assert held_c < 1.3 * noise
    assert held_g > 1.3 * noise


@pytest.mark.parametrize(("declared", "warns"), [(5e-4, True), (1e-5, True), (1e-4, False), (3e-5, False)])
def test_sigma_warning_both_ways_and_only_beyond_3x(puma_truth, declared, warns):
    """Noise 0.05 mm: declared 10x too large or 5x too small warns; 2x or 0.6x does not."""
    import warnings

    r, true, _ = puma_truth
    q = poses("puma560", 80, 4)
    y = measured(true, q, TARGETS[:1])[:, 0] + np.random.default_rng(1).normal(0, 5e-5, (80, 3))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        calibrate(r, q, y, "s-model", sigma=declared)
    said = [str(w.message) for w in caught if "variance factor" in str(w.message)]
    assert bool(said) == warns, said
    if warns:
        assert ("smaller" if declared > 5e-5 else "larger") in said[0]
