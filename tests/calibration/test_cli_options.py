"""``robodyn calibrate`` options against hand-converted equivalents: units, joint mapping, targets."""

from __future__ import annotations

import csv
import dataclasses
import json

import numpy as np
import pytest

from robodyn.calibration.io import read_calibration_csv, read_joint_map
from robodyn.cli import main
from robodyn.robot.errors import DataFileError
from robodyn.studies.calibration_study import perturbed_robot
from tests.calibration.helpers import TRACKER, poses, robot
from tests.calibration.test_nongeometric import TARGETS, measured


def _write(path, header, rows):
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(header)
        for r in rows:
            w.writerow([repr(float(v)) for v in r])


@pytest.fixture(scope="module")
def data(tmp_path_factory):
    r = robot("puma560")
    true = perturbed_robot(r, 7, base=TRACKER, target=(0.0, 0.0, 0.0))
    rng = np.random.default_rng(2)
    q, q_test = poses("puma560", 60, 41), poses("puma560", 30, 42)
    y = measured(true, q, TARGETS[:2]) + rng.normal(0, 5e-5, (60, 2, 3))
    y_test = measured(true, q_test, TARGETS[:2]) + rng.normal(0, 5e-5, (30, 2, 3))
    d = tmp_path_factory.mktemp("cal")
    xyz = ["x", "y", "z", "x2", "y2", "z2"]
    _write(d / "si.csv", [*r.joint_names, *xyz], np.hstack((q, y.reshape(60, 6))))
    _write(d / "si_test.csv", [*r.joint_names, *xyz], np.hstack((q_test, y_test.reshape(30, 6))))
    # controller file: degrees, millimetres, J3 measured against J2 with a flipped sign and an offset
    def controller(qq, yy):
        c = np.degrees(qq).copy()
        c[:, 2] = -(np.degrees(qq[:, 2]) - 10.0 - c[:, 1])  # q3 = -J3 + 10 + J2
        return np.hstack((c, yy.reshape(len(qq), 6) * 1e3))
    header = ["J1", "J2", "J3", "J4", "J5", "J6", *xyz]
    _write(d / "ctl.csv", header, controller(q, y))
    _write(d / "ctl_test.csv", header, controller(q_test, y_test))
    (d / "map.yaml").write_text(
        "q1: J1\nq2: J2\nq3: {column: J3, sign: -1, offset: 10.0, coupling: {J2: 1.0}}\n"
        "q4: J4\nq5: J5\nq6: J6\n")
    return d


def test_units_mapping_and_targets_match_the_hand_converted_run(data, tmp_path, capsys):
    a, b = tmp_path / "si", tmp_path / "ctl"
    assert main(["calibrate", "puma560", "--data", str(data / "si.csv"), "--validate",
                 str(data / "si_test.csv"), "-o", str(a)]) == 0
    assert main(["calibrate", "puma560", "--data", str(data / "ctl.csv"), "--validate",
                 str(data / "ctl_test.csv"), "--length-unit", "mm", "--angle-unit", "deg",
                 "--joint-map", str(data / "map.yaml"), "--targets", "2", "-o", str(b)]) == 0
    out = capsys.readouterr().out
    assert "held-out" in out and "before" in out
    ja = json.loads((a / "puma560_calibrated_report.json").read_text())
    jb = json.loads((b / "puma560_calibrated_report.json").read_text())
    pa = {p["name"]: p["value"] for p in ja["parameters"]}
    pb = {p["name"]: p["value"] for p in jb["parameters"]}
    assert pa.keys() == pb.keys()
    for k in pa:
        assert pb[k] == pytest.approx(pa[k], abs=1e-9), k
    for key in ("before_m", "after_m"):
        assert jb["validation"][key]["rms"] == pytest.approx(ja["validation"][key]["rms"], abs=1e-9)
    assert ja["validation"]["after_m"]["rms"] < ja["validation"]["before_m"]["rms"]
    assert (b / "puma560_calibrated_terms.yaml").exists()


def test_nongeometric_option_writes_the_terms(data, tmp_path):
    assert main(["calibrate", "puma560", "--data", str(data / "si.csv"), "--model", "hayati",
                 "--nongeometric", "compliance", "-o", str(tmp_path)]) == 0
    j = json.loads((tmp_path / "puma560_calibrated_report.json").read_text())
    assert j["nongeometric"]["torque_source"] == "gravity model"
    assert "q2.compliance" in (tmp_path / "puma560_calibrated_terms.yaml").read_text()


def test_no_report_skips_only_the_html(data, tmp_path, capsys):
    a, b = tmp_path / "with", tmp_path / "without"
    args = ["calibrate", "puma560", "--data", str(data / "si.csv"), "--model", "hayati"]
    assert main([*args, "-o", str(a)]) == 0
    assert main([*args, "--no-report", "-o", str(b)]) == 0
    assert (a / "puma560_calibrated_report.html").exists()
    assert (a / "puma560_calibrated_report.png").exists()
    assert sorted(p.name for p in b.iterdir()) == sorted(
        p.name for p in a.iterdir() if p.suffix not in (".html", ".png"))
    # the rest is the same calibration
    assert (json.loads((b / "puma560_calibrated_report.json").read_text())["parameters"]
            == json.loads((a / "puma560_calibrated_report.json").read_text())["parameters"])
    assert "wrote html" not in capsys.readouterr().out.split("puma560_calibrated.yaml")[-1]


