"""The built-in ``reach_alpha5`` (Reach Alpha 5 subsea arm): data, statics, formulations, backends.

The references here are independent of robodyn's kinematics and hydrodynamics: the link masses
and cylinder lengths are the published URDF numbers written again in this file, and the gravity
plus buoyancy torque is the gradient of a potential computed with this file's own homogeneous
transforms.
"""

from __future__ import annotations

import csv
import math

import numpy as np
import pytest
import sympy as sp

import robodyn as rd
from robodyn.cli import main
from robodyn.robot.hydro import fluid_of, hydro_of

NAME = "reach_alpha5"
RHO, G, R = 1025.0, 9.81, 0.020
# published link masses (kg) of the four moving links, Robotic-Decision-Making-Lab/reach
MASSES = (0.194, 0.429, 0.115, 0.200)
# collision cylinders of each moving link: (length m, centre in the link frame m)
CYLINDERS = (
    ((0.033, (0.0, 0.0, 0.0165)),),
    ((0.145, (-0.02, 0.0, -0.0725)), (0.040, (0.0, 0.0, 0.0)), (0.040, (-0.04, 0.0, -0.1453))),
    ((0.033, (0.02, 0.0, 0.0165)),),
    ((0.100, (0.0, 0.0, 0.05)),),
)
COMS = ((0.0, 0.0, 0.0165), (-0.02, 0.0, -0.0725), (0.02, 0.0, 0.0165), (0.0, 0.0, 0.05))
# joint origins (xyz, yaw) and axes of the manufacturer's URDF (all rolls and pitches are zero)
ORIGINS = (((0, 0, 0.014), 0.0), ((-0.02, 0, 0.033), 0.0), ((-0.04, 0, -0.1453), 3.14159),
           ((0.02, 0, 0.033), 2.09439))
AXES = ((0, 0, 1), (0, 1, 0), (0, 1, 0), (0, 0, -1))
WET = {"vc": 0.3, "CL": 0.2}  # every effect on: a current along x and some lift


def _numeric(expr: sp.Expr, robot: rd.Robot) -> float:
    values = {s: robot.parameters[s.name] for s in sp.sympify(expr).free_symbols}
    return float(sp.sympify(expr).xreplace(values))


def test_loads_with_the_published_masses_and_cylinder_volumes() -> None:
    robot = rd.load(NAME)
    assert [j.name for j in robot.joints] == ["axis_e", "axis_d", "axis_c", "axis_b"]
    assert [_numeric(link.mass, robot) for link in robot.links] == pytest.approx(MASSES, abs=0)
    assert sum(MASSES) == pytest.approx(0.938, abs=1e-12)
    fluid = fluid_of(robot)
    assert fluid is not None and _numeric(fluid.density, robot) == RHO
    hydros = hydro_of(robot)
    for hydro, cylinders in zip(hydros, CYLINDERS, strict=True):
        assert hydro is not None
        lengths = sum(length for length, _ in cylinders)
        assert _numeric(hydro.volume, robot) == pytest.approx(math.pi * R**2 * lengths, rel=1e-12)
    # the totals written in the description's comment: 0.391 m of cylinder, 4.913e-4 m^3
    total = sum(_numeric(h.volume, robot) for h in hydros if h is not None)
    assert total == pytest.approx(4.913e-4, abs=1e-7)
    assert RHO * total == pytest.approx(0.504, abs=1e-3)  # kg of buoyancy in sea water


def _rot(axis: tuple[float, float, float], angle: float) -> np.ndarray:
    k = np.asarray(axis, dtype=float)
    kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + math.sin(angle) * kx + (1 - math.cos(angle)) * kx @ kx


def _height(pose: np.ndarray, point: tuple[float, float, float]) -> float:
    """Base-frame z of a point given in the frame ``pose`` (4, 4), m."""
    return float((pose[:3, :3] @ np.asarray(point) + pose[:3, 3])[2])


def _potential(q: np.ndarray) -> float:
    """Gravity minus buoyancy potential of the four moving links, J (own forward kinematics)."""
    pose = np.eye(4)
    energy = 0.0
    for i in range(4):
        xyz, yaw = ORIGINS[i]
        step = np.eye(4)
        step[:3, :3] = _rot((0, 0, 1), yaw) @ _rot(AXES[i], q[i])
        step[:3, 3] = xyz
        pose = pose @ step
        energy += MASSES[i] * G * _height(pose, COMS[i])
        for length, centre in CYLINDERS[i]:  # buoyancy: mass -rho V at each volume centre
            energy -= RHO * math.pi * R**2 * length * G * _height(pose, centre)
    return energy


@pytest.mark.slow
@pytest.mark.parametrize("seed", [0, 1])
def test_gravity_with_buoyancy_is_the_gradient_of_an_independent_potential(seed: int) -> None:
    model = rd.compile_model(rd.load(NAME), backend="numpy")
    h = 1e-6
    for q in np.random.default_rng(seed).uniform(-2.5, 2.5, (4, 4)):
        grad = [(_potential(q + h * e) - _potential(q - h * e)) / (2 * h) for e in np.eye(4)]
        np.testing.assert_allclose(model.gravity(q), grad, rtol=0, atol=1e-9)


