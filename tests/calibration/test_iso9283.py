"""ISO 9283: pose accuracy and repeatability, test cube points, overshoot and stabilisation."""

from __future__ import annotations

import math

import numpy as np
import pytest

from robodyn.calibration.iso9283 import (
    cube_corners,
    cube_points,
    overshoot_stabilisation,
    pose_characteristics,
    pose_characteristics_from_csv,
)


def test_accuracy_and_repeatability_by_hand():
    commanded = np.array([[0.0, 0.0, 0.0]])
    # three cycles around the barycentre (1, 2, 2) mm at distances 1, 1, 2 mm
    bar = np.array([1e-3, 2e-3, 2e-3])
    attained = np.array([[bar + [1e-3, 0, 0], bar + [0, -1e-3, 0], bar + [-2e-3, 1e-3, 0]]])
    # the barycentre of these is bar + (-1/3, 0, 0) mm: recompute by hand
    x_bar = attained[0].mean(axis=0)
    pc = pose_characteristics(commanded, attained)
    np.testing.assert_allclose(pc.barycentre[0], x_bar)
    np.testing.assert_allclose(pc.ap_xyz[0], x_bar)
    assert pc.ap[0] == pytest.approx(np.linalg.norm(x_bar))
    lj = np.linalg.norm(attained[0] - x_bar, axis=1)
    s_l = math.sqrt(((lj - lj.mean()) ** 2).sum() / 2)
    assert pc.rp[0] == pytest.approx(lj.mean() + 3 * s_l)
    assert pc.cycles == 3 and pc.labels == ("P1",)


def test_repeatability_of_gaussian_scatter():
    rng = np.random.default_rng(0)
    sigma = 1e-4
    attained = np.array([0.5, 0.1, 0.3]) + rng.normal(0, sigma, (5, 3000, 3))
    pc = pose_characteristics(np.full((5, 3), [0.5, 0.1, 0.3]), attained)
    # l follows a Maxwell distribution: mean 2 sqrt(2/pi) sigma, std sigma sqrt(3 - 8/pi)
    expected = sigma * (2 * math.sqrt(2 / math.pi) + 3 * math.sqrt(3 - 8 / math.pi))
    np.testing.assert_allclose(pc.rp, expected, rtol=0.05)
    assert np.all(pc.ap < 1e-5)


def test_orientation_accuracy_and_repeatability():
    abc = np.array([[[0.01, 0.0, 0.0], [0.03, 0.0, 0.0]]])
    pc = pose_characteristics(np.zeros((1, 3)), np.zeros((1, 2, 3)), commanded_abc=np.zeros((1, 3)),
                              attained_abc=abc)
    np.testing.assert_allclose(pc.ap_abc[0], [0.02, 0, 0])
    np.testing.assert_allclose(pc.rp_abc[0], [3 * np.std([0.01, 0.03], ddof=1), 0, 0])


def test_cube_points_for_the_500_mm_cube():
    c = np.array([0.6, 0.0, 0.4])
    p = cube_points(c, 0.5)
    corners = cube_corners(c, 0.5)
    np.testing.assert_allclose(p[0], c)  # P1: the centre
    diag = np.linalg.norm(corners[6] - corners[0])
    assert diag == pytest.approx(math.sqrt(0.5**2 + 0.5**2 + 0.5**2))
    for k, corner in zip(range(1, 5), corners[[0, 1, 6, 7]], strict=True):
        assert np.linalg.norm(p[k] - corner) == pytest.approx(0.1 * diag)
    # all five in the measuring plane C1-C2-C7-C8
    n = np.cross(corners[1] - corners[0], corners[7] - corners[0])
    np.testing.assert_allclose((p - corners[0]) @ n, 0, atol=1e-15)
    with pytest.raises(ValueError, match="10 %"):
        cube_points(c, 0.5, fraction=0.2)


def test_overshoot_and_stabilisation_of_a_known_trajectory():
    t = np.arange(0, 1.0, 0.01)
    s = np.where(t < 0.2, 5e-3 * (1 - t / 0.2), 0.0)  # approach along +x to the target
    s = s + np.where((t >= 0.2) & (t < 0.4), -0.3e-3 * np.sin(np.pi * (t - 0.2) / 0.2), 0.0)  # overshoot
    s = s + np.where((t >= 0.4) & (t < 0.5), 0.15e-3 * np.sin(np.pi * (t - 0.4) / 0.1), 0.0)  # rebound
    x = np.column_stack((0.6 + s, np.full_like(t, 0.1), np.full_like(t, 0.3)))
    res = overshoot_stabilisation(t, x, band=0.1e-3, attained=[0.6, 0.1, 0.3])
    assert res.overshoot == pytest.approx(0.3e-3, rel=1e-3)
    inside = np.abs(s) <= 0.1e-3
    first = t[np.argmax(inside)]
    last_out = t[np.flatnonzero(~inside)[-1] + 1]
    assert res.stabilisation_time == pytest.approx(last_out - first)
    assert res.settled


def test_overshoot_rejects_bad_trajectories():
    with pytest.raises(ValueError, match="increase"):
        overshoot_stabilisation([0, 1, 1], np.zeros((3, 3)), band=1e-4)
    with pytest.raises(ValueError, match="NaN"):
        overshoot_stabilisation([0, 1, 2], np.full((3, 3), np.nan), band=1e-4)


def test_pose_characteristics_from_csv(tmp_path):
    rows = ["pose,x_cmd,y_cmd,z_cmd,x,y,z"]
    rng = np.random.default_rng(1)
    pts = {"P1": [0.6, 0.0, 0.4], "P2": [0.5, -0.2, 0.3]}
    attained = {k: np.array(v) + 2e-4 + rng.normal(0, 5e-5, (4, 3)) for k, v in pts.items()}
    for cycle in range(4):
        for k, v in pts.items():
            rows.append(",".join([k, *(repr(float(a)) for a in (*v, *attained[k][cycle]))]))
    path = tmp_path / "iso.csv"
    path.write_text("\n".join(rows) + "\n")
    pc = pose_characteristics_from_csv(path)
    direct = pose_characteristics(np.array(list(pts.values())), np.array(list(attained.values())))
    np.testing.assert_allclose(pc.ap, direct.ap)
    np.testing.assert_allclose(pc.rp, direct.rp)
    assert pc.labels == ("P1", "P2")
    path.write_text("\n".join(rows[:-1]) + "\n")
    with pytest.raises(ValueError, match="different numbers of cycles"):
        pose_characteristics_from_csv(path)
