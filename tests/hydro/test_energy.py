"""``simulate``'s energy under water: added-mass kinetic energy and buoyancy potential included."""

from __future__ import annotations

import numpy as np

import robodyn as rd
from robodyn.simulation.energy import potential_energy
from tests.hydro.test_dynamics import _energy_function

Q0, QD0 = np.array([0.4, -0.8]), np.array([1.0, -0.5])


def test_reported_energy_is_conserved_without_drag() -> None:
    robot = rd.load("underwater_2r")
    model = rd.compile_model(robot, parameters={"Cd": 0.0})
    run = rd.simulate(model, Q0, QD0, 10.0, 1e-3)
    assert run.energy_drift < 1e-8
    # it is the total written out independently in the tests (fluid kinetic and buoyancy terms)
    ref = _energy_function(robot, model)(run.q, run.qd)
    np.testing.assert_allclose(run.energy, ref, rtol=1e-12, atol=1e-9)
    # without the buoyancy potential it would not be conserved: the test can fail
    assert np.ptp(run.potential) > 10.0


def test_potential_gradient_is_the_gravity_load_with_buoyancy() -> None:
    model = rd.compile_model(rd.load("underwater_2r"))
    h = 1e-6
    for q in np.random.default_rng(3).uniform(-3, 3, (5, 2)):
        grad = [(potential_energy(model, q + h * e) - potential_energy(model, q - h * e)) / (2 * h)
                for e in np.eye(2)]
        np.testing.assert_allclose(grad, model.gravity(q), rtol=1e-7, atol=1e-6)


def test_reported_energy_decreases_with_drag() -> None:
    model = rd.compile_model(rd.load("underwater_2r"))
    run = rd.simulate(model, Q0, QD0, 3.0, 1e-3)
    assert np.all(np.diff(run.energy) <= 1e-12) and run.energy[-1] < run.energy[0] - 1.0
