"""URDF export: ``rd.load(to_urdf(robot))`` keeps frames and dynamics; Pinocchio reads the file."""

from __future__ import annotations

import functools
import math
import warnings
from dataclasses import replace

import numpy as np
import pytest
import sympy as sp
from lxml import etree

import robodyn as rd
from robodyn.export import export
from robodyn.export.urdf import to_urdf
from robodyn.robot.errors import DescriptionWarning
from robodyn.robot.model import Drive, Friction, Robot
from tests.export import Dynamics, as_array, frames, quiet_load, relative_error
from tests.numeric_eval import random_states

BUILTINS = rd.builtin_names()
TOL = 1e-12
quiet = pytest.mark.filterwarnings("ignore::robodyn.robot.errors.DescriptionWarning")


@functools.cache
def builtin(name: str) -> Robot:
    return quiet_load(name)


@functools.cache
def dynamics_of(name: str) -> Dynamics:
    """Dynamics of a built-in robot, derived once per test session."""
    return Dynamics(builtin(name))


def export_and_load(robot: Robot, tmp_path, **options) -> tuple[Robot, list[str], str]:
    """Write the URDF, load it back; also the export warnings and the text."""
    path = tmp_path / f"{robot.name}.urdf"
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        text = to_urdf(robot, path, **options)
    messages = [str(w.message) for w in caught if issubclass(w.category, DescriptionWarning)]
    assert path.read_text(encoding="utf-8") == text
    return quiet_load(path), messages, text


def urdf_expected(robot: Robot) -> Robot:
    """What a URDF can hold of ``robot``: no drive, symmetric Coulomb friction only, URDF gravity."""
    joints = []
    for joint in robot.joints:
        f = joint.friction
        symmetric = float(as_array(sp.Matrix([f.coulomb_positive - f.coulomb_negative]), robot)[0, 0]) == 0
        coulomb = f.coulomb_positive if symmetric else sp.Integer(0)
        joints.append(replace(joint, drive=Drive(), friction=Friction(f.viscous, coulomb, coulomb)))
    gravity = sp.ImmutableMatrix([0, 0, sp.Rational(-981, 100)])
    return replace(robot, joints=tuple(joints), gravity=gravity)


def assert_same_frames(original: Robot, loaded: Robot, rng: np.random.Generator) -> float:
    """Every URDF link frame, every robodyn link frame and the tool agree; the max error."""
    worst = 0.0
    posts = [as_array(j.post, original) for j in original.joints]
    for _ in range(4):
        q = rng.uniform(-math.pi, math.pi, original.dof)
        a, b = frames(original, q), frames(loaded, q)
        for k in range(original.dof):
            # URDF link k is robodyn's frame before post_k; post_k leads to robodyn's link frame
            np.testing.assert_allclose(b.links[k], a.moved[k], atol=TOL)
            np.testing.assert_allclose(b.links[k] @ posts[k], a.links[k], atol=TOL)
            worst = max(worst, float(np.abs(b.links[k] - a.moved[k]).max()))
        np.testing.assert_allclose(b.tool, a.tool, atol=TOL)
        worst = max(worst, float(np.abs(b.tool - a.tool).max()))
    return worst


@pytest.mark.parametrize("name", [pytest.param(n, marks=pytest.mark.slow) if n == "kinova_gen3" else n
                                  for n in BUILTINS])
def test_round_trip_keeps_frames_and_dynamics(name, tmp_path):
    original = builtin(name)
    loaded, messages, _ = export_and_load(original, tmp_path)
    assert loaded.joint_names == original.joint_names
    assert [lk.name for lk in loaded.links] == [lk.name for lk in original.links]
    assert [j.type for j in loaded.joints] == [j.type for j in original.joints]
    assert all(j.post == sp.eye(4) for j in loaded.joints)
    np.testing.assert_array_equal(as_array(loaded.base, loaded), as_array(original.base, original))
    rng = np.random.default_rng(1)
    frame_error = assert_same_frames(original, loaded, rng)

    expected, got = Dynamics(urdf_expected(original)), Dynamics(loaded)
    errors = {"M": 0.0, "g": 0.0, "tau": 0.0}
    for q, qd, qdd in random_states(original.dof, 4, seed=2):
        errors["M"] = max(errors["M"], relative_error(got.M(q), expected.M(q)))
        errors["g"] = max(errors["g"], relative_error(got.g(q), expected.g(q)))
        errors["tau"] = max(errors["tau"], relative_error(got.tau(q, qd, qdd), expected.tau(q, qd, qdd)))
    assert max(errors.values()) < TOL, (frame_error, errors)
    # the rigid-body part is the original's, gravity aside (URDF has none)
    reference = dynamics_of(name)
    q, qd, qdd = next(random_states(original.dof, 1, seed=3))
    assert relative_error(got.M_rigid(q), reference.M_rigid(q)) < TOL
    if np.array_equal(as_array(original.gravity, original).ravel(), [0, 0, -9.81]):
        assert relative_error(got.tau_rigid(q, qd, qdd), reference.tau_rigid(q, qd, qdd)) < TOL
        assert not any("gravity" in m for m in messages)
    else:
        assert any("gravity" in m for m in messages)
    has_drive = any(j.drive != Drive() for j in original.joints)
    assert any("drive data" in m for m in messages) == has_drive


