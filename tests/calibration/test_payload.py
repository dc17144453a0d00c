"""Payload in the compliance model: known (mass and centre of mass in the tool frame) and identified.

The truth is independent of :mod:`robodyn.calibration.nongeometric`: the joints deflect by
``-c_j (g_j(q) + tau_p,j(q))`` with ``g`` from ``rd.compile_model(robot).gravity`` and the
payload's holding torque ``tau_p = dV/dq`` taken by central differences of its potential energy
``V = -m gravity . p(q)``, ``p`` the payload's centre on the nominal tool frame.
"""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd
from robodyn.calibration import calibrate, validate
from robodyn.studies.calibration_study import perturbed_robot, robot_frames
from tests.calibration.helpers import TRACKER, poses, robot
from tests.calibration.test_nongeometric import TARGETS, measured, true_terms

MASS, COM = 4.5, np.array([0.02, -0.03, 0.11])  # kg; m, tool frame


def payload_torque(r: rd.Robot, q: np.ndarray, mass: float, com: np.ndarray, h: float = 1e-5) -> np.ndarray:
    """``dV/dq`` (N, n) of a point mass ``mass`` at ``com`` (tool frame), central differences."""
    g = np.array(r.gravity.xreplace(r.defaults()), dtype=float).ravel()

    def energy(qq):
        f = robot_frames(r, qq)
        return -mass * (f[:, :3, :3] @ com + f[:, :3, 3]) @ g

    out = np.zeros_like(q)
    for j in range(q.shape[1]):
        dq = np.zeros(q.shape[1])
        dq[j] = h
        out[:, j] = (energy(q + dq) - energy(q - dq)) / (2 * h)
    return out


@pytest.fixture(scope="module")
def loaded():
    r = robot("puma560")
    true = perturbed_robot(r, 7, base=TRACKER, target=(0.0, 0.0, 0.0))
    terms = {k: v for k, v in true_terms(r).items() if k.endswith("compliance")}
    c = np.array([terms[f"{j.name}.compliance"] for j in r.joints])
    q, q_test = poses("puma560", 150, 21), poses("puma560", 60, 22)

    def link(qq):
        tau = rd.compile_model(r).gravity(qq) + payload_torque(r, qq, MASS, COM)
        return qq - c * tau

    return r, true, terms, q, q_test, measured(true, link(q), TARGETS), measured(true, link(q_test), TARGETS)


def _check_compliance(cal, terms):
    found = {p.name: p.value for p in cal.parameters}
    checked = [k for k in terms if k in found]
    assert len(checked) >= 4  # q1's is unidentifiable (its axis is parallel to gravity)
    for k in checked:
        assert found[k] == pytest.approx(terms[k], rel=1e-6), k
    return found


@pytest.mark.filterwarnings("ignore:calibration of puma560. the variance factor")
def test_known_payload_gives_the_compliances(loaded):
    r, _, terms, q, q_test, y, y_test = loaded
    cal = calibrate(r, q, y, "s-model", nongeometric=("compliance",), payload=(MASS, COM))
    assert cal.nongeometric["torque_source"] == "gravity model + payload"
    _check_compliance(cal, terms)
    assert validate(cal, q_test, y_test).rms < 1e-9
    # ignoring the payload, the same model cannot fit these data
    blind = calibrate(r, q, y, "s-model", nongeometric=("compliance",))
    assert validate(blind, q_test, y_test).rms > 1e-5


@pytest.mark.filterwarnings("ignore:calibration of puma560. the variance factor")
def test_identified_payload_is_recovered(loaded):
    r, _, terms, q, q_test, y, y_test = loaded
    cal = calibrate(r, q, y, "s-model", nongeometric=("compliance",), identify_payload=True)
    assert cal.converged
    found = _check_compliance(cal, terms)
    # the wrist's last joint carries no torque from the arm itself, only the payload's
    assert "q6.compliance" in found
    assert found["payload.mass"] == pytest.approx(MASS, rel=1e-6)
    moments = np.array([found[f"payload.m{a}"] for a in "xyz"])
    np.testing.assert_allclose(moments / found["payload.mass"], COM, rtol=0, atol=1e-6)
    assert validate(cal, q_test, y_test).rms < 1e-9
    assert cal.nongeometric["torque_source"] == "gravity model + identified payload"


