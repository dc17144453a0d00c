"""Exact static deflection of compliant joints (``deflection="exact"``).

The truth is independent of :mod:`robodyn.numeric.deflection`: the link angles solve
``x = q - c * g(x)`` by plain fixed-point iteration (a contraction: ``|c dg/dq|`` is about 1e-2)
with ``g`` from ``rd.compile_model(robot).gravity``; the derivative ``dg/dq`` is checked against
central differences of that gravity, and the Jacobians against finite differences of the
predicted points.
"""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd
from robodyn.calibration import build_model, calibrate, robot_geometry
from robodyn.calibration.kinematics import trans
from robodyn.calibration.models import extend_model
from robodyn.calibration.nongeometric import build_nongeometric, gravity_torque, nominal_frames
from robodyn.numeric.deflection import exact_deflection
from robodyn.studies.calibration_study import perturbed_robot
from tests.calibration.helpers import TARGET, TRACKER, poses, robot
from tests.calibration.test_nongeometric import TARGETS, measured

#: Cobot-like compliances (stiffness 1e4 N m/rad), rad/(N m), PUMA 560 joints 1-6.
COBOT = np.array([1.0e-4, 1.2e-4, 0.8e-4, 1.5e-4, 1.1e-4, 0.9e-4])
#: Industrial-arm compliances (2-8 urad/(N m)).
STIFF = np.array([3e-6, 5e-6, 4e-6, 7e-6, 6e-6, 2e-6])


def true_link(r: rd.Robot, q: np.ndarray, c: np.ndarray) -> np.ndarray:
    """``x = q - c g(x)`` by fixed-point iteration to 1e-15 rad (independent of Newton's method)."""
    g = rd.compile_model(r).gravity
    x = q.copy()
    for _ in range(200):
        new = q - c * g(x)
        if np.max(np.abs(new - x)) < 1e-15:
            return new
        x = new
    raise AssertionError("fixed-point iteration did not converge")


@pytest.fixture(scope="module")
def puma():
    r = robot("puma560")
    ng = build_nongeometric(r, ("compliance",), nominal_frames(robot_geometry(r)), deflection="exact")
    return r, ng


def test_newton_solves_the_fixed_point_and_g_is_the_gravity_derivative(puma):
    r, ng = puma
    q = poses("puma560", 40, 31)
    d = exact_deflection(q, COBOT, ng.exact_torque, ng.torque_jacobian)
    g = rd.compile_model(r).gravity
    assert np.max(np.abs(d.q_link - q + COBOT * g(d.q_link))) < 1e-12
    # the calibration's own numeric gravity (no compiled model) holds the same equilibrium
    assert np.max(np.abs(d.q_link - q + COBOT * gravity_torque(r)(d.q_link))) < 1e-12
    assert np.max(np.abs(d.q_link - true_link(r, q, COBOT))) < 1e-13
    assert 1 <= d.iterations <= 6
    # the linear model differs by ~C G C tau: tens of microradians here
    linear_error = np.max(np.abs(d.q_link - (q - COBOT * g(q))))
    assert 1e-6 < linear_error < 1e-3
    # G from inverse_dynamics_derivatives(q, 0, 0) against central differences of g
    big_g = ng.torque_jacobian(q)
    h = 1e-6
    fd = np.stack([(g(q + h * e) - g(q - h * e)) / (2 * h) for e in np.eye(6)], axis=2)
    scale = np.max(np.abs(big_g))
    assert scale > 10.0
    np.testing.assert_allclose(big_g, fd, rtol=0, atol=1e-7 * scale)


@pytest.mark.slow
@pytest.mark.parametrize("payload", [None, (3.0, (0.02, -0.03, 0.11))])
def test_jacobian_of_the_predicted_points_matches_finite_differences(payload):
    r = robot("puma560")
    geometry = robot_geometry(r)
    ng = build_nongeometric(r, ("compliance", "harmonics"), nominal_frames(geometry), payload=payload,
                            deflection="exact")
    target = TRACKER @ geometry.target @ trans(*TARGET)  # off the wrist centre: every joint moves it
    em = extend_model(build_model("s-model", geometry, base=TRACKER, target=target), None, ng)
    p = em.initial.copy()
    sl = em.nongeometric_slice
    rng = np.random.default_rng(4)
    theta = np.where(np.array(ng.kinds) == "compliance", 0.0, rng.normal(0, 1e-3, ng.n_params))
    theta[np.array(ng.kinds) == "compliance"] = COBOT
    p[sl] = theta
    q = poses("puma560", 12, 32)
    jac = em.evaluate(p, q).jac_param[:, :3, sl]  # position rows
    checked = 0
    for k in range(ng.n_params):
        # five-point central differences, O(h^4): a step large enough that round-off of the
        # ~2 m positions (eps |p| / h) stays far below 1e-6 of the column
        h = 1e-4  # x(c) is analytic with radius ~ 1 / |G| ~ 2e-2 rad/(N m): truncation ~ (h / 2e-2)^4

        def pos(step, k=k):
            pk = p.copy()
            pk[sl.start + k] += step
            return em.evaluate(pk, q, derivatives=False).position

        fd = (-pos(2 * h) + 8 * pos(h) - 8 * pos(-h) + pos(-2 * h)) / (12 * h)
        norm = np.max(np.abs(fd))
        # round-off of the stencil: ~eps |p| / h (1e-11 here); columns far above it are held to
        # 1e-6 relative, the few that are not (unloaded joints, e.g. q1 and the wrist without
        # payload, whose compliance moves the target by < 1e-7 m per 1e-4 rad/(N m)) to that floor
        floor = 10 * np.finfo(float).eps * np.max(np.abs(pos(0.0))) / h
        err = np.max(np.abs(jac[:, :, k] - fd))
        if norm > 1e5 * floor:
            assert err < 1e-6 * norm, ng.names[k]
            checked += 1
        else:
            assert err < 10 * floor, ng.names[k]
    assert checked >= 20


