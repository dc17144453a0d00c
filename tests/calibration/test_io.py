"""The measured-data path end to end (CSV in; YAML, URDF and report out) and CSV errors."""

from __future__ import annotations

import importlib.util
import json
import warnings

import numpy as np
import pytest

import robodyn as rd
from robodyn.calibration import calibrate
from robodyn.calibration.io import read_calibration_csv, write_calibration, write_calibration_csv
from robodyn.studies.calibration_study import perturbed_robot, robot_positions
from tests.calibration.helpers import TARGET, TRACKER, poses, robot, symbolic_fk


def test_csv_to_calibrated_yaml_and_urdf_that_reproduce_the_residuals(tmp_path):
    r = robot("puma560")
    true = perturbed_robot(r, 8, base=TRACKER, target=TARGET)
    q = poses("puma560", 50, 8)
    y = robot_positions(true, q) + np.random.default_rng(8).normal(0, 5e-5, (50, 3))
    csv_path = tmp_path / "tracker.csv"
    write_calibration_csv(csv_path, r, q, y)
    data = read_calibration_csv(csv_path, r)
    np.testing.assert_array_equal(data.q, q)
    np.testing.assert_array_equal(data.points, y)
    cal = calibrate(r, data.q, data.points, "s-model")
    paths = write_calibration(cal, tmp_path / "out")
    assert paths["yaml"].exists() and paths["report"].exists() and paths["residuals"].exists()
    if importlib.util.find_spec("robodyn.export") is not None:
        assert paths["urdf"] is not None and paths["urdf"].exists()
    report = json.loads(paths["json"].read_text())
    assert report["after_m"]["rms"] == pytest.approx(cal.after.rms)
    assert len(report["parameters"]) == len(cal.parameters)
    assert "not identifiable" in paths["report"].read_text()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        loaded = [rd.load(paths["yaml"])]
        if paths["urdf"] is not None:
            loaded.append(rd.load(paths["urdf"]))
    for back in loaded:
        residuals = data.points - symbolic_fk(back)(data.q)[:, :3, 3]
        np.testing.assert_allclose(residuals, cal.residuals, atol=1e-9)
        assert back.links[2].mass == r.links[2].mass


def _write(tmp_path, text):
    p = tmp_path / "data.csv"
    p.write_text(text)
    return p


HEADER = "q1,q2,q3,q4,q5,q6,x,y,z\n"


def test_csv_errors_name_file_line_and_column(tmp_path):
    r = robot("puma560")
    with pytest.raises(FileNotFoundError, match="nothere.csv: no such file"):
        read_calibration_csv(tmp_path / "nothere.csv", r)
    with pytest.raises(ValueError, match="empty file"):
        read_calibration_csv(_write(tmp_path, "# only a comment\n"), r)
    with pytest.raises(ValueError, match=r"data.csv: line 1: missing column\(s\) q6, z"):
        read_calibration_csv(_write(tmp_path, "q1,q2,q3,q4,q5,x,y\n1,2,3,4,5,6,7\n"), r)
    with pytest.raises(ValueError, match=r"data.csv: line 3, column 'y': 'abc' is not a number"):
        read_calibration_csv(_write(tmp_path, HEADER + "0,0,0,0,0,0,1,2,3\n0,0,0,0,0,0,1,abc,3\n"), r)
    with pytest.raises(ValueError, match=r"data.csv: line 2, column 'q3': nan is not a finite number"):
        read_calibration_csv(_write(tmp_path, HEADER + "0,0,nan,0,0,0,1,2,3\n"), r)
    with pytest.raises(ValueError, match=r"data.csv: line 2: 8 values, but the header \(line 1\) "
                                         r"has 9 columns"):
        read_calibration_csv(_write(tmp_path, HEADER + "0,0,0,0,0,0,1,2\n"), r)
    with pytest.raises(ValueError, match="no data rows"):
        read_calibration_csv(_write(tmp_path, HEADER), r)
    with pytest.raises(ValueError, match="quaternion"):
        text = HEADER.strip() + ",qw,qx,qy,qz\n0,0,0,0,0,0,1,2,3,1,1,0,0\n"
        read_calibration_csv(_write(tmp_path, text), r)


def test_csv_orientation_and_sigma_columns(tmp_path):
    r = robot("puma560")
    half = "0.7071067811865476"
    text = HEADER.strip() + f",qw,qx,qy,qz,sigma\n0,0,0,0,0,0,1,2,3,{half},0,0,{half},1e-4\n"
    data = read_calibration_csv(_write(tmp_path, text), r)
    np.testing.assert_allclose(data.orientations[0], [[0, -1, 0], [1, 0, 0], [0, 0, 1]], atol=1e-15)
    np.testing.assert_allclose(data.sigma, [1e-4])