def test_limits_and_friction_that_map_exactly_come_back(tmp_path):
    robot = builtin("trolley_double_pendulum")
    j0, j1, j2 = robot.joints
    robot = replace(robot, joints=(
        replace(j0, lower=sp.Float(-0.5), upper=sp.Float(0.75), effort_limit=sp.Integer(40),
                velocity_limit=sp.Float(1.5), friction=Friction(sp.Float(0.3), sp.Float(0.2), sp.Float(0.2))),
        replace(j1, upper=sp.Float(1.0), friction=Friction(sp.Float(0.1), sp.Float(0.2), sp.Float(0.3),
                                                           sp.Float(0.05))),
        j2,
    ))
    loaded, messages, text = export_and_load(robot, tmp_path)
    a, b, c = loaded.joints
    assert [float(v) for v in (a.lower, a.upper, a.effort_limit, a.velocity_limit)] == [-0.5, 0.75, 40, 1.5]
    assert a.friction == Friction(sp.Float(0.3), sp.Float(0.2), sp.Float(0.2))
    assert b.friction == Friction(sp.Float(0.1))  # viscous kept; asymmetric Coulomb, offset dropped
    assert (b.lower, b.upper) == (None, None)  # one-sided: continuous
    assert (c.lower, c.upper, c.effort_limit) == (None, None, None)
    root = etree.fromstring(text.encode())
    kinds = {j.get("name"): j.get("type") for j in root.iter("joint")}
    assert kinds == {"base_joint": "fixed", "x": "prismatic", "theta1": "continuous",
                     "theta2": "continuous", "tool_joint": "fixed"}
    for needle in ("different levels per direction", "offsets", "one-sided"):
        assert any(needle in m for m in messages), needle


@quiet
def test_parameters_are_substituted_and_listed(tmp_path):
    robot = builtin("planar_2r")
    loaded, _, text = export_and_load(robot, tmp_path, parameters={"l1": 2.0, "l2": 0.5, "m2": 3.0})
    assert "l1 = 2.0" in text and "m2 = 3.0" in text and "m1 = 1.0" in text
    assert loaded.parameters == {}
    tool = frames(loaded, np.zeros(2)).tool
    np.testing.assert_allclose(tool[:3, 3], [2.5, 0, 0], atol=TOL)
    assert float(loaded.links[1].mass) == 3.0
    # the substituted robot, exported, is the same file
    assert to_urdf(rd.robot.chain.with_parameters(robot, {"l1": 2.0, "l2": 0.5, "m2": 3.0})) == text


def test_names_that_collide_with_the_frame_links_are_made_unique(tmp_path):
    robot = builtin("trolley_double_pendulum")
    names = ("world", "base", "tool")
    robot = replace(robot, links=tuple(replace(lk, name=n) for lk, n in zip(robot.links, names, strict=True)))
    loaded, _, text = export_and_load(robot, tmp_path)
    assert [lk.name for lk in loaded.links] == list(names)
    root = etree.fromstring(text.encode())
    written = [lk.get("name") for lk in root.iter("link")]
    assert written == ["world_", "base_", "world", "base", "tool", "tool_"]
    rng = np.random.default_rng(4)
    assert_same_frames(robot, loaded, rng)


