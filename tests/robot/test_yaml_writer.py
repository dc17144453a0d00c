"""YAML writer: ``load_yaml_text(dump_yaml(robot))`` keeps kinematics and inertial data."""

from __future__ import annotations

import importlib.util
import math
import warnings
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
import yaml

from robodyn import spatial as S
from robodyn.robot import placement, yaml_loader
from robodyn.robot.chain import ChainElement, assemble
from robodyn.robot.errors import DescriptionWarning
from robodyn.robot.hydro import parse_hydro
from robodyn.robot.model import Drive, Friction, Link, Robot
from robodyn.robot.yaml_writer import dump_yaml, matrix_to_rpy

ROOT = Path(__file__).resolve().parents[2]
GEN3 = ROOT.parent / "shared" / "data" / "kinova-gen3" / "gen3.urdf"
LIBRARY = ROOT / "src" / "robodyn" / "robot" / "library"
needs_gen3 = pytest.mark.data(GEN3)


def reload(robot: Robot) -> Robot:
    """``load_yaml_text(dump_yaml(robot))`` (plausibility warnings ignored)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DescriptionWarning)
        return yaml_loader.load_yaml_text(dump_yaml(robot), source="dumped.yaml")


def link_frames(robot: Robot, q: np.ndarray, params: dict | None = None) -> list[np.ndarray]:
    """World poses of every link frame and, last, of the tool, each shape (4, 4)."""
    subs = {**robot.defaults(), **(params or {})}
    t = sp.ImmutableMatrix(robot.base)
    out = []
    for joint, qi in zip(robot.joints, q, strict=True):
        if joint.type == "revolute":
            motion = S.rot_h(S.axis_angle(joint.axis, sp.Float(qi)))
        else:
            motion = S.trans(*(joint.axis * sp.Float(qi)))
        t = t * joint.pre * motion * joint.post
        out.append(t)
    out.append(t * robot.tool)
    return [np.array(m.subs(subs).evalf(), dtype=float) for m in out]


def world_inertials(
    robot: Robot, q: np.ndarray, params: dict | None = None
) -> list[tuple[float, np.ndarray, np.ndarray]]:
    """Per link: mass (kg), COM in the world (m), inertia about the COM in world axes."""
    subs = {**robot.defaults(), **(params or {})}
    out = []
    for t, link in zip(link_frames(robot, q, params), robot.links, strict=False):
        r, p = t[:3, :3], t[:3, 3]
        com = np.array(link.com.subs(subs), dtype=float).ravel()
        inertia = np.array(link.inertia.subs(subs), dtype=float)
        out.append((float(link.mass.subs(subs)), r @ com + p, r @ inertia @ r.T))
    return out


def assert_same_robot(a: Robot, b: Robot, rng: np.random.Generator, atol: float = 1e-12) -> None:
    """Same joint count, FK (every moving frame and the tool) and world inertials at random q."""
    assert a.dof == b.dof
    assert a.joint_names == b.joint_names
    assert [lk.name for lk in a.links] == [lk.name for lk in b.links]
    assert [lk.mass for lk in a.links] == [lk.mass for lk in b.links]
    for _ in range(3):
        q = rng.uniform(-math.pi, math.pi, a.dof)
        np.testing.assert_allclose(link_frames(b, q)[-1], link_frames(a, q)[-1], atol=atol)
        for (ma, ca, ia), (mb, cb, ib) in zip(
            world_inertials(a, q), world_inertials(b, q), strict=True
        ):
            assert ma == mb
            np.testing.assert_allclose(cb, ca, atol=atol)
            np.testing.assert_allclose(ib, ia, atol=atol)


def _rot(rng: np.random.Generator) -> np.ndarray:
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


def _f(x: float) -> sp.Float:
    return sp.Float(float(x))


def random_link(rng: np.random.Generator, name: str) -> Link:
    """A plausible random link (box principal moments, rotated)."""
    a, b, c = rng.uniform(0.05, 0.5, 3) ** 2
    m = rng.uniform(0.2, 5.0)
    r = _rot(rng)
    tensor = r @ np.diag(m / 12 * np.array([b + c, a + c, a + b])) @ r.T
    tensor = (tensor + tensor.T) / 2
    return Link(
        name,
        _f(m),
        sp.ImmutableMatrix([_f(v) for v in rng.uniform(-0.2, 0.2, 3)]),
        sp.ImmutableMatrix(3, 3, [_f(v) for v in tensor.ravel()]),
    )


def random_robot(rng: np.random.Generator, n: int) -> Robot:
    """A random chain mixing DH (post transforms), modified DH, origin and fixed elements."""
    elements = []
    for k in range(n):
        kind = rng.choice(["dh", "mdh", "origin", "fixed"]) if k else "dh"
        jtype = str(rng.choice(["revolute", "prismatic"]))
        link = random_link(rng, f"link{k}")
        if kind in ("dh", "mdh"):
            a, alpha, d, theta = (_f(v) for v in rng.uniform(-1, 1, 4))
            build = placement.from_dh if kind == "dh" else placement.from_mdh
            pre, axis, post = build(jtype, a, alpha, d, theta)
        else:
            v = rng.normal(size=3)
            pre, axis, post = placement.from_origin(
                [_f(x) for x in rng.uniform(-0.5, 0.5, 3)],
                [_f(x) for x in rng.uniform(-math.pi, math.pi, 3)],
                [_f(x) for x in v / np.linalg.norm(v)],
            )
        jt = "fixed" if kind == "fixed" else jtype
        elements.append(ChainElement(f"j{k}", jt, pre, axis, post, link))
    base = S.transform(S.rpy_to_matrix(*map(_f, rng.uniform(-1, 1, 3))), [_f(0.1), 0, _f(0.3)])
    tool = S.transform(S.rpy_to_matrix(0, sp.pi / 2, 0), [0, 0, _f(0.12)])
    return assemble(f"random{n}", elements, base=base, tool=tool, source="random")


# ----------------------------------------------------------------------------------------------


@needs_gen3
def test_kinova_gen3_round_trip() -> None:
    from robodyn.robot.urdf import load_urdf

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DescriptionWarning)
        robot = load_urdf(GEN3)
    back = reload(robot)
    assert_same_robot(robot, back, np.random.default_rng(3))
    # no post transforms: the links are written unchanged, numbers exactly
    for a, b in zip(robot.links, back.links, strict=True):
        assert (a.mass, a.com, a.inertia) == (b.mass, b.com, b.inertia)
    for a, b in zip(robot.joints, back.joints, strict=True):
        assert (a.pre, a.axis, a.lower, a.upper) == (b.pre, b.axis, b.lower, b.upper)
        assert (a.velocity_limit, a.effort_limit) == (b.velocity_limit, b.effort_limit)
    assert back.tool == robot.tool or np.allclose(
        np.array(back.tool, dtype=float), np.array(robot.tool, dtype=float), atol=1e-15
    )
    assert back.gravity == robot.gravity


@pytest.mark.parametrize("seed", range(6))
def test_random_robots_round_trip(seed: int) -> None:
    rng = np.random.default_rng(100 + seed)
    robot = random_robot(rng, int(rng.integers(2, 7)))
    assert any(j.post != sp.eye(4) for j in robot.joints)  # exercises the post push
    assert_same_robot(robot, reload(robot), rng)


def test_puma560_round_trip() -> None:
    from robodyn.robot.load import load

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DescriptionWarning)
        robot = load("puma560")
    back = reload(robot)
    assert_same_robot(robot, back, np.random.default_rng(5))
    for a, b in zip(robot.joints, back.joints, strict=True):
        assert a.drive == b.drive
        assert a.friction == b.friction  # motor-side friction is written reflected, side: joint
        assert (a.lower, a.upper) == (b.lower, b.upper)


def parametric_robot() -> Robot:
    """A symbolic two-link arm: DH placements with exact angles and parameters l, m."""
    length, m = sp.Symbol("l", real=True), sp.Symbol("m", real=True)
    rod = sp.ImmutableMatrix(sp.diag(0, m * length**2 / 12, m * length**2 / 12))
    elements = []
    for k, alpha in enumerate((sp.pi / 2, 0)):
        pre, axis, post = placement.from_dh(
            "revolute", length, alpha, length / 2, sp.pi / 3 * k
        )
        link = Link(f"link{k}", m, sp.ImmutableMatrix([-length / 2, 0, 0]), rod)
        fields = {
            "lower": -2 * sp.pi / 3,
            "upper": 2 * sp.pi / 3,
            "drive": Drive(gear_ratio=sp.Integer(-50), rotor_inertia=sp.Float(1e-5)),
            "friction": Friction(viscous=sp.Float(0.1), coulomb_positive=sp.Float(0.2),
                                 coulomb_negative=sp.Float(0.3), offset=sp.Float(-0.01)),
        }
        elements.append(ChainElement(f"j{k}", "revolute", pre, axis, post, link, fields))
    return assemble("two_link", elements, parameters={"l": 0.5, "m": 2.0}, source="memory")


def test_parameters_and_expressions_round_trip() -> None:
    robot = parametric_robot()
    text = dump_yaml(robot)
    assert "parameters: {l: 0.5, m: 2.0}" in text
    assert "l/2" in text and "pi/2" in text and "2*pi/3" in text
    back = reload(robot)
    assert dict(back.parameters) == {"l": 0.5, "m": 2.0}
    length, m = sp.Symbol("l", real=True), sp.Symbol("m", real=True)
    assert [lk.mass for lk in back.links] == [m, m]
    assert back.joints[0].lower == -2 * sp.pi / 3
    for a, b in zip(robot.joints, back.joints, strict=True):
        assert (a.drive, a.friction) == (b.drive, b.friction)
    rng = np.random.default_rng(11)
    assert_same_robot(robot, back, rng)
    # and at other parameter values: the expressions, not only their defaults, are kept
    params = {length: 0.8, m: 3.5}
    for _ in range(3):
        q = rng.uniform(-math.pi, math.pi, 2)
        np.testing.assert_allclose(
            link_frames(back, q, params)[-1], link_frames(robot, q, params)[-1], atol=1e-12
        )
        for (ma, ca, ia), (mb, cb, ib) in zip(
            world_inertials(robot, q, params), world_inertials(back, q, params), strict=True
        ):
            assert ma == pytest.approx(mb, rel=1e-15)
            np.testing.assert_allclose(cb, ca, atol=1e-12)
            np.testing.assert_allclose(ib, ia, atol=1e-12)


def test_header_description_and_yaml_floats() -> None:
    robot = parametric_robot()
    text = dump_yaml(robot)
    assert text.startswith("# Generated by robodyn from memory.")
    data = yaml.safe_load(text)
    assert data["name"] == "two_link"
    assert data["joints"][0]["friction"]["side"] == "joint"
    # 1e-05 is written so that YAML 1.1 reads a float, not a text
    assert data["joints"][0]["drive"]["rotor_inertia"] == 1e-05
    assert isinstance(data["joints"][0]["drive"]["rotor_inertia"], float)


def test_hydro_is_written_field_by_field_or_refused() -> None:
    block = {"cylinders": [{"radius": 0.05, "length": 0.4, "axis": [0, 0, 2]}], "drag": 1.3}
    hydro = parse_hydro(block, {}, {}, where="test")
    pre, axis, post = placement.from_origin([0, 0, sp.Float(0.1)], [0, 0, 0], [0, 0, 1])
    link = Link("l0", sp.Integer(1), sp.ImmutableMatrix([0, 0, 0]), sp.ImmutableMatrix(sp.eye(3)),
                hydro=hydro)
    robot = assemble("wet", [ChainElement("j0", "revolute", pre, axis, post, link)])
    back = reload(robot).links[0].hydro
    # what the block gave, and the defaults, read back exactly; the volume pi r^2 L within rounding
    assert back.cylinders == hydro.cylinders and back.cylinders[0].axis == sp.ImmutableMatrix([0, 0, 1])
    assert (back.drag, back.added_mass, back.lift, back.quadrature) == (1.3, 1.0, 0.0, 6)
    assert back.center_of_buoyancy == sp.ImmutableMatrix([0, 0, 0.2])
    assert float(back.volume) == pytest.approx(np.pi * 0.05**2 * 0.4, rel=1e-14)
    pre, axis, post = placement.from_dh("revolute", sp.Float(0.3), 0, 0, 0)
    robot = assemble("wet_dh", [ChainElement("j0", "revolute", pre, axis, post, link)])
    with pytest.raises(ValueError, match="hydro"):
        dump_yaml(robot)


def test_unwritable_expression_is_refused() -> None:
    robot = parametric_robot()
    length = sp.Symbol("l", real=True)
    bad = Link("link0", sp.sinh(length), robot.links[0].com, robot.links[0].inertia)
    robot = Robot(robot.name, robot.joints, (bad, robot.links[1]), parameters=robot.parameters)
    with pytest.raises(ValueError, match=r"joints\[0\]\.link\.mass.*sinh"):
        dump_yaml(robot)


@pytest.mark.parametrize(
    ("rpy", "expected"),
    [
        ((sp.pi / 2, 0, 0), (sp.pi / 2, 0, 0)),
        ((0, 0, -sp.pi / 3), (0, 0, -sp.pi / 3)),
        ((sp.pi / 4, sp.pi / 6, sp.pi / 3), (sp.pi / 4, sp.pi / 6, sp.pi / 3)),
        ((0, sp.pi / 2, 0), (0, sp.pi / 2, 0)),  # gimbal lock: yaw set to zero
    ],
)
def test_matrix_to_rpy_exact(rpy: tuple, expected: tuple) -> None:
    got = matrix_to_rpy(S.rpy_to_matrix(*rpy))
    assert all(sp.simplify(g - e) == 0 for g, e in zip(got, expected, strict=True))


def test_matrix_to_rpy_numeric_and_near_gimbal_lock() -> None:
    rng = np.random.default_rng(0)
    cases = [rng.uniform(-math.pi, math.pi, 3) for _ in range(20)]
    cases += [np.array([0.3, math.pi / 2 - 1e-9, -1.2]), np.array([0.3, -math.pi / 2, 2.0])]
    for rpy in cases:
        r = S.rpy_to_matrix(*map(_f, rpy))
        back = S.rpy_to_matrix(*matrix_to_rpy(r))
        np.testing.assert_allclose(np.array(back, dtype=float), np.array(r, dtype=float),
                                   atol=1e-15)


@needs_gen3
def test_builtin_kinova_gen3_is_reproducible() -> None:
    """``tools/urdf_to_yaml.py`` regenerates the shipped kinova_gen3.yaml exactly."""
    script = ROOT / "tools" / "urdf_to_yaml.py"
    spec = importlib.util.spec_from_file_location("urdf_to_yaml", script)
    assert spec is not None and spec.loader is not None
    tool = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(tool)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DescriptionWarning)
        text = tool.convert(
            GEN3,
            name="kinova_gen3",
            source="gen3.urdf of github.com/wissem01chiha/dynamic-identification",
            licence=LIBRARY / "LICENSE-kinova_gen3.txt",
        )
    shipped = (LIBRARY / "kinova_gen3.yaml").read_text(encoding="utf-8")
    assert text == shipped
    assert "Copyright (c) 2022 Wissem CHIHA" in shipped
    assert "wissem01chiha/dynamic-identification" in shipped
