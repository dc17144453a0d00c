"""Vectorised model kinematics: nominal FK against the symbolic FK, analytic Jacobians against
finite differences, and the DH table recovered from the PUMA 560 description."""

from __future__ import annotations

import numpy as np
import pytest

from robodyn.calibration import MODELS, build_model, robot_geometry
from robodyn.calibration.kinematics import inv, rot, trans
from tests.calibration.helpers import TRACKER, poses, robot, symbolic_fk

ROBOTS = ("puma560", "puma560_akb", "kinova_gen3", "aa300")


@pytest.mark.parametrize("name", ROBOTS)
def test_nominal_model_fk_matches_symbolic_fk(name):
    r = robot(name)
    q = np.random.default_rng(1).uniform(-2.5, 2.5, (12, r.dof))
    ref = symbolic_fk(r)(q)
    g = robot_geometry(r)
    for model in MODELS:
        em = build_model(model, g, orientation=True)
        ev = em.evaluate(em.initial, q, derivatives=False)
        np.testing.assert_allclose(ev.position, ref[:, :3, 3], rtol=0, atol=1e-12, err_msg=model)
        np.testing.assert_allclose(ev.rotation, ref[:, :3, :3], rtol=0, atol=1e-12, err_msg=model)


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("name", ("puma560", "aa300"))
def test_analytic_jacobians_match_central_differences(name, model):
    r = robot(name)
    g = robot_geometry(r)
    em = build_model(model, g, base=TRACKER, orientation=True)
    rng = np.random.default_rng(2)
    p = em.initial + rng.normal(0, 1e-2, em.n_params)
    q = poses(name, 5, 3)
    ev = em.evaluate(p, q)
    h = 1e-6
    for k in range(em.n_params):
        dp = np.zeros(em.n_params)
        dp[k] = h
        plus, minus = em.evaluate(p + dp, q, derivatives=False), em.evaluate(p - dp, q, derivatives=False)
        lin = (plus.position - minus.position) / (2 * h)
        # angular rows: small world rotation w with R(p + dp) = exp(w) R(p)
        dr = plus.rotation @ np.swapaxes(minus.rotation, 1, 2)
        ang = np.stack((dr[:, 2, 1] - dr[:, 1, 2], dr[:, 0, 2] - dr[:, 2, 0], dr[:, 1, 0] - dr[:, 0, 1]), 1)
        ang = ang / 2 / (2 * h)
        np.testing.assert_allclose(ev.jac_param[:, :3, k], lin, atol=1e-7, err_msg=em.names[k])
        np.testing.assert_allclose(ev.jac_param[:, 3:, k], ang, atol=1e-7, err_msg=em.names[k])
    for j in range(r.dof):
        dq = np.zeros(r.dof)
        dq[j] = h
        lin = (em.evaluate(p, q + dq, derivatives=False).position
               - em.evaluate(p, q - dq, derivatives=False).position) / (2 * h)
        np.testing.assert_allclose(ev.jac_joint[:, :3, j], lin, atol=1e-7)


def test_puma560_dh_parameters_are_its_own_table():
    em = build_model("dh", robot_geometry(robot("puma560")))
    values = dict(zip(em.names, em.initial, strict=True))
    table = {  # (a, alpha, d) of the description, theta offsets all zero
        "q1": (0, np.pi / 2, 0.67183), "q2": (0.4318, 0, 0), "q3": (0.0203, -np.pi / 2, 0.15005),
        "q4": (0, np.pi / 2, 0.4318), "q5": (0, -np.pi / 2, 0), "q6": (0, 0, 0),
    }
    for joint, (a, alpha, d) in table.items():
        assert values[f"{joint}.a"] == pytest.approx(a, abs=1e-14)
        assert values[f"{joint}.alpha"] == pytest.approx(alpha, abs=1e-14)
        assert values[f"{joint}.d"] == pytest.approx(d, abs=1e-14)
        assert values[f"{joint}.theta"] == pytest.approx(0, abs=1e-14)


def test_parameter_counts_per_joint_type():
    # PUMA: 6 revolute joints, joints 2 and 3 parallel; AA300: revolute, prismatic, revolute, all parallel
    counts = {}
    for name in ("puma560", "aa300"):
        g = robot_geometry(robot(name))
        counts[name] = {m: build_model(m, g).n_params for m in MODELS}
    # base 6 + tool 3 + per joint: DH 4; Hayati 4 (5 for a prismatic joint before a parallel axis);
    # S-model 6; POE 4 per revolute, 2 per prismatic (no base)
    assert counts["puma560"] == {"dh": 33, "hayati": 33, "s-model": 45, "poe": 27}
    assert counts["aa300"] == {"dh": 21, "hayati": 22, "s-model": 28, "poe": 13}


def test_hayati_link_at_parallel_axes_has_no_d():
    em = build_model("hayati", robot_geometry(robot("puma560")))
    assert "q2.beta" in em.names and "q2.d" not in em.names
    assert "q3.d" in em.names and "q3.beta" not in em.names


def test_inverse_of_homogeneous_transforms():
    t = trans(0.1, -0.2, 0.3) @ rot("x", 0.4) @ rot("z", -1.1)
    np.testing.assert_allclose(inv(t) @ t, np.eye(4), atol=1e-15)
    np.testing.assert_allclose(inv(np.stack([t, t])), np.stack([np.linalg.inv(t)] * 2), atol=1e-14)