def test_a_cached_robot_calibrates_as_a_freshly_loaded_one(data, tmp_path, monkeypatch, capsys):
    """The first run loads the description in full and caches its numbers, the second reads them
    (no SymPy before its solve): the same calibrated description and report."""
    monkeypatch.setenv("ROBODYN_CACHE", str(tmp_path / "cache"))
    args = ["calibrate", "puma560", "--data", str(data / "si.csv"), "--model", "hayati", "--no-report"]
    assert main([*args, "-o", str(tmp_path / "first")]) == 0
    assert len(list((tmp_path / "cache").glob("rd_robot_*.json"))) == 1
    assert main([*args, "-o", str(tmp_path / "second")]) == 0
    first, second = (tmp_path / d for d in ("first", "second"))
    assert sorted(p.name for p in first.iterdir()) == sorted(p.name for p in second.iterdir())
    assert ((second / "puma560_calibrated.yaml").read_text()
            == (first / "puma560_calibrated.yaml").read_text())
    assert (json.loads((second / "puma560_calibrated_report.json").read_text())["parameters"]
            == json.loads((first / "puma560_calibrated_report.json").read_text())["parameters"])


def test_bad_mapping_and_target_count(data, tmp_path, capsys):
    r = robot("puma560")
    with pytest.raises(DataFileError, match="names joint 'q9', which puma560 does not have"):
        read_joint_map({"q9": "J9"}, r)
    with pytest.raises(DataFileError, match="field 'sign'"):
        read_joint_map({"q3": {"column": "J3", "sign": 2}}, r)
    with pytest.raises(DataFileError,
                       match=r"si.csv: 3 target\(s\) per pose were declared but the columns hold 2"):
        read_calibration_csv(data / "si.csv", r, targets=3)
    code = main(["calibrate", "puma560", "--data", str(data / "ctl.csv"), "--angle-unit", "deg",
                 "--joint-map", str(data / "map.yaml"), "-o", str(tmp_path)])
    assert code == 2
    assert "look like millimetres" in capsys.readouterr().err


def test_circle_files_with_multi_turn_joints_as_given_or_wrapped(tmp_path, capsys):
    """``--circle`` in degrees: q4 sweeps 400 deg in 16 readings, q6 680 deg in 4 (steps of 227
    deg); the same poses with the readings wrapped to (-180, 180] by the controller give the
    identical calibration, at the noise level."""
    from robodyn.studies.calibration_study import HOME, robot_positions

    r = robot("puma560")
    true = perturbed_robot(r, 6, base=TRACKER, target=(0.031, -0.018, 0.076))
    rng = np.random.default_rng(5)
    q = poses("puma560", 50, 43)
    _write(tmp_path / "poses.csv", [*r.joint_names, "x", "y", "z"],
           np.hstack((np.degrees(q), robot_positions(true, q) + rng.normal(0, 5e-5, (50, 3)))))
    given, wrapped = [], []
    for j, (sweep, count) in enumerate(zip(np.radians([60, 60, 60, 200, 60, 340]),
                                           (16, 16, 16, 16, 16, 4), strict=True)):
        qs = np.tile(HOME, (count, 1))
        qs[:, j] = HOME[j] + np.linspace(-sweep, sweep, count)
        pts = robot_positions(true, qs) + rng.normal(0, 5e-5, (count, 3))
        for kind, readings, names in (("given", qs, given), ("wrapped", np.angle(np.exp(1j * qs)), wrapped)):
            path = tmp_path / f"circle{j + 1}_{kind}.csv"
            _write(path, [*r.joint_names, "x", "y", "z"], np.hstack((np.degrees(readings), pts)))
            names += ["--circle", str(path)]
    runs = {}
    for kind, names in (("given", given), ("wrapped", wrapped)):
        out = tmp_path / kind
        assert main(["calibrate", "puma560", "--data", str(tmp_path / "poses.csv"), *names,
                     "--angle-unit", "deg", "-o", str(out)]) == 0
        runs[kind] = json.loads((out / "puma560_calibrated_report.json").read_text())
        assert runs[kind]["initial"] == "circle-point"
        assert runs[kind]["after_m"]["rms"] < 1.3 * np.sqrt(3) * 5e-5
    pa = {p["name"]: p["value"] for p in runs["given"]["parameters"]}
    pb = {p["name"]: p["value"] for p in runs["wrapped"]["parameters"]}
    assert pa.keys() == pb.keys()
    for k in pa:
        assert pb[k] == pytest.approx(pa[k], abs=1e-9), k


