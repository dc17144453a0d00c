"""``robodyn simulate``, ``robodyn calibrate`` and ``robodyn iso9283`` from the command line."""

from __future__ import annotations

import csv
import json
import re
import warnings

import numpy as np
import pytest

import robodyn as rd
from robodyn.calibration.io import write_calibration_csv
from robodyn.cli import main
from robodyn.studies.calibration_study import perturbed_robot, robot_positions
from tests.calibration.helpers import TARGET, TRACKER, poses, robot

# --- simulate ----------------------------------------------------------------------------------


def _columns(path):
    with path.open() as fh:
        rows = list(csv.reader(fh))
    head, data = rows[0], np.array(rows[1:], dtype=float)
    return {h: data[:, k] for k, h in enumerate(head)}


def test_simulate_passive_double_pendulum_writes_csv_and_plot(tmp_path, capsys):
    rc = main(["simulate", "trolley_double_pendulum", "--q0", "0,0.3,-0.2", "--duration", "2",
               "-o", str(tmp_path)])
    assert rc == 0
    cols = _columns(tmp_path / "trolley_double_pendulum_simulation.csv")
    assert (tmp_path / "trolley_double_pendulum_simulation.png").stat().st_size > 10_000
    assert len(cols["t"]) == 2001 and cols["t"][-1] == pytest.approx(2.0)
    assert cols["q[theta1]"][0] == 0.3 and cols["q[theta2]"][0] == -0.2
    # passive and frictionless: RK4 at 1 ms keeps the energy to well under 1e-5 relative
    e = _columns(tmp_path / "trolley_double_pendulum_energy.csv")["energy"]
    assert np.abs(e - e[0]).max() < 1e-5 * abs(e[0])
    assert np.all(cols["tau[x]"] == 0)
    # the recording layout: the run reads back as a recording
    rec = rd.read_recording(tmp_path / "trolley_double_pendulum_simulation.csv")
    assert np.array_equal(rec.q[:, 1], cols["q[theta1]"]) and np.array_equal(rec.tau[:, 0], cols["tau[x]"])
    out = capsys.readouterr().out
    drift = float(re.search(r"relative drift ([0-9.e+-]+)", out).group(1))
    assert drift < 1e-5


def test_simulate_computed_torque_reaches_the_target(tmp_path, capsys):
    target = [0.5, -0.4, 0.6, 0.3, -0.5, 0.7]
    rc = main(["simulate", "puma560", "--controller", "computed-torque", "--target",
               ",".join(map(str, target)), "--duration", "2", "--move-time", "1", "-o", str(tmp_path)])
    assert rc == 0
    cols = _columns(tmp_path / "puma560_simulation.csv")
    final = np.array([cols[f"q[q{j}]"][-1] for j in range(1, 7)])
    # the law holds tau over each 1 ms step and the PUMA has Coulomb friction: mrad, not exact
    np.testing.assert_allclose(final, target, atol=5e-3)
    assert "max |q - q_ref|" in capsys.readouterr().out


def test_simulate_rejects_a_wrong_vector_length(tmp_path, capsys):
    rc = main(["simulate", "puma560", "--q0", "1,2", "-o", str(tmp_path)])
    assert rc == 2
    assert "--q0: expected 1 or 6 comma-separated values" in capsys.readouterr().err
    rc = main(["simulate", "planar_2r", "--target", "1,1", "-o", str(tmp_path)])
    assert rc == 2
    assert "--target needs a controller" in capsys.readouterr().err


# --- calibrate ---------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def tracker_data(tmp_path_factory):
    """A perturbed PUMA 560 measured at 80 + 60 poses with 0.05 mm noise, as CSV files."""
    d = tmp_path_factory.mktemp("tracker")
    r = robot("puma560")
    true = perturbed_robot(r, 4, base=TRACKER, target=TARGET)
    rng = np.random.default_rng(4)
    out = {}
    for name, count, seed in (("poses", 80, 4), ("held", 60, 5)):
        q = poses("puma560", count, seed)
        clean = robot_positions(true, q)
        write_calibration_csv(d / f"{name}.csv", r, q, clean + rng.normal(0, 5e-5, clean.shape))
        out[name] = (q, clean)
    return d, out


