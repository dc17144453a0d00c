"""Random serial URDF chains: robodyn's Newton-Euler against Pinocchio (test-only oracle)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import robodyn as rd
from tests.numeric_eval import evaluator, program_evaluator
from tests.urdf_chains import pin_q, random_urdf

try:  # test-only oracle: the tests that use it are marked and skip alone (see tests/conftest.py)
    import pinocchio as pin
except ImportError:
    pin = None


@pytest.mark.oracle("pinocchio")
@pytest.mark.parametrize("seed", [pytest.param(s, marks=pytest.mark.slow) if s in (0, 2, 3) else s
                                  for s in range(6)])
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


@pytest.mark.slow
@pytest.mark.data(GEN3_URDF)
@pytest.mark.oracle("pinocchio")
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
