"""MJCF export: MuJoCo's mass matrix, bias forces, inverse dynamics and frames equal robodyn's."""

from __future__ import annotations

import functools
import math
import warnings
from dataclasses import replace

import numpy as np
import pytest
import sympy as sp

from robodyn.export import export
from robodyn.export.inertia import MIN_INERTIA, MIN_MASS, engine_inertial, rotation_axes
from robodyn.export.mjcf import mjcf_robot, to_mjcf
from robodyn.export.numeric import values_of
from robodyn.robot.errors import DescriptionWarning
from robodyn.robot.model import Friction, Robot
from tests.export import Dynamics, as_array, frames, quiet_load, relative_error
from tests.numeric_eval import random_states

try:  # test-only oracle: the tests that use it are marked and skip alone (see tests/conftest.py)
    import mujoco
except ImportError:
    mujoco = None

ROBOTS = ["puma560", "aa300", "planar_2r", "trolley_double_pendulum", "kinova_gen3"]
TOL = 1e-9
needs_mujoco = pytest.mark.oracle("mujoco")
quiet = pytest.mark.filterwarnings("ignore::robodyn.robot.errors.DescriptionWarning")


@functools.cache
def builtin(name: str) -> Robot:
    return quiet_load(name)


@functools.cache
def written(name: str) -> tuple[Robot, str, tuple[str, ...]]:
    """The robot as written, the MJCF text and the export warnings."""
    robot = builtin(name)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        text = to_mjcf(robot)
    messages = tuple(str(w.message) for w in caught if issubclass(w.category, DescriptionWarning))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DescriptionWarning)
        return mjcf_robot(robot), text, messages


def load(text: str):
    model = mujoco.MjModel.from_xml_string(text)
    return model, mujoco.MjData(model)


def full_mass_matrix(model, data) -> np.ndarray:
    """``mj_fullM`` as a dense (nv, nv) array (MuJoCo 4 takes ``d``, MuJoCo 3 took ``d.qM``)."""
    out = np.zeros((model.nv, model.nv))
    try:
        mujoco.mj_fullM(model, data, out)
    except TypeError:
        mujoco.mj_fullM(model, out, data.qM)
    return out


@pytest.mark.parametrize("name", ROBOTS)
@needs_mujoco
def test_mujoco_dynamics_equal_robodyn(name):
    robot, text, _ = written(name)
    model, data = load(text)
    assert model.nq == model.nv == model.nu == robot.dof
    model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONSTRAINT  # no limits, no frictionloss
    dyn = Dynamics(robot)
    n = robot.dof
    errors = {"M": 0.0, "g": 0.0, "tau": 0.0}
    for q, qd, qdd in random_states(n, 4, seed=7):
        data.qpos[:], data.qvel[:] = q, 0.0
        mujoco.mj_forward(model, data)
        m = full_mass_matrix(model, data)
        errors["M"] = max(errors["M"], relative_error(m, dyn.M(q)))  # armature = G^2 Jm
        errors["g"] = max(errors["g"], relative_error(data.qfrc_bias, dyn.g(q)))
        data.qvel[:], data.qacc[:] = qd, qdd
        mujoco.mj_inverse(model, data)
        # damping = viscous friction; Coulomb (frictionloss) is a constraint, disabled here
        expected = dyn.tau_rigid(q, qd, qdd) + dyn.rotor * qdd + dyn.viscous * qd
        errors["tau"] = max(errors["tau"], relative_error(data.qfrc_inverse, expected))
    assert max(errors.values()) < TOL, errors


@pytest.mark.parametrize("name", ROBOTS)
@needs_mujoco
def test_bodies_are_robodyn_link_frames(name):
    robot, text, _ = written(name)
    model, data = load(text)
    rng = np.random.default_rng(8)
    for _ in range(3):
        q = rng.uniform(-math.pi, math.pi, robot.dof)
        data.qpos[:] = q
        mujoco.mj_kinematics(model, data)
        ref = frames(robot, q)
        for k, link in enumerate(robot.links):
            body = data.body(link.name)
            np.testing.assert_allclose(body.xpos, ref.links[k][:3, 3], atol=1e-12)
            np.testing.assert_allclose(body.xmat.reshape(3, 3), ref.links[k][:3, :3], atol=1e-12)
        site = data.site("tool")
        np.testing.assert_allclose(site.xpos, ref.tool[:3, 3], atol=1e-12)
        np.testing.assert_allclose(site.xmat.reshape(3, 3), ref.tool[:3, :3], atol=1e-12)


