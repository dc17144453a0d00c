"""Random serial URDF chains: robodyn's Newton-Euler against Pinocchio (test-only oracle)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import robodyn as rd
from tests.numeric_eval import evaluator, program_evaluator

pin = pytest.importorskip("pinocchio")


def random_urdf(rng: np.random.Generator, n: int) -> str:
    """A serial chain of n moving joints (revolute, prismatic, continuous) plus fixed joints."""

    def vec(scale):
        return " ".join(f"{v:.6f}" for v in rng.uniform(-scale, scale, 3))

    def inertial():
        a = rng.uniform(0.05, 0.5, 3)  # principal moments that satisfy the triangle inequality
        a = np.sort(a)
        a[2] = min(a[2], a[0] + a[1] - 1e-3)
        return (f'<inertial><origin xyz="{vec(0.2)}" rpy="{vec(np.pi)}"/>'
                f'<mass value="{rng.uniform(0.5, 5):.6f}"/>'
                f'<inertia ixx="{a[0]:.6f}" iyy="{a[1]:.6f}" izz="{a[2]:.6f}" '
                f'ixy="0" ixz="0" iyz="0"/></inertial>')

    links = ['<link name="base"/>']
    joints = []
    parent = "base"
    k = 0
    for i in range(n):
        if rng.uniform() < 0.3:  # a fixed joint with a massive link in between
            k += 1
            name = f"fixed_link{k}"
            links.append(f'<link name="{name}">{inertial()}</link>')
            joints.append(f'<joint name="fix{k}" type="fixed"><parent link="{parent}"/>'
                          f'<child link="{name}"/><origin xyz="{vec(0.3)}" rpy="{vec(np.pi)}"/>'
                          f'</joint>')
            parent = name
        jtype = rng.choice(["revolute", "prismatic", "continuous"])
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        name = f"link{i + 1}"
        links.append(f'<link name="{name}">{inertial()}</link>')
        limit = '<limit lower="-3" upper="3" effort="100" velocity="5"/>' if jtype != "continuous" else ""
        joints.append(f'<joint name="j{i + 1}" type="{jtype}"><parent link="{parent}"/>'
                      f'<child link="{name}"/><origin xyz="{vec(0.3)}" rpy="{vec(np.pi)}"/>'
                      f'<axis xyz="{axis[0]:.9f} {axis[1]:.9f} {axis[2]:.9f}"/>{limit}</joint>')
        parent = name
    return f'<robot name="random">{"".join(links)}{"".join(joints)}</robot>'


def pin_q(model, q):
    """Pinocchio configuration vector: continuous joints use (cos, sin)."""
    out = []
    for jid in range(1, model.njoints):
        joint = model.joints[jid]
        qi = q[jid - 1]
        if joint.nq == 2:
            out += [np.cos(qi), np.sin(qi)]
        else:
            out.append(qi)
    return np.array(out)


@pytest.mark.parametrize("seed", range(6))
def test_random_chain_matches_pinocchio(tmp_path, seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(2, 6))
    path = tmp_path / f"random_{seed}.urdf"
    path.write_text(random_urdf(rng, n))
    robot = rd.load(path)
    assert robot.dof == n
    eom = rd.derive(robot, method="newton_euler")
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    # the recursive forms (their expansion is checked on the built-in robots)
    f_m = program_evaluator(eom, eom.M_rigid_form)
    f_g = program_evaluator(eom, eom.g_form)
    f_tau = program_evaluator(eom, eom.program)
    f_fk = evaluator(eom, eom.fk)
    for _ in range(4):
        q, qd, qdd = rng.uniform(-2, 2, n), rng.uniform(-2, 2, n), rng.uniform(-2, 2, n)
        pq = pin_q(model, q)
        np.testing.assert_allclose(f_m(q), pin.crba(model, data, pq), atol=1e-9, rtol=1e-9)
        np.testing.assert_allclose(f_g(q).ravel(), pin.computeGeneralizedGravity(model, data, pq),
                                   atol=1e-9, rtol=1e-9)
        np.testing.assert_allclose(f_tau(q, qd, qdd).ravel(), pin.rnea(model, data, pq, qd, qdd),
                                   atol=1e-9, rtol=1e-9)
        pin.forwardKinematics(model, data, pq)
        np.testing.assert_allclose(f_fk(q)[:3, 3], data.oMi[model.njoints - 1].translation,
                                   atol=1e-9)


GEN3_URDF = Path(__file__).resolve().parents[3] / "shared" / "data" / "kinova-gen3" / "gen3.urdf"


@pytest.mark.skipif(not GEN3_URDF.exists(), reason="../shared/data/kinova-gen3 not beside the repo")
def test_builtin_kinova_gen3_matches_pinocchio_on_the_original_urdf():
    eom = rd.derive(rd.load("kinova_gen3"), method="newton_euler")
    model = pin.buildModelFromUrdf(str(GEN3_URDF))
    data = model.createData()
    f_tau = program_evaluator(eom, eom.program)
    f_m = program_evaluator(eom, eom.M_rigid_form)
    f_g = program_evaluator(eom, eom.g_form)
    f_y = program_evaluator(eom, eom.regressor_program)
    p = np.array(eom.params.xreplace(eom.numeric()), dtype=float).ravel()
    rng = np.random.default_rng(11)
    for _ in range(3):
        q, qd, qdd = rng.uniform(-2, 2, 7), rng.uniform(-2, 2, 7), rng.uniform(-2, 2, 7)
        pq = pin_q(model, q)
        np.testing.assert_allclose(f_m(q), pin.crba(model, data, pq), atol=1e-9)
        np.testing.assert_allclose(f_g(q).ravel(), pin.computeGeneralizedGravity(model, data, pq),
                                   atol=1e-9)
        ref = pin.rnea(model, data, pq, qd, qdd)
        np.testing.assert_allclose(f_tau(q, qd, qdd).ravel(), ref, atol=1e-9)
        # gen3 has no drives or friction: the regressor reproduces the rigid-body torques
        np.testing.assert_allclose(f_y(q, qd, qdd) @ p, ref, atol=1e-9)