def _fit(r, q, y, deflection):
    return calibrate(r, q, y, "s-model", nongeometric=("compliance",), deflection=deflection,
                     sigma=5e-6)


@pytest.mark.filterwarnings("ignore:calibration of puma560. the variance factor")
def test_exact_model_recovers_cobot_compliance_where_the_linear_one_cannot():
    r = robot("puma560")
    true = perturbed_robot(r, 7, base=TRACKER, target=(0.0, 0.0, 0.0))
    q = poses("puma560", 120, 33)
    y = measured(true, true_link(r, q, COBOT), TARGETS)
    exact = _fit(r, q, y, "exact")
    linear = _fit(r, q, y, "linear")
    assert exact.converged
    assert exact.nongeometric["deflection"] == "exact"
    found = {p.name: p.value for p in exact.parameters}
    checked = 0
    for j, joint in enumerate(r.joints):
        name = f"{joint.name}.compliance"
        if name in found:
            assert found[name] == pytest.approx(COBOT[j], rel=1e-6), name
            checked += 1
    assert checked >= 4  # q1 (vertical axis) and q6 (no torque without payload) are unidentifiable
    assert exact.after.rms < 1e-9
    # the linear model leaves a systematic residual (about 10 um RMS here, see docs/calibration.md)
    assert linear.after.rms > 1e-6
    assert linear.after.rms > 1000 * exact.after.rms
    fl = {p.name: p.value for p in linear.parameters}
    print("linear estimates / true:", {k: round(fl[k] / found[k], 4) for k in found if k in fl
                                       and k.endswith("compliance")})
    print(f"cobot compliance: RMS residual exact {exact.after.rms:.3g} m, linear {linear.after.rms:.3g} m, "
          f"max linear {linear.after.max:.3g} m")


@pytest.mark.filterwarnings("ignore:calibration of puma560. the variance factor")
def test_small_compliance_both_models_agree():
    r = robot("puma560")
    true = perturbed_robot(r, 7, base=TRACKER, target=(0.0, 0.0, 0.0))
    q = poses("puma560", 120, 34)
    y = measured(true, true_link(r, q, STIFF), TARGETS)
    exact = _fit(r, q, y, "exact")
    linear = _fit(r, q, y, "linear")
    fe = {p.name: p.value for p in exact.parameters}
    fl = {p.name: p.value for p in linear.parameters}
    for j, joint in enumerate(r.joints):
        name = f"{joint.name}.compliance"
        if name in fe:
            assert fe[name] == pytest.approx(STIFF[j], rel=1e-6), name
            # the linear model's estimates carry the second-order bias: small for the loaded
            # shoulder and elbow; the lightly loaded wrist joints (torques of a few N m) absorb
            # more of it relative to their value (q4 about 10 % here), invisibly in position
            if j in (1, 2):
                assert fl[name] == pytest.approx(STIFF[j], rel=1e-3), name
    # second-order effect c G c tau ~ 1e-7 rad: far under a tracker's noise (~1e-5 m)
    assert linear.after.rms < 1e-7
    diff = np.max(np.abs(exact.predict(q) - linear.predict(q)))
    assert diff < 1e-7
    print(f"industrial compliance: RMS residual exact {exact.after.rms:.3g} m, linear "
          f"{linear.after.rms:.3g} m, max prediction difference {diff:.3g} m")


def test_bad_combinations_are_refused():
    r = robot("puma560")
    q = poses("puma560", 30, 35)
    y = np.zeros((30, 3))
    with pytest.raises(ValueError, match="deflection must be"):
        calibrate(r, q, y, nongeometric=("compliance",), deflection="quadratic")
    with pytest.raises(ValueError, match="needs the 'compliance' term"):
        calibrate(r, q, y, nongeometric=("harmonics",), deflection="exact")
    geometry = robot_geometry(r)
    with pytest.raises(ValueError, match="identify_payload"):
        build_nongeometric(r, ("compliance",), nominal_frames(geometry), identify_payload=True,
                           deflection="exact")


@pytest.mark.filterwarnings("ignore:calibration of puma560. the variance factor")
def test_cli_deflection_exact_matches_the_api(tmp_path):
    import csv
    import json

    from robodyn.cli import main

    r = robot("puma560")
    true = perturbed_robot(r, 7, base=TRACKER, target=(0.0, 0.0, 0.0))
    q = poses("puma560", 60, 36)
    y = measured(true, true_link(r, q, COBOT), TARGETS[:1])[:, 0]
    path = tmp_path / "poses.csv"
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow([*r.joint_names, "x", "y", "z"])
        w.writerows([[repr(float(v)) for v in row] for row in np.hstack((q, y))])
    assert main(["calibrate", "puma560", "--data", str(path), "--nongeometric", "compliance",
                 "--deflection", "exact", "--sigma", "0.005", "-o", str(tmp_path)]) == 0
    report = json.loads((tmp_path / "puma560_calibrated_report.json").read_text())
    assert report["nongeometric"]["deflection"] == "exact"
    api = calibrate(r, q, y, "s-model", nongeometric=("compliance",), deflection="exact", sigma=5e-6)
    cli = {p["name"]: p["value"] for p in report["parameters"]}
    for p in api.parameters:
        if p.name.endswith("compliance"):
            assert cli[p.name] == pytest.approx(p.value, rel=1e-9), p.name
            assert p.value == pytest.approx(COBOT[r.joint_names.index(p.name[:2])], rel=1e-6)