@pytest.mark.parametrize("name", ["aa300", "planar_2r", "trolley_double_pendulum",
                                  pytest.param("kinova_gen3", marks=pytest.mark.slow)])
def test_inertia_repairs_keep_the_dynamics(name):
    """Massless links, thin rods, point masses, Kinova's shoulder: repaired without a change."""
    original, (robot, _, messages) = builtin(name), written(name)
    assert not any("inertia" in m for m in messages), messages
    a, b = Dynamics(original), Dynamics(robot)
    for q, qd, qdd in random_states(robot.dof, 3, seed=9):
        assert relative_error(b.M(q), a.M(q)) < TOL
        assert relative_error(b.g(q), a.g(q)) < TOL
        assert relative_error(b.tau(q, qd, qdd), a.tau(q, qd, qdd)) < TOL


def test_puma560_link3_inertia_is_changed_with_a_warning():
    robot, _, messages = written("puma560")
    assert any("inertias outside what MuJoCo accepts were changed" in m and "link3" in m for m in messages)
    assert any("different levels per direction" in m for m in messages)
    moments = np.linalg.eigvalsh(as_array(robot.links[2].inertia, robot))
    np.testing.assert_allclose(moments, [0.01625, 0.06975, 0.086], rtol=1e-9)
    # link 1 (massless, only turned about its y axis) is repaired without a warning
    assert float(robot.links[0].mass) == MIN_MASS
    np.testing.assert_allclose(as_array(robot.links[0].inertia, robot), 0.35 * np.eye(3))


@needs_mujoco
def test_options_actuators_limits_and_friction():
    robot = builtin("trolley_double_pendulum")
    j0, j1, j2 = robot.joints
    robot = replace(robot, joints=(
        replace(j0, lower=sp.Float(-0.5), upper=sp.Float(0.75), effort_limit=sp.Integer(40),
                friction=Friction(sp.Float(0.3), sp.Float(0.2), sp.Float(0.2))),
        replace(j1, upper=sp.Float(1.0), friction=Friction(sp.Float(0.1), sp.Float(0.2), sp.Float(0.3))),
        j2,
    ))
    with pytest.warns(DescriptionWarning) as caught:
        text = to_mjcf(robot, timestep=0.002, integrator="implicitfast")
    messages = " ".join(str(w.message) for w in caught)
    assert "different levels per direction" in messages and "theta1" in messages
    assert "one-sided position limits are dropped (range needs both bounds): theta1" in messages
    model, _ = load(text)
    assert model.opt.timestep == 0.002
    assert model.opt.integrator == mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    assert model.opt.disableflags & mujoco.mjtDisableBit.mjDSBL_CONTACT
    np.testing.assert_array_equal(model.opt.gravity, [0, 0, -9.81])
    np.testing.assert_array_equal(model.jnt_limited, [1, 0, 0])
    np.testing.assert_array_equal(model.jnt_range[0], [-0.5, 0.75])
    np.testing.assert_array_equal(model.dof_damping, [0.3, 0.1, 0.0])
    np.testing.assert_array_equal(model.dof_frictionloss, [0.2, 0.0, 0.0])
    np.testing.assert_array_equal(model.actuator_gear[:, 0], [1, 1, 1])
    np.testing.assert_array_equal(model.actuator_ctrllimited, [1, 0, 0])
    np.testing.assert_array_equal(model.actuator_ctrlrange[0], [-40, 40])
    assert [model.actuator(k).name for k in range(3)] == ["x", "theta1", "theta2"]


@quiet
@needs_mujoco
def test_parameters_are_substituted():
    robot = builtin("planar_2r")
    text = to_mjcf(robot, parameters={"l1": 2.0, "g": 3.0})
    assert "l1 = 2.0" in text
    model, data = load(text)
    np.testing.assert_array_equal(model.opt.gravity, [0, -3.0, 0])
    mujoco.mj_kinematics(model, data)
    np.testing.assert_allclose(data.site("tool").xpos, [3.0, 0, 0], atol=1e-12)
    assert mjcf_robot(robot, parameters={"l1": 2.0}).parameters["l1"] == 2.0


@quiet
@needs_mujoco
def test_names_that_collide_with_mujoco_names_are_made_unique():
    robot = builtin("trolley_double_pendulum")
    names = ("world", "base", "tool")
    robot = replace(robot, links=tuple(replace(lk, name=n) for lk, n in zip(robot.links, names, strict=True)))
    model, data = load(to_mjcf(robot))
    assert [model.body(k).name for k in range(model.nbody)] == ["world", "base_", "world_", "base", "tool"]
    q = np.array([0.3, -0.4, 1.1])
    data.qpos[:] = q
    mujoco.mj_kinematics(model, data)
    np.testing.assert_allclose(data.site("tool").xpos, frames(robot, q).tool[:3, 3], atol=1e-12)


