"""Joint maps of calibration files: a recording spec applies to a calibration file exactly as it
applies to a recording (checked against rd.read_recording and against the formula by hand), and
the short form keeps its meaning."""

from __future__ import annotations

import csv
import math

import numpy as np
import pytest
import yaml

import robodyn as rd
from robodyn.calibration.io import read_calibration_csv, read_joint_map
from robodyn.cli import main
from robodyn.robot.errors import DataFileError, RecordingError
from tests.calibration.helpers import robot

N = 24


def _write(path, columns, rows) -> None:
    with path.open("w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow(columns)
        w.writerows(rows)


@pytest.fixture
def controller_file(tmp_path):
    """A controller's log of the PUMA's joints J1..J6 in degrees, with a time and x, y, z."""
    rng = np.random.default_rng(3)
    t = np.arange(N) * 0.01
    j = rng.uniform(-90.0, 90.0, (N, 6))
    xyz = rng.uniform(-1.0, 1.0, (N, 3))
    path = tmp_path / "ctl.csv"
    _write(path, ["t", *(f"J{k}" for k in range(1, 7)), "x", "y", "z"], np.hstack([t[:, None], j, xyz]))
    return path, j


SPEC = {"joints": ["q1", "q2", "q3", "q4", "q5", "q6"],
        "time": {"column": "t", "unit": "s"},
        "position": {"columns": "J{k}", "unit": "deg", "sign": [1, -1, 1, 1, 1, -1],
                     "offset": [0.0, 0.5, 0.0, 0.0, 0.0, 0.0]},
        "couplings": [{"joint": "q3", "add": {"q2": 1.0}}]}


def test_a_recording_spec_reads_a_calibration_file_as_it_reads_a_recording(controller_file):
    path, j = controller_file
    r = robot("puma560")
    jmap = read_joint_map(SPEC, r)
    q = read_calibration_csv(path, r, joint_map=jmap).q
    # the recording reader, the other user of the same spec
    np.testing.assert_allclose(q, rd.read_recording(path, spec=SPEC).q, rtol=0, atol=1e-12)
    # and the spec's meaning by hand: q = C (sign * rad(J) + offset)
    rad = np.radians(j)
    q2 = -rad[:, 1] + 0.5
    np.testing.assert_allclose(q[:, 1], q2, rtol=0, atol=1e-12)
    np.testing.assert_allclose(q[:, 2], rad[:, 2] + q2, rtol=0, atol=1e-12)
    np.testing.assert_allclose(q[:, 5], -rad[:, 5], rtol=0, atol=1e-12)
    assert jmap.si


def test_a_spec_without_time_in_another_joint_order_and_in_counts(controller_file, tmp_path):
    path, j = controller_file
    r = robot("puma560")
    spec = {"joints": ["q6", "q5", "q4", "q3", "q2", "q1"],  # the log's own order
            "position": {"columns": ["J6", "J5", "J4", "J3", "J2", "J1"], "unit": "counts",
                         "counts_per_rev": 4096, "gear_ratio": [2, 2, 2, 50, 100, 100]}}
    file = tmp_path / "arm.yaml"
    file.write_text(yaml.safe_dump(spec), encoding="utf-8")
    q = read_calibration_csv(path, r, joint_map=read_joint_map(file, r)).q
    gear = np.array([100, 100, 50, 2, 2, 2])  # q1..q6
    np.testing.assert_allclose(q, 2 * math.pi * j / (4096 * gear), rtol=0, atol=1e-12)


def test_a_spec_is_refused_where_it_cannot_apply(tmp_path):
    r = robot("puma560")
    with pytest.raises(DataFileError, match="joints: the spec names a, b; puma560 has q1"):
        read_joint_map({"joints": ["a", "b"], "position": {"columns": "J{k}", "unit": "rad"}}, r)
    six = SPEC["joints"]
    with pytest.raises(DataFileError, match="wrap_bits: a counter that wraps"):
        read_joint_map({"joints": six, "position": {"columns": "J{k}", "unit": "counts",
                                                    "counts_per_rev": 4096, "wrap_bits": 16}}, r)
    with pytest.raises(DataFileError, match="column names, not indices"):
        read_joint_map({"joints": six, "position": {"columns": [0, 1, 2, 3, 4, 5], "unit": "rad"}}, r)
    with pytest.raises(RecordingError, match=r"position.unit"):
        read_joint_map({"joints": six, "position": {"columns": "J{k}", "unit": "grad"}}, r)


def test_the_short_form_keeps_its_meaning(controller_file):
    path, j = controller_file
    r = robot("puma560")
    short = {f"q{k}": f"J{k}" for k in range(1, 7)}
    short["q3"] = {"column": "J3", "sign": -1, "offset": 10.0, "coupling": {"J2": 1.0}}
    jmap = read_joint_map(short, r)
    q = read_calibration_csv(path, r, joint_map=jmap).q
    # q3 = -J3 + 10 + J2 in the file's unit (degrees here; the calibration converts them)
    np.testing.assert_allclose(q[:, 2], -j[:, 2] + 10.0 + j[:, 1], rtol=0, atol=1e-12)
    np.testing.assert_allclose(q[:, [0, 1, 3, 4, 5]], j[:, [0, 1, 3, 4, 5]], rtol=0, atol=1e-12)
    assert not jmap.si


def test_cli_refuses_an_angle_unit_beside_a_spec(controller_file, tmp_path, capsys):
    path, _ = controller_file
    spec = tmp_path / "arm.yaml"
    spec.write_text(yaml.safe_dump(SPEC), encoding="utf-8")
    code = main(["calibrate", "puma560", "--data", str(path), "--joint-map", str(spec),
                 "--angle-unit", "deg", "-o", str(tmp_path / "out")])
    assert code == 2
    assert "recording spec, whose position.unit already gives the joints' unit" in capsys.readouterr().err
