"""An underwater arm identified with its description's hydrodynamic torque taken as known
(robodyn.identification.hydro_load): simulated ``underwater_2r`` runs, the plant being the
description itself, so its own inverse dynamics is the independent reference."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

import robodyn as rd
from robodyn.identification.hydro_load import hydro_load
from tests.identification.helpers import fourier, load_quiet


@pytest.fixture(scope="module")
def wet():
    robot = load_quiet("underwater_2r")
    return robot, rd.compile_model(robot)


def _run(model, seed: int) -> rd.Recording:
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, 30.0, 0.01)
    q, qd, qdd = fourier(t, model.dof, rng, f0=1 / 30)
    tau = model.inverse_dynamics(q, qd, qdd) + 0.05 * rng.standard_normal((t.size, model.dof))
    return rd.Recording(t=t, q=q, tau=tau, joint_names=model.robot.joint_names, source=f"run{seed}")


def _error(pred: np.ndarray, rec: rd.Recording) -> float:
    return float(np.linalg.norm(pred - rec.tau) / np.linalg.norm(rec.tau))


def test_the_fluid_torque_is_taken_as_known_and_the_written_robot_predicts_alike(wet):
    robot, model = wet
    fit, check = _run(model, 1), _run(model, 2)
    ident = rd.identify(robot, fit, model=model)
    assert ident.hydro is not None
    # the fluid's share is large here: the description without it misses by 0.8
    dry = replace(robot, links=tuple(replace(link, hydro=None) for link in robot.links), fluid=None)
    assert _error(rd.compile_model(dry).inverse_dynamics(check.q, check.qd, check.qdd), check) > 0.3
    # with it known, the fit predicts another run to the noise (before: 0.13, the fluid absorbed
    # into the rigid body and friction), and the written robot, which keeps the hydrodynamic
    # blocks with their values, predicts alike (before: it did not compile, its blocks' named
    # coefficients dropped; then 0.87, the fluid counted twice)
    assert _error(ident.predict(check), check) < 0.01
    assert all(link.hydro is not None for link in ident.robot.links)
    validated = rd.validate(ident.robot, check, "tau", window=None).predicted
    assert _error(validated, check) < 0.01


def test_a_dry_robot_has_no_hydrodynamic_load():
    robot = load_quiet("planar_2r")
    assert hydro_load(robot, None) is None


def test_a_current_target_takes_the_fluid_through_the_fits_gains(wet):
    # the description has no drive data (gains absorbed); the plant's drives turn 40 and 25 N m
    # into one ampere: the fluid's torque enters the current through the gains the fit finds,
    # as a payload's does (before: subtracted as if 1 N m were 1 A, and predict missed another
    # run's current by far more than its noise)
    robot, model = wet
    gains = np.array([40.0, 25.0])

    def current(rec: rd.Recording, seed: int) -> rd.Recording:
        noise = 0.002 * np.random.default_rng(seed).standard_normal(rec.tau.shape)
        return rd.Recording(t=rec.t, q=rec.q, current=rec.tau / gains + noise,
                            joint_names=rec.joint_names, source=rec.source)

    fit, check = current(_run(model, 1), 1), current(_run(model, 2), 2)
    ident = rd.identify(robot, fit, target="current", model=model)
    assert ident.gains_source.startswith("absorbed")
    err = np.linalg.norm(ident.predict(check) - check.current) / np.linalg.norm(check.current)
    assert err < 0.02
    validated = rd.validate(ident.robot, check, "current", window=None).predicted
    assert np.linalg.norm(validated - check.current) / np.linalg.norm(check.current) < 0.02
