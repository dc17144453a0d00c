"""Underwater dynamics: formulations, compiled model, equilibrium and energy in simulation."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

import robodyn as rd
from robodyn import spatial as S
from robodyn.robot.hydro import fluid_of, hydro_of
from robodyn.robot.yaml_loader import load_yaml_text
from robodyn.symbolic.kinematics import forward_kinematics
from tests.hydro.test_closed_form import PENDULUM

# every effect on: a current along x and some lift
WET = {"vc": 0.3, "CL": 0.2}


def _lambdify(eom: rd.EquationsOfMotion, expr: sp.MatrixBase, values: dict[str, float]):
    subs = eom.numeric(values)
    return sp.lambdify([eom.q, eom.qd, eom.qdd], expr.xreplace(subs), "numpy")


def _states(seed: int, count: int) -> np.ndarray:
    return np.random.default_rng(seed).uniform(-2, 2, (count, 3, 2))


def test_three_formulations_agree_with_hydrodynamics_on() -> None:
    robot = rd.load("underwater_2r")
    eoms = [rd.derive(robot, method=m) for m in ("newton_euler", "lagrange", "kane")]
    for name in ("M", "C", "g", "tau"):
        fns = [_lambdify(e, getattr(e, name), WET) for e in eoms]
        for q, qd, qdd in _states(4, 5):
            ref = np.array(fns[0](q, qd, qdd), dtype=float)
            for f in fns[1:]:
                np.testing.assert_allclose(np.array(f(q, qd, qdd), dtype=float), ref,
                                           rtol=1e-10, atol=1e-10)
    # and the hydrodynamic part is really there (not zero) in every formulation
    for e in eoms:
        assert e.hydro is not None and e.hydro.drag != sp.zeros(2, 1)


@pytest.mark.parametrize("backend", ["c", "numpy"])
def test_compiled_model_equals_the_symbolic_terms(backend: str) -> None:
    robot = rd.load("underwater_2r")
    eom = rd.derive(robot)
    model = rd.compile_model(robot, backend=backend, parameters=WET)
    tau = _lambdify(eom, eom.tau, WET)
    mass = _lambdify(eom, eom.M, WET)
    grav = _lambdify(eom, eom.g, WET)
    cor = _lambdify(eom, eom.C * sp.Matrix(eom.qd), WET)
    for q, qd, qdd in _states(5, 6):
        ref = np.ravel(tau(q, qd, qdd))
        np.testing.assert_allclose(model.inverse_dynamics(q, qd, qdd), ref, rtol=1e-12, atol=1e-10)
        np.testing.assert_allclose(model.mass_matrix(q), np.array(mass(q, qd, qdd), dtype=float),
                                   rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(model.gravity(q), np.ravel(grav(q, qd, qdd)), rtol=1e-12, atol=1e-10)
        np.testing.assert_allclose(model.coriolis(q, qd), np.ravel(cor(q, qd, qdd)), rtol=1e-12,
                                   atol=1e-10)
        np.testing.assert_allclose(model.forward_dynamics(q, qd, ref), qdd, rtol=1e-9, atol=1e-9)


def test_neutrally_buoyant_body_stays_at_rest() -> None:
    # the link's density equals the water's and its centre of mass is its centre of buoyancy
    text = PENDULUM.replace("m: 3.0,", "m: 1025.0*pi*0.08**2*0.9/4,")
    robot = load_yaml_text(text, source="neutral.yaml")
    model = rd.compile_model(robot)
    for q in (0.0, 1.0, -2.5):
        assert np.abs(model.gravity(np.array([q]))).max() < 1e-12
    run = rd.simulate(model, np.array([1.0]), None, 1.0, 1e-3)
    assert np.abs(run.q - 1.0).max() < 1e-12 and np.abs(run.qd).max() < 1e-12
    # the same body in air falls
    dry = rd.compile_model(load_yaml_text(text.replace("fluid: {density: rho}\n", "").replace(
        "      hydro:\n        cylinders: [{radius: D/2, length: L, axis: [0, -1, 0], "
        "start: [0, 0, 0]}]\n        added_mass: Ca\n        drag: Cd\n", ""), source="dry.yaml"))
    assert abs(dry.gravity(np.array([1.0]))[0]) > 1.0


def _energy_function(robot: rd.Robot, model: rd.Model):
    """Total energy 1/2 qd^T (M + M_a) qd + gravity and buoyancy potentials, written out here."""
    eom = rd.derive(robot)
    kin = forward_kinematics(robot, eom.q)
    fluid, hydro = fluid_of(robot), hydro_of(robot)
    g_w = robot.gravity
    v = sp.Integer(0)
    for link, h, t in zip(robot.links, hydro, kin.links, strict=True):
        # gravity: -m g . p_c;  buoyancy: +rho V g . p_B
        v -= link.mass * (g_w.T * (S.rotation(t) * link.com + S.translation(t)))[0, 0]
        v += fluid.density * h.volume * (g_w.T * (S.rotation(t) * h.center_of_buoyancy
                                                  + S.translation(t)))[0, 0]
    pot = sp.lambdify([eom.q], v.xreplace(eom.numeric(model.parameters)), "numpy")

    def energy(q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        m = model.mass_matrix(q)
        return 0.5 * np.einsum("ni,nij,nj->n", qd, m, qd) + np.array([pot(x) for x in q])

    return energy


def test_energy_is_conserved_without_drag() -> None:
    robot = rd.load("underwater_2r")
    model = rd.compile_model(robot, parameters={"Cd": 0.0})
    run = rd.simulate(model, np.array([0.4, -0.8]), np.array([1.0, -0.5]), 10.0, 1e-3)
    e = _energy_function(robot, model)(run.q, run.qd)
    drift = np.abs(e - e[0]).max() / (np.abs(e).max())
    assert drift < 1e-8


def test_energy_decays_at_the_drag_power() -> None:
    robot = rd.load("underwater_2r")
    model = rd.compile_model(robot)
    run = rd.simulate(model, np.array([0.4, -0.8]), np.array([1.0, -0.5]), 3.0, 1e-3)
    e = _energy_function(robot, model)(run.q, run.qd)
    assert e[-1] < e[0] and np.all(np.diff(e) <= 1e-12)
    # drag torques: inverse dynamics minus the same without drag
    no_drag = rd.compile_model(robot, parameters={"Cd": 0.0})
    tau_d = model.inverse_dynamics(run.q, run.qd, run.qdd) - no_drag.inverse_dynamics(
        run.q, run.qd, run.qdd)
    power = -np.einsum("ni,ni->n", run.qd, tau_d)  # dE/dt = -qd . tau_d
    lost = np.trapezoid(power, run.t)
    assert e[-1] - e[0] == pytest.approx(lost, rel=1e-5)
