"""Identifiable subsets, named combinations, observability indices and pose selection."""

from __future__ import annotations

import numpy as np
import pytest

from robodyn.calibration import MODELS, build_model, observability, robot_geometry, select_poses
from robodyn.calibration.identifiability import dependency, independent_columns
from robodyn.calibration.kinematics import trans
from robodyn.calibration.pipeline import identifiable_parameters
from tests.calibration.helpers import TARGET, TRACKER, poses, robot


def _model(model: str, name: str = "puma560", target=TARGET):
    """Error model with the tracker placement and a target offset on the flange."""
    g = robot_geometry(robot(name))
    return build_model(model, g, base=TRACKER, target=TRACKER @ g.target @ trans(*target))


def _analysis(model: str, name: str = "puma560", count: int = 60):
    r = robot(name)
    em = _model(model, name)
    free, unid = identifiable_parameters(r, em, em.initial, poses(name, count, 4))
    return em, free, {u.name: u for u in unid}


def test_puma_identifiable_counts_match_the_minimal_model():
    # a complete, minimal model of a 6R arm measured in position has 4 R + 2 P + 3 = 27 parameters
    # (Everett, Driels & Mooring 1987); standard DH at the parallel joints 2-3 loses one of them
    counts = {m: len(_analysis(m)[1]) for m in MODELS}
    assert counts == {"dh": 26, "hayati": 27, "s-model": 27, "poe": 27}


def test_parallel_axis_d_offsets_are_named_as_inseparable():
    _, _, unid = _analysis("dh")
    u = unid["q3.d"]
    assert u.kind == "structural"
    assert [n for n, _ in u.combination] == ["q2.d"]
    assert u.combination[0][1] == pytest.approx(1.0, abs=1e-9)
    assert "q2.d + 1*q3.d" in u.reason
    # Hayati's link has no d at the parallel joints, so nothing is left to separate there
    _, _, unid_h = _analysis("hayati")
    assert "q3.d" not in unid_h and "q2.d" not in unid_h


def test_base_and_tool_redundancies_are_found():
    em, free, unid = _analysis("hayati")
    expected = {"q1.theta", "q1.d", "q6.theta", "q6.d", "q6.a", "q6.alpha"}
    assert set(unid) == expected
    assert {n for n, _ in unid["q1.d"].combination} <= {"base.x", "base.y", "base.z"}
    for name in ("base.x", "base.rz", "tool.x", "tool.z"):
        assert em.index(name) in free
    # the S-model's screws along each axis are redundant with the next joint's d and theta
    _, _, unid_s = _analysis("s-model")
    assert {f"q{i}.{p}" for i in range(1, 7) for p in ("b", "beta")} <= set(unid_s)


def test_a_target_on_the_wrist_centre_leaves_the_wrist_unidentifiable():
    # the PUMA's nominal tool frame is the wrist centre: joints 4-6 cannot move a target there
    r = robot("puma560")
    em = _model("hayati", target=(0, 0, 0))
    free, unid = identifiable_parameters(r, em, em.initial, poses("puma560", 60, 4))
    names = {u.name for u in unid}
    assert {"q4.theta", "q5.theta"} <= names
    assert all(u.kind == "structural" for u in unid)
    assert len(free) < 27


def test_a_joint_that_never_moves_is_reported_with_the_pose_set():
    r = robot("puma560")
    em = _model("hayati")
    q = poses("puma560", 60, 5)
    q[:, 5] = 0.3  # joint 6 never moves
    _, unid = identifiable_parameters(r, em, em.initial, q)
    data = [u for u in unid if u.kind == "pose set"]
    assert data, "a joint that never moves must leave something unidentifiable"
    assert all("q6 take a single value" in u.reason for u in data)


def test_independent_columns_and_dependency_on_a_known_matrix():
    rng = np.random.default_rng(0)
    a = rng.normal(size=(50, 3))
    jac = np.column_stack((a[:, 0], a[:, 1], 2 * a[:, 0] - a[:, 1], a[:, 2], np.zeros(50)))
    assert independent_columns(jac, range(5)) == [0, 1, 3]
    assert independent_columns(jac, [2, 1, 0, 3, 4]) == [2, 1, 3]
    np.testing.assert_allclose(dependency(jac, [0, 1], 2), [2, -1], atol=1e-12)


def test_observability_indices_from_singular_values():
    u, _ = np.linalg.qr(np.random.default_rng(1).normal(size=(12, 3)))
    s = np.array([4.0, 2.0, 0.5])
    jac = u * s  # singular values 4, 2, 0.5
    obs = observability(jac, n_poses=4)
    assert obs.o1 == pytest.approx((4 * 2 * 0.5) ** (1 / 3) / 2)
    assert obs.o2 == pytest.approx(0.5 / 4)
    assert obs.o3 == pytest.approx(0.5)
    assert obs.o4 == pytest.approx(0.25 / 4)
    assert obs.o5 == pytest.approx(1 / (1 / 4 + 1 / 2 + 1 / 0.5))
    assert obs.condition == pytest.approx(8)


def test_pose_selection_beats_random_subsets():
    r = robot("puma560")
    em = _model("hayati")
    cand = poses("puma560", 150, 6)
    free, _ = identifiable_parameters(r, em, em.initial, cand)
    jac = em.evaluate(em.initial, cand).jac_param[:, :3][:, :, free]
    chosen = select_poses(jac, 15, index="O1", exchange_passes=1)
    assert len(set(chosen.tolist())) == 15
    best = observability(jac[chosen].reshape(-1, len(free)), 15).o1
    rng = np.random.default_rng(7)
    randoms = [observability(jac[rng.choice(150, 15, replace=False)].reshape(-1, len(free)), 15).o1
               for _ in range(20)]
    assert best > max(randoms)
    chosen4 = select_poses(jac, 15, index="O4", exchange_passes=1)
    o4 = observability(jac[chosen4].reshape(-1, len(free)), 15).o4
    assert o4 >= observability(jac[chosen].reshape(-1, len(free)), 15).o4


def test_pose_selection_rejects_bad_requests():
    jac = np.zeros((5, 3, 2))
    with pytest.raises(ValueError, match="count"):
        select_poses(jac, 6)
    with pytest.raises(ValueError, match="O1 to O5"):
        select_poses(np.ones((5, 3, 2)), 2, index="O9")