@pytest.mark.slow
@pytest.mark.parametrize("rho", [RHO, 0.0])
def test_net_weight_torques_at_the_zero_pose_by_hand(rho: float) -> None:
    # q = 0: every link frame is parallel to the base (the elbow's yaw 3.14159 ~ pi turns x into
    # -x); a body of weight w = (m - rho V) g at horizontal offset x from a y axis loads it with
    # -w x (shoulder, axis +y) or +w x (elbow, whose +y is the base's -y). Offsets along base x,
    # m: shoulder at x = -0.02; m2's centre of mass -0.02 further, its cylinders' centres -0.02,
    # 0, -0.04; m2_1_3 and m1 (masses and cylinders) at -0.06 from the shoulder, -0.02 from the
    # elbow. Vertical axes (axis_e, axis_b) carry nothing.
    area = math.pi * R**2
    shoulder = G * (0.429 * 0.02 + 0.115 * 0.06 + 0.200 * 0.06
                    - rho * area * (0.145 * 0.02 + 0.040 * 0.0 + 0.040 * 0.04 + 0.033 * 0.06
                                    + 0.100 * 0.06))
    elbow = -G * 0.02 * ((0.115 + 0.200) - rho * area * (0.033 + 0.100))
    model = rd.compile_model(rd.load(NAME), parameters={"rho": rho})
    np.testing.assert_allclose(model.gravity(np.zeros(4)), [0.0, shoulder, elbow, 0.0],
                               rtol=0, atol=1e-9)
    if rho:  # the figures of the description's comment: 0.1119 N m and -0.0282 N m
        assert shoulder == pytest.approx(0.11188, abs=1e-5)
        assert elbow == pytest.approx(-0.028192, abs=1e-6)


@pytest.mark.slow
def test_three_formulations_agree_with_every_effect_on() -> None:
    # each formulation's own straight-line M, C, g and tau (with the shared hydrodynamic terms)
    robot = rd.load(NAME)
    eoms = [rd.derive(robot, method=m) for m in ("newton_euler", "lagrange", "kane")]
    states = np.random.default_rng(3).uniform(-2, 2, (4, 3, 4))
    for q, qd, qdd in states:
        args = {"M": (q,), "C": (q, qd), "g": (q,), "tau": (q, qd, qdd)}
        for name, arg in args.items():
            ref = eoms[0].numeric_function(name)(*arg, values=WET)
            for e in eoms[1:]:
                np.testing.assert_allclose(e.numeric_function(name)(*arg, values=WET), ref,
                                           rtol=1e-10, atol=1e-10)
    for e in eoms:
        assert e.hydro is not None and e.hydro.drag != sp.zeros(4, 1)


@pytest.mark.slow
def test_compiled_c_model_equals_the_numpy_backend() -> None:
    robot = rd.load(NAME)
    c = rd.compile_model(robot, backend="c", parameters=WET)
    npy = rd.compile_model(robot, backend="numpy", parameters=WET)
    symbolic_tau = rd.derive(robot).numeric_function("tau")
    for q, qd, qdd in np.random.default_rng(7).uniform(-2, 2, (6, 3, 4)):
        np.testing.assert_allclose(c.inverse_dynamics(q, qd, qdd),
                                   symbolic_tau(q, qd, qdd, values=WET), rtol=1e-10, atol=1e-12)
        np.testing.assert_allclose(c.inverse_dynamics(q, qd, qdd), npy.inverse_dynamics(q, qd, qdd),
                                   rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(c.mass_matrix(q), npy.mass_matrix(q), rtol=1e-12, atol=1e-14)
        np.testing.assert_allclose(c.gravity(q), npy.gravity(q), rtol=1e-12, atol=1e-14)
    # the drag torque is really in there: a current changes the torque at rest
    still = rd.compile_model(robot, backend="numpy")
    q = np.array([0.3, 1.0, 0.5, 0.2])
    zero = np.zeros(4)
    assert np.abs(npy.inverse_dynamics(q, zero, zero) - still.inverse_dynamics(q, zero, zero)).max() > 1e-4


def test_passive_simulation_loses_energy_to_drag() -> None:
    # released at rest in still water: drag is the only non-conservative force, so the total
    # energy (with the added-mass kinetic energy and the buoyancy potential) never increases
    model = rd.compile_model(rd.load(NAME))
    run = rd.simulate(model, np.array([0.0, 1.2, 0.6, 0.0]), None, 2.0, 2e-3)
    assert np.all(np.isfinite(run.q)) and np.abs(run.qd).max() > 0.5
    assert np.diff(run.energy).max() < 1e-9
    assert run.energy[-1] < run.energy[0] - 0.1


@pytest.mark.slow  # six variants compiled: ~100 s with a cold model cache, ~4 s warm
def test_underwater_series_only_cli(tmp_path, capsys) -> None:
    out = tmp_path / "alpha"
    code = main(["underwater", NAME, "-o", str(out), "--series-only", "--move-time", "0.5",
                 "--hold-time", "0.2", "--free-time", "0.5"])
    assert code == 0, capsys.readouterr().err
    with (out / "effects.csv").open() as f:
        rows = list(csv.DictReader(f))
    assert [r["effect"] for r in rows[::4]] == ["dry", "buoyancy", "added_mass", "drag", "lift",
                                                "current"]
    assert not (out / "sensitivity.csv").exists()