@pytest.mark.slow
def test_calibrate_command_writes_a_description_that_reproduces_the_residuals(tracker_data, tmp_path,
                                                                              capsys):
    d, data = tracker_data
    rc = main(["calibrate", "puma560", "--data", str(d / "poses.csv"), "--validate",
               str(d / "held.csv"), "-o", str(tmp_path)])
    assert rc == 0
    stem = tmp_path / "puma560_calibrated"
    for suffix in (".yaml", ".urdf", "_report.txt", "_report.json", "_residuals.csv",
                   "_report.html", "_report.png"):
        assert (tmp_path / f"{stem.name}{suffix}").exists(), suffix
    report = json.loads((tmp_path / "puma560_calibrated_report.json").read_text())
    residuals = np.array(report["residuals_m"])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        back = [rd.load(tmp_path / "puma560_calibrated.yaml"), rd.load(tmp_path / "puma560_calibrated.urdf")]
    with (d / "poses.csv").open() as fh:
        rows = np.array(list(csv.reader(fh))[1:], dtype=float)
    q, y = rows[:, :6], rows[:, 6:]
    for loaded in back:
        fk = rd.compile_model(loaded, backend="numpy").forward_kinematics(q)[:, :3, 3]
        np.testing.assert_allclose(y - fk, residuals, atol=1e-9)
    # held-out error near the noise (0.05 mm per coordinate: RMS distance 0.087 mm)
    out = capsys.readouterr().out
    held = float(re.search(r"held-out .*RMS ([0-9.]+) mm", out).group(1))
    assert held < 1.3 * 0.05 * np.sqrt(3)
    html = (tmp_path / "puma560_calibrated_report.html").read_text()
    assert "Not identifiable" in html and "held-out (held.csv)" in html


def test_calibrate_command_errors_name_the_file_and_column(tracker_data, tmp_path, capsys):
    d, _ = tracker_data
    bad = tmp_path / "bad.csv"
    text = (d / "poses.csv").read_text().splitlines()
    text[3] = text[3].replace(text[3].split(",")[7], "nan", 1)
    bad.write_text("\n".join(text) + "\n")
    assert main(["calibrate", "puma560", "--data", str(bad), "-o", str(tmp_path / "o")]) == 2
    msg = capsys.readouterr().err
    assert "bad.csv" in msg and "'y'" in msg
    assert main(["calibrate", "puma560", "--data", str(d / "poses.csv"), "--circle",
                 str(d / "held.csv"), "-o", str(tmp_path / "o")]) == 2
    assert "one file per joint" in capsys.readouterr().err
    assert main(["calibrate", "puma560", "--data", str(tmp_path / "missing.csv"), "-o",
                 str(tmp_path / "o")]) == 2
    assert "missing.csv: no such file" in capsys.readouterr().err


# --- iso9283 -----------------------------------------------------------------------------------


def test_iso9283_command_prints_ap_and_rp_by_the_standard_formulas(tmp_path, capsys):
    rng = np.random.default_rng(2)
    cmd = {"P1": np.array([0.6, 0.0, 0.4]), "P2": np.array([0.35, 0.25, 0.15])}
    att = {k: v + [3e-4, -1e-4, 2e-4] + rng.normal(0, 4e-5, (30, 3)) for k, v in cmd.items()}
    lines = ["pose,x_cmd,y_cmd,z_cmd,x,y,z"]
    for c in range(30):
        for k in cmd:
            lines.append(",".join([k, *(repr(float(v)) for v in (*cmd[k], *att[k][c]))]))
    path = tmp_path / "cycles.csv"
    path.write_text("\n".join(lines) + "\n")
    assert main(["iso9283", str(path)]) == 0
    out = capsys.readouterr().out
    for k in cmd:
        # ISO 9283 7.2.1 / 7.2.2: AP = |barycentre - commanded|, RP = l_bar + 3 S_l
        bary = att[k].mean(axis=0)
        ap = np.linalg.norm(bary - cmd[k]) * 1e3
        dist = np.linalg.norm(att[k] - bary, axis=1)
        rp = (dist.mean() + 3 * dist.std(ddof=1)) * 1e3
        row = next(line for line in out.splitlines() if line.startswith(k)).split()
        assert float(row[1]) == pytest.approx(ap, abs=1e-4)
        assert float(row[5]) == pytest.approx(rp, abs=1e-4)


def test_iso9283_overshoot_from_an_approach_csv(tmp_path, capsys):
    t = np.arange(0, 1.0, 0.01)
    s = np.where(t < 0.2, 5e-3 * (1 - t / 0.2), 0.0)
    s = s + np.where((t >= 0.2) & (t < 0.4), -0.3e-3 * np.sin(np.pi * (t - 0.2) / 0.2), 0.0)
    path = tmp_path / "approach.csv"
    rows = (f"{float(a)!r},{float(0.6 + b)!r},0.1,0.3" for a, b in zip(t, s, strict=True))
    path.write_text("t,x,y,z\n" + "\n".join(rows))
    assert main(["iso9283", "--approach", str(path), "--band", "0.1", "--attained", "0.6,0.1,0.3"]) == 0
    out = capsys.readouterr().out
    assert float(re.search(r"overshoot\s+([0-9.]+) mm", out).group(1)) == pytest.approx(0.3, rel=1e-3)
    assert main(["iso9283"]) == 2
    assert "give a CSV" in capsys.readouterr().err