@quiet
def test_hydro_data_is_dropped_with_a_warning(tmp_path):
    robot = builtin("planar_2r")
    link = replace(robot.links[0], hydro={"shape": "cylinder", "radius": 0.05})
    robot = replace(robot, links=(link, robot.links[1]))
    with pytest.warns(DescriptionWarning, match="hydrodynamic link data is dropped.*link1"):
        to_urdf(robot)


# ----------------------------------------------------------------------------------------------
# Pinocchio reads the exported file


try:  # test-only oracle: the tests that use it are marked and skip alone (see tests/conftest.py)
    import pinocchio as pin
except ImportError:
    pin = None


def pin_q(model, q: np.ndarray) -> np.ndarray:
    """Pinocchio configuration: continuous joints take (cos, sin)."""
    out: list[float] = []
    for jid in range(1, model.njoints):
        qi = q[jid - 1]
        out += [math.cos(qi), math.sin(qi)] if model.joints[jid].nq == 2 else [qi]
    return np.array(out)


@pytest.mark.oracle("pinocchio")
@pytest.mark.parametrize("name", BUILTINS)
def test_pinocchio_matches_robodyn_on_the_exported_urdf(name, tmp_path):
    robot = builtin(name)
    path = tmp_path / f"{name}.urdf"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DescriptionWarning)
        to_urdf(robot, path)
    model = pin.buildModelFromUrdf(str(path))
    assert tuple(model.names)[1:] == robot.joint_names
    dyn = dynamics_of(name)
    model.armature = dyn.rotor  # URDF has no rotor inertia; Pinocchio takes it as armature
    model.gravity.linear = as_array(robot.gravity, robot).ravel()  # nor gravity
    data = model.createData()
    worst = 0.0
    for q, qd, qdd in random_states(robot.dof, 4, seed=5):
        pq = pin_q(model, q)
        m = pin.crba(model, data, pq)
        m = np.triu(m) + np.triu(m, 1).T
        errors = (relative_error(m, dyn.M(q)),
                  relative_error(pin.computeGeneralizedGravity(model, data, pq), dyn.g(q)),
                  relative_error(pin.rnea(model, data, pq, qd, qdd),
                                 dyn.tau_rigid(q, qd, qdd) + dyn.rotor * qdd))
        worst = max(worst, *errors)
    assert worst < 1e-12, worst


# ----------------------------------------------------------------------------------------------
# Bad input


def test_unknown_parameter_is_rejected():
    with pytest.raises(ValueError, match=r"unknown parameter\(s\) \['length'\].*declared: m1, m2"):
        to_urdf(builtin("planar_2r"), parameters={"length": 1.0})


def test_non_finite_parameter_is_rejected():
    with pytest.raises(ValueError, match="parameter 'l1'.*not finite"):
        to_urdf(builtin("planar_2r"), parameters={"l1": float("nan")})


def test_undeclared_symbol_is_rejected():
    robot = builtin("trolley_double_pendulum")
    link = replace(robot.links[0], mass=sp.Symbol("mystery", real=True))
    robot = replace(robot, links=(link, *robot.links[1:]))
    with pytest.raises(ValueError, match=r"joints\[0\] \(x\)\.link\.mass.*mystery.*not a declared parameter"):
        to_urdf(robot)


def test_duplicate_names_are_rejected():
    robot = builtin("planar_2r")
    robot = replace(robot, links=(robot.links[0], replace(robot.links[1], name="link1")))
    with pytest.raises(ValueError, match="two links named 'link1'"):
        to_urdf(robot)


def test_not_a_robot_is_rejected():
    with pytest.raises(TypeError, match="expected a robodyn Robot, got str"):
        to_urdf("puma560")


@quiet
def test_unwritable_path_names_the_file(tmp_path):
    path = tmp_path / "missing" / "arm.urdf"
    with pytest.raises(OSError, match=r"missing/arm\.urdf: cannot write the URDF file"):
        to_urdf(builtin("planar_2r"), path)
    with pytest.raises(OSError, match="cannot write the URDF file"):
        to_urdf(builtin("planar_2r"), tmp_path)  # a directory


def test_export_by_format_name(tmp_path):
    robot = builtin("planar_2r")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DescriptionWarning)
        assert export(robot, "URDF") == to_urdf(robot)
    with pytest.raises(ValueError, match="unknown export format 'sdf'; choose one of urdf, mjcf"):
        export(robot, "sdf", tmp_path / "arm.sdf")
    assert not (tmp_path / "arm.sdf").exists()
