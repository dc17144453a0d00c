"""The PUMA 560 simulation study: numbers, findings and figures."""

from __future__ import annotations

import math

import pytest

from robodyn.studies.calibration_study import puma_study


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    return puma_study(tmp_path_factory.mktemp("study"), noises=(5e-5,), n_poses=80, n_test=100, seed=3)


def test_complete_models_reach_the_noise_and_dh_does_not(study):
    by_run = {(c.model, c.initial): c for c in study.cases}
    noise_rms = 5e-5 * math.sqrt(3)
    for run in (("hayati", "nominal"), ("s-model", "circle-point"), ("s-model", "nominal"),
                ("poe", "nominal")):
        c = by_run[run]
        assert c.test_before.rms > 1e-3
        assert c.test_after.rms < 1.3 * noise_rms, run
        assert c.test_after_true.rms < c.test_after.rms
    assert by_run[("dh", "nominal")].test_after.rms > 2 * noise_rms


def test_findings_describe_dh_at_the_parallel_joints(study):
    text = " ".join(study.notes)
    assert "parallel joints 2 and 3" in text
    assert "q3.d and q2.d only enter as their sum" in text
    assert "q2.d =" in text  # the far-away common normal from the circle-point start
    assert "poses" in study.table() and "after/noise" in study.table()


def test_figures_are_written(study):
    names = {p.name for p in study.figures}
    assert names == {"calibration_histograms.png", "calibration_workspace.png",
                     "calibration_parameters.png", "calibration_rms.png"}
    for p in study.figures:
        assert p.stat().st_size > 10_000
