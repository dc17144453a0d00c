"""A calibrated description with non-geometric terms, loaded alone, predicts what the calibration did.

The written YAML is read back from disk with ``rd.load`` and evaluated by the compiled model's
forward kinematics (``rd.compile_model(robot).forward_kinematics``), which knows nothing of the
calibration. Two references: ``cal.predict`` (to 1e-9 m), and, for noise-free data, the truth of
tests/calibration/test_nongeometric.py and test_payload.py (link angles from the compiled gravity
model and hand-written harmonics, independent of the corrections code).
"""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np
import pytest

import robodyn as rd
from robodyn.calibration import calibrate
from robodyn.calibration.io import write_calibration
from robodyn.studies.calibration_study import perturbed_robot
from tests.calibration.helpers import TRACKER, poses, robot
from tests.calibration.test_nongeometric import link_angles, measured, true_terms
from tests.calibration.test_payload import COM, MASS, payload_torque

pytestmark = pytest.mark.filterwarnings("ignore:calibration of puma560. the variance factor")


def _written(cal, tmp_path) -> rd.Robot:
    paths = write_calibration(cal, tmp_path)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the PUMA's documented inertia quirks
        return rd.load(str(paths["yaml"]))


def _world(model, q):
    """Tool positions (N, 3) of a loaded description (its base is the instrument placement)."""
    return model.forward_kinematics(q)[:, :3, 3]


@pytest.fixture(scope="module")
def puma():
    r = robot("puma560")
    true = perturbed_robot(r, 7, base=TRACKER, target=(0.0, 0.0, 0.0))
    return r, true, true_terms(r), poses("puma560", 80, 11), poses("puma560", 40, 12)


@pytest.mark.parametrize("deflection", ["linear", pytest.param("exact", marks=pytest.mark.slow)])
def test_written_description_reproduces_predict(puma, tmp_path, deflection):
    r, true, terms, q, q_test = puma
    y = measured(true, link_angles(r, q, terms), np.zeros((1, 3)))[:, 0]
    cal = calibrate(r, q, y, "s-model", nongeometric=("compliance", "harmonics"), deflection=deflection)
    loaded = _written(cal, tmp_path)
    assert loaded.corrections is not None and loaded.corrections.deflection == deflection
    model = rd.compile_model(loaded)
    pred = cal.predict(q_test)
    np.testing.assert_allclose(_world(model, q_test), pred, rtol=0, atol=1e-9)
    if deflection == "linear":  # the data's own model: the truth is reproduced as well
        truth = measured(true, link_angles(r, q_test, terms), np.zeros((1, 3)))[:, 0]
        np.testing.assert_allclose(_world(model, q_test), truth, rtol=0, atol=1e-9)
    # the geometry alone (what a URDF holds) does not: the terms move the tool by millimetres
    rigid = rd.compile_model(dataclasses.replace(loaded, corrections=None))
    assert np.abs(_world(rigid, q_test) - pred).max() > 1e-4


def test_jacobian_is_with_respect_to_the_readings(puma, tmp_path):
    r, true, terms, q, _ = puma
    y = measured(true, link_angles(r, q, terms), np.zeros((1, 3)))[:, 0]
    cal = calibrate(r, q, y, "s-model", nongeometric=("compliance", "harmonics"))
    model = rd.compile_model(_written(cal, tmp_path))
    x = q[:4]
    jac = model.jacobian(x)
    h = 1e-6
    for k in range(6):
        e = np.zeros(6)
        e[k] = h
        fd = (_world(model, x + e) - _world(model, x - e)) / (2 * h)
        np.testing.assert_allclose(jac[:, :3, k], fd, rtol=0, atol=1e-7)
    # the rigid Jacobian at the readings differs by the corrections' derivative (ratio errors)
    rigid = rd.compile_model(dataclasses.replace(model.robot, corrections=None)).jacobian(x)
    assert np.abs(rigid - jac).max() > 1e-6


@pytest.mark.slow
def test_identified_payload_and_its_compliances_carried(tmp_path):
    r = robot("puma560")
    true = perturbed_robot(r, 7, base=TRACKER, target=(0.0, 0.0, 0.0))
    c = np.array([v for k, v in true_terms(r).items() if k.endswith("compliance")])
    q, q_test = poses("puma560", 80, 21), poses("puma560", 40, 22)

    def link(qq):
        return qq - c * (rd.compile_model(r).gravity(qq) + payload_torque(r, qq, MASS, COM))

    y = measured(true, link(q), np.zeros((1, 3)))[:, 0]
    cal = calibrate(r, q, y, "s-model", nongeometric=("compliance",), identify_payload=True)
    loaded = _written(cal, tmp_path)
    assert loaded.corrections.holding.source == "gravity model + identified payload"
    model = rd.compile_model(loaded)
    truth = measured(true, link(q_test), np.zeros((1, 3)))[:, 0]
    np.testing.assert_allclose(_world(model, q_test), cal.predict(q_test), rtol=0, atol=1e-9)
    np.testing.assert_allclose(_world(model, q_test), truth, rtol=0, atol=1e-9)


def test_gravity_shaped_basis_carried(puma, tmp_path):
    r, true, terms, q, q_test = puma
    massless = dataclasses.replace(r, links=tuple(dataclasses.replace(link, mass=0 * link.mass)
                                                  for link in r.links))
    y = measured(true, link_angles(r, q, terms), np.zeros((1, 3)))[:, 0]
    cal = calibrate(massless, q, y, "s-model", nongeometric=("compliance",))
    loaded = _written(cal, tmp_path)
    assert loaded.corrections.holding.source == "gravity-shaped basis"
    from robodyn.calibration.frames import robot_positions  # no masses: no dynamics to compile

    np.testing.assert_allclose(robot_positions(loaded, q_test), cal.predict(q_test), rtol=0, atol=1e-9)
    np.testing.assert_allclose(rd.compile_model(loaded).forward_kinematics(q_test)[:, :3, 3],
                               cal.predict(q_test), rtol=0, atol=1e-9)
