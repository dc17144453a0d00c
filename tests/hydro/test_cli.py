"""``robodyn underwater ROBOT -o DIR``: files written, exit codes, one-line errors."""

from __future__ import annotations

import csv

import pytest

from robodyn.cli import main


@pytest.mark.slow
def test_underwater_writes_table_figures_and_report(tmp_path, capsys) -> None:
    out = tmp_path / "uw"
    code = main(["underwater", "underwater_2r", "-o", str(out), "--move-time", "0.5",
                 "--hold-time", "0.2", "--free-time", "0.5", "--end", "0.8", "0.8",
                 "--current", "0.5", "0", "0", "--cd-values", "0.6", "2.4",
                 "--current-speeds", "0", "1"])
    assert code == 0
    text = capsys.readouterr().out
    printed = text.split()
    for name in ("effects.csv", "effects.md", "tracking_q.png", "tracking_tau.png", "free_q.png",
                 "ideal_tau.png", "sensitivity.csv", "sensitivity.png", "model_error.csv",
                 "model_error.png", "underwater_section.html", "underwater.html"):
        assert (out / name).stat().st_size > 0 and str(out / name) in printed
    with (out / "sensitivity.csv").open() as f:
        sens = list(csv.DictReader(f))
    assert [(r["parameter"], float(r["value"])) for r in sens[::2]] == [
        ("C_d", 0.6), ("C_d", 2.4), ("current", 0.0), ("current", 1.0)]
    with (out / "model_error.csv").open() as f:
        errors = {(r["omitted"], r["joint"]): r for r in csv.DictReader(f)}
    assert float(errors[("nothing", "q1")]["max_error"]) < 1e-9
    assert float(errors[("everything", "q2")]["max_error"]) > 1e-3
    html = (out / "underwater.html").read_text()
    assert "Which effects must the controller" in html and "Sensitivity to the drag" in html
    with (out / "effects.csv").open() as f:
        rows = list(csv.DictReader(f))
    # no lift row on the planar arm, and the terminal says why
    assert [r["effect"] for r in rows[::2]] == ["dry", "buoyancy", "added_mass", "drag", "current"]
    assert "No '+ lift' row" in text
    assert float(rows[2]["peak_tau"]) < float(rows[0]["peak_tau"])  # buoyancy unloads joint 1


def test_robot_without_hydro_blocks_exits_2_with_one_line(tmp_path, capsys) -> None:
    code = main(["underwater", "planar_2r", "-o", str(tmp_path / "x")])
    err = capsys.readouterr().err.strip()
    assert code == 2
    assert err.count("\n") == 0 and "planar_2r" in err and "no hydro blocks" in err
    assert not (tmp_path / "x").exists()


def test_unknown_parameter_exits_2(tmp_path, capsys) -> None:
    code = main(["underwater", "underwater_2r", "-o", str(tmp_path / "x"), "--set", "nope=1"])
    err = capsys.readouterr().err.strip()
    assert code == 2 and "nope" in err and err.count("\n") == 0