def test_identify_payload_needs_compliance():
    r = robot("puma560")
    q = poses("puma560", 30, 1)
    y = measured(r, q, TARGETS[:1])[:, 0]
    with pytest.raises(ValueError, match="identify_payload needs the 'compliance' term"):
        calibrate(r, q, y, "s-model", nongeometric=("harmonics",), identify_payload=True)
    with pytest.raises(ValueError, match="identify_payload needs the 'compliance' term"):
        calibrate(r, q, y, "s-model", identify_payload=True)
    with pytest.raises(ValueError, match="payload needs the 'compliance' term"):
        calibrate(r, q, y, "s-model", payload=(2.0, (0.0, 0.0, 0.1)))


@pytest.mark.slow
@pytest.mark.filterwarnings("ignore:calibration of puma560. the variance factor")
def test_cli_payload_options(loaded, tmp_path, capsys):
    import json

    from robodyn.cli import main

    r, _, _, q, _, y, _ = loaded
    path = tmp_path / "poses.csv"
    cols = [*r.joint_names] + [f"{a}{k if k > 1 else ''}" for k in (1, 2, 3) for a in "xyz"]
    np.savetxt(path, np.hstack((q, y.reshape(len(q), -1))), delimiter=",", header=",".join(cols),
               comments="", fmt="%.17g")
    base = ["calibrate", "puma560", "--data", str(path), "--nongeometric", "compliance"]
    assert main([*base, "--identify-payload", "-o", str(tmp_path / "a")]) == 0
    report = json.loads((tmp_path / "a" / "puma560_calibrated_report.json").read_text())
    values = {p["name"]: p["value"] for p in report["nongeometric"]["parameters"]}
    assert values["payload.mass"] == pytest.approx(MASS, rel=1e-6)
    assert main([*base, "--payload", f"{MASS},{COM[0]},{COM[1]},{COM[2]}", "-o", str(tmp_path / "b")]) == 0
    report = json.loads((tmp_path / "b" / "puma560_calibrated_report.json").read_text())
    assert report["nongeometric"]["torque_source"] == "gravity model + payload"
    capsys.readouterr()
    assert main([*base, "--payload", "4.5,0.1", "-o", str(tmp_path / "c")]) == 2
    assert "--payload: expected 4 numbers" in capsys.readouterr().err


@pytest.mark.parametrize("name", ["puma560", "planar_2r"])
def test_numeric_gravity_equals_the_compiled_models(name):
    from robodyn.calibration import random_configurations
    from robodyn.calibration.nongeometric import gravity_torque

    r = robot(name)
    q = random_configurations(r, 40, 3)
    expected = rd.compile_model(r).gravity(q)
    np.testing.assert_allclose(gravity_torque(r)(q), expected, rtol=0, atol=1e-12 * np.abs(expected).max())


def test_compliance_compiles_nothing():
    import json
    import subprocess
    import sys

    code = ("import warnings, numpy as np, robodyn as rd\nwarnings.simplefilter('ignore')\n"
            "from robodyn.calibration import calibrate, random_configurations\n"
            "r = rd.load('puma560'); q = random_configurations(r, 40, 1)\n"
            "from robodyn.studies.calibration_study import robot_positions\n"
            "calibrate(r, q, robot_positions(r, q), 'hayati', nongeometric=('compliance',))\n"
            "import sys, json; print(json.dumps(sorted(m for m in ('cffi', 'robodyn.numeric.model',"
            " 'robodyn.codegen.build') if m in sys.modules)))")
    out = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True)
    assert json.loads(out.stdout.strip().splitlines()[-1]) == []
