"""The AA300 design study runs end to end and sizes its actuators."""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

import robodyn as rd
from robodyn.studies.aa300 import run_study, with_payload


def test_payload_is_merged_into_the_last_link(aa300):
    robot = with_payload(aa300.robot, 50.0)
    model = rd.compile_model(robot)
    # the slide carries arm + tube + gripper + payload whatever the pose
    q = np.array([0.4, 0.7, 1.1])
    np.testing.assert_allclose(model.gravity(q)[1], (201.4534 + 118.9522 + 65.1572 + 50.0) * 9.81, rtol=1e-12)
    # the payload adds 50 (d_tool)^2 about the tube axis
    # tube column of the Jacobian: v = z x (p_tool - o), |v| = the tool's lever about the tube axis
    lever = np.linalg.norm(aa300.jacobian(q)[:3, 2])
    np.testing.assert_allclose(model.mass_matrix(q)[2, 2] - aa300.mass_matrix(q)[2, 2], 50.0 * lever**2,
                               rtol=1e-9)


@pytest.mark.slow
def test_aa300_study_sizes_the_motors(tmp_path):
    study = run_study(tmp_path, payload=50.0, fps=2)
    names = [m.name for m in study.manoeuvres]
    assert names == ["approach shelf", "lift off shelf", "retract", "lift", "rotate", "place"]
    column, slide, tube = study.demands
    static = (201.4534 + 118.9522 + 65.1572 + 50.0) * 9.81  # 4273 N holds the arm up
    assert slide.peak > static and slide.peak_ideal > static
    assert slide.rms > 0.95 * static
    # the applied peaks are close to the ideal (perfect tracking) ones
    for d in study.demands:
        assert 0.9 * d.peak_ideal < d.peak < 1.3 * d.peak_ideal, d
        assert len(d.per_manoeuvre) == 6 and max(d.per_manoeuvre) == d.peak
    # the column and tube work hardest in the rotation
    assert column.per_manoeuvre[4] == column.peak
    assert study.max_tracking_error.max() < 0.03
    assert "upper_arm" in study.table()
    for path in study.figures:
        assert path.stat().st_size > 10_000
    with Image.open(study.animation) as gif:
        assert gif.n_frames > 10