def test_cli_warns_when_sigma_is_off_by_more_than_3x(data, tmp_path, capsys):
    # the data's noise is 0.05 mm; --sigma 0.5 mm is 10x too large
    assert main(["calibrate", "puma560", "--data", str(data / "si.csv"), "--sigma", "0.5",
                 "-o", str(tmp_path)]) == 0
    err = capsys.readouterr().err
    assert "robodyn: warning: calibration of puma560: the variance factor" in err
    assert "wrong by a factor of about 0.1" in err


def test_circle_file_whose_readings_do_not_follow_the_arc_says_what_to_do(tmp_path, capsys):
    from robodyn.studies.calibration_study import HOME, robot_positions

    r = robot("puma560")
    true = perturbed_robot(r, 6, base=TRACKER, target=(0.031, -0.018, 0.076))
    q = poses("puma560", 40, 44)
    _write(tmp_path / "poses.csv", [*r.joint_names, "x", "y", "z"],
           np.hstack((np.degrees(q), robot_positions(true, q))))
    names = []
    for j, (sweep, count) in enumerate(zip(np.radians([60, 60, 60, 60, 60, 340]), (12,) * 5 + (4,),
                                           strict=True)):
        qs = np.tile(HOME, (count, 1))
        qs[:, j] = HOME[j] + np.linspace(-sweep, sweep, count)
        readings = np.degrees(qs)
        if j == 5:
            readings[:, 5] *= 1.3  # the controller reports 1.3x the joint angle (a wrong ratio)
        path = tmp_path / f"circle{j + 1}.csv"
        _write(path, [*r.joint_names, "x", "y", "z"], np.hstack((readings, robot_positions(true, qs))))
        names += ["--circle", str(path)]
    code = main(["calibrate", "puma560", "--data", str(tmp_path / "poses.csv"), *names,
                 "--angle-unit", "deg", "-o", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert code == 2
    assert "circle-point set 5 (q6)" in err and "measure the sweep in steps under 180 deg" in err
    assert len([line for line in err.splitlines() if line.startswith("robodyn: error:")]) == 1


@pytest.mark.slow
def test_nongeometric_terms_cross_validated_and_the_description_alone_stated(data, tmp_path, capsys):
    # the data are geometric errors only (perturbed_robot): terms cannot help on held-out poses
    assert main(["calibrate", "puma560", "--data", str(data / "si.csv"), "--targets", "2",
                 "--validate", str(data / "si_test.csv"), "--nongeometric", "compliance",
                 "--nongeometric", "harmonics", "-o", str(tmp_path)]) == 0
    captured = capsys.readouterr()
    assert "held-out RMS over 5 folds of 60 poses (cross-validation):" in captured.out
    j = json.loads((tmp_path / "puma560_calibrated_report.json").read_text())
    cv = j["terms_cross_validation_m"]
    assert list(cv) == ["geometry", "geometry + compliance", "geometry + compliance + harmonics"]
    names = list(cv)
    worse = [b.split(" + ")[-1] for a, b in zip(names[:-1], names[1:], strict=True) if cv[b] > cv[a]]
    for family in worse:
        assert f"adding '{family}' made the held-out error worse" in captured.err
    # the written description alone, evaluated here by the compiled model's forward kinematics
    # (loaded from the file, placed by its own base and tool), against the figures its header
    # and the report state: with its corrections it reproduces cal.predict's figure
    import robodyn as rd

    alone_robot = rd.load(str(tmp_path / "puma560_calibrated.yaml"))
    assert alone_robot.corrections is not None
    held = read_calibration_csv(data / "si_test.csv", alone_robot, targets=2)
    model = rd.compile_model(alone_robot)

    def rms(m):
        return float(np.sqrt(np.mean(np.sum((held.points[:, 0] - m.forward_kinematics(held.q)[:, :3, 3])
                                            ** 2, axis=1))))

    stated = j["description_alone_m"]
    assert stated["poses"] == "si_test.csv"
    assert stated["alone_rms"] == pytest.approx(rms(model), rel=1e-9)
    assert stated["alone_rms"] == pytest.approx(stated["with_terms_rms"], rel=1e-9)
    geometry_only = rd.compile_model(dataclasses.replace(alone_robot, corrections=None))
    assert stated["urdf_geometry_only_rms"] == pytest.approx(rms(geometry_only), rel=1e-9)
    header = (tmp_path / "puma560_calibrated.yaml").read_text().splitlines()[0]
    assert header.startswith("# carries the non-geometric terms as joint-reading corrections")
    assert f"alone it predicts {rms(model) * 1e3:.4f} mm RMS on si_test.csv" in header
    urdf = (tmp_path / "puma560_calibrated.urdf").read_text()
    assert f"alone this file predicts {rms(geometry_only) * 1e3:.4f} mm RMS" in urdf
    assert "joint-reading corrections (compliance, transmission errors of a calibration) are not " \
           "written" in urdf
