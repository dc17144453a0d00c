"""Sensitivity sweeps and the controller-design question (which effect the model must keep)."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

import robodyn as rd
from robodyn.robot.errors import StudyError
from robodyn.robot.hydro import fluid_of, hydro_of
from robodyn.robot.yaml_loader import load_yaml_text
from robodyn.simulation.trajectory import quintic
from robodyn.studies.underwater import effect_variant
from robodyn.studies.underwater_model_error import model_error_study, model_without
from robodyn.studies.underwater_sensitivity import sensitivity, with_drag_coefficient
from tests.hydro.test_closed_form import PENDULUM


@pytest.fixture(scope="module")
def errors():
    robot = rd.load("underwater_2r")
    ref = quintic([0.0, 0.0], [0.8, 0.8], 1.0, dt=1e-3)
    # 1 s move, 2 s hold: a 2 Hz critically damped error settles well within the hold
    return model_error_study(robot, ref, 3.0, omitted=("nothing", "buoyancy", "drag", "everything"))


def _row(study, omitted: str, joint: str) -> dict:
    t = study.table
    return t[(t["omitted"] == omitted) & (t["joint"] == joint)].iloc[0].to_dict()


def test_exact_model_tracks_to_integrator_round_off(errors) -> None:
    for joint in ("q1", "q2"):
        assert _row(errors, "nothing", joint)["max_error"] < 1e-9
        # an omitted effect is visible many orders above it
        assert _row(errors, "drag", joint)["max_error"] > 1e-3


def test_omitting_buoyancy_leaves_the_predicted_steady_error(errors) -> None:
    robot = rd.load("underwater_2r")
    run = errors.runs["buoyancy"]
    q_ss = run.q[-1]
    # the missing gravity term, written here from the description: rho V g at the cylinders'
    # centres, g_B = -rho g pi (r1^2 l1^2/2 cos q1 + r2^2 l2 (l1 cos q1 + l2/2 cos(q1+q2)), ...)
    p = dict(robot.parameters)
    rho, g = p["rho"], p["g"]
    v1, v2 = np.pi * p["r1"] ** 2 * p["l1"], np.pi * p["r2"] ** 2 * p["l2"]
    c1, c12 = np.cos(q_ss[0]), np.cos(q_ss.sum())
    g_b = -rho * g * np.array([v1 * p["l1"] / 2 * c1 + v2 * (p["l1"] * c1 + p["l2"] / 2 * c12),
                               v2 * p["l2"] / 2 * c12])
    plant = rd.compile_model(effect_variant(robot, "current", current=errors.current))
    predicted = np.linalg.solve(plant.mass_matrix(q_ss), g_b) / errors.kp
    steady = np.array([_row(errors, "buoyancy", j)["steady_error"] for j in ("q1", "q2")])
    np.testing.assert_allclose(steady, predicted, rtol=1e-3)
    np.testing.assert_allclose(errors.predicted_error, predicted, rtol=1e-9)
    # the arm is lighter in water: the uncompensated upthrust lifts link 1 above its target
    assert steady[0] < -1e-3
    # the velocity errors are gone by then: the error is steady, not a transient
    assert np.abs(run.qd[-1]).max() < 1e-6


def test_model_without_drops_exactly_one_effect() -> None:
    full = effect_variant(rd.load("underwater_2r"), "current", current=[0.5, 0.0, 0.0])
    for effect, key in (("added_mass", "added_mass"), ("drag", "drag"), ("buoyancy", "volume")):
        h = hydro_of(model_without(full, effect))
        assert all(float(getattr(x, key)) == 0.0 for x in h if x is not None)
        # the other coefficients are untouched
        assert all(x.lift == y.lift for x, y in zip(h, hydro_of(full), strict=True) if x is not None)
    assert not any(float(c) for c in fluid_of(model_without(full, "current")).current)
    with pytest.raises(StudyError, match="unknown effect"):
        model_without(full, "vortex")


def test_more_drag_gives_a_smaller_free_swing() -> None:
    pendulum = load_yaml_text(PENDULUM, source="pendulum.yaml")
    ref = quintic([1.0], [1.2], 0.5, dt=1e-3)
    t = 1e-3 * np.arange(501)
    sens = sensitivity(pendulum, ref, t, free_time=2.0, cd_values=(0.3, 1.2, 4.0),
                       current_speeds=(0.0, 1.0))
    cd = sens.table[sens.table["parameter"] == "C_d"]
    amp = cd["free_amplitude"].to_numpy()
    assert amp[0] > amp[1] > amp[2] > 0
    # this pendulum floats (rho V = 4.6 kg > m = 3 kg): it rises towards q = pi (tip up); a
    # current along +x pushes the tip (at L (sin q, -cos q)) downstream: sin(q) grows
    cur = sens.table[sens.table["parameter"] == "current"]
    still, flowing = cur["free_mean"].to_numpy()
    assert np.pi / 2 < flowing < still < np.pi
    assert np.sin(flowing) > np.sin(still) + 0.01
    assert with_drag_coefficient(pendulum, 2.0).links[0].hydro.drag == 2.0
    assert pendulum.links[0].hydro.drag == sp.Symbol("Cd", real=True)  # the input is not modified


def test_bad_sweep_values_are_refused() -> None:
    robot = rd.load("underwater_2r")
    ref = quintic([0.0, 0.0], [0.1, 0.1], 0.1)
    with pytest.raises(StudyError, match="cd_values"):
        sensitivity(robot, ref, np.zeros(1), cd_values=(-1.0,))
    with pytest.raises(StudyError, match="direction"):
        sensitivity(robot, ref, np.zeros(1), direction=(0, 0, 0))