# ----------------------------------------------------------------------------------------------
# Inertia repair rules


def test_engine_inertial_rules():
    valid = np.diag([1.0, 2.0, 2.5])
    kept = engine_inertial(3.0, valid, None)
    assert not kept.changed and kept.equivalent
    np.testing.assert_array_equal(kept.inertia, valid)
    # a link that only turns about its y axis keeps I_yy and becomes isotropic
    about_y = engine_inertial(0.0, np.diag([0.0, 0.35, 0.0]), np.array([0.0, 1.0, 0.0]))
    assert about_y.mass == MIN_MASS and about_y.equivalent
    np.testing.assert_allclose(about_y.inertia, 0.35 * np.eye(3))
    # a link that never turns: floors only
    point = engine_inertial(1.0, np.zeros((3, 3)), np.zeros(3))
    assert point.equivalent and point.mass == 1.0
    np.testing.assert_allclose(point.inertia, MIN_INERTIA * np.eye(3))
    # varying axes: the two smaller moments share the triangle deficit; reported as a change
    general = engine_inertial(1.0, np.diag([0.066, 0.086, 0.0125]), None)
    assert general.changed and not general.equivalent
    np.testing.assert_allclose(np.diag(general.inertia), [0.06975, 0.086, 0.01625], rtol=1e-9)
    # a tensor on the triangle boundary (thin plate) gets the margin, invisibly
    plate = engine_inertial(1.0, np.diag([1.0, 2.0, 3.0]), None)
    assert plate.equivalent and plate.moments_after[0] + plate.moments_after[1] > plate.moments_after[2]
    with pytest.raises(ValueError, match="negative mass"):
        engine_inertial(-1.0, valid, None)


def test_rotation_axes():
    planar = builtin("planar_2r")
    axes = rotation_axes(planar, values_of(planar))
    for axis in axes:
        np.testing.assert_allclose(np.abs(axis), [0, 0, 1], atol=1e-15)
    trolley = builtin("trolley_double_pendulum")
    axes = rotation_axes(trolley, values_of(trolley))
    np.testing.assert_array_equal(axes[0], np.zeros(3))
    np.testing.assert_allclose(np.abs(axes[2]), [0, 1, 0], atol=1e-15)
    puma = builtin("puma560")
    axes = rotation_axes(puma, values_of(puma))
    assert axes[0] is not None and all(a is None for a in axes[1:])


# ----------------------------------------------------------------------------------------------
# Bad input


@pytest.mark.parametrize(
    ("options", "match"),
    [
        ({"integrator": "rk4"}, "unknown integrator 'rk4'; choose one of Euler, RK4, implicit, implicitfast"),
        ({"timestep": 0.0}, "timestep must be a positive number of seconds, got 0.0"),
        ({"timestep": "fast"}, "timestep must be a positive number of seconds, got 'fast'"),
        ({"parameters": {"mass": 1.0}}, r"unknown parameter\(s\) \['mass'\]"),
    ],
)
def test_bad_options_are_rejected(options, match):
    with pytest.raises(ValueError, match=match):
        to_mjcf(builtin("trolley_double_pendulum"), **options)


def test_negative_mass_is_rejected():
    robot = builtin("trolley_double_pendulum")
    robot = replace(robot, links=(replace(robot.links[0], mass=sp.Integer(-1)), *robot.links[1:]))
    with pytest.raises(ValueError, match=r"joints\[0\] \(x\)\.link\.mass: negative mass -1\.0 kg"):
        to_mjcf(robot)


def test_unwritable_path_names_the_file(tmp_path):
    path = tmp_path / "no" / "arm.xml"
    with pytest.raises(OSError, match=r"no/arm\.xml: cannot write the MJCF file"):
        to_mjcf(builtin("trolley_double_pendulum"), path)


@needs_mujoco
def test_export_by_format_name_writes_the_file(tmp_path):
    robot = builtin("trolley_double_pendulum")
    path = tmp_path / "arm.xml"
    text = export(robot, "mjcf", path, timestep=0.01)
    assert path.read_text(encoding="utf-8") == text
    model = mujoco.MjModel.from_xml_path(str(path))
    assert model.opt.timestep == 0.01
