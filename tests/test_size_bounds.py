"""Options that would ask for a time grid of terabytes are refused before anything is allocated."""

from __future__ import annotations

import re

import pytest

from robodyn.cli import main
from robodyn.robot.sizes import MAX_GRID_SAMPLES, max_grid_samples, time_grid_steps


@pytest.mark.parametrize("args, why", [
    (["excite", "planar_2r", "--dt", "0"], "excitation: dt must be a positive number of seconds"),
    (["excite", "planar_2r", "--duration", "1e9"], r"1e\+12 samples, more than 1e\+07"),
    (["underwater", "underwater_2r", "--dt", "1e-12"], "effect_series: move_time 2 s at dt 1e-12 s"),
    (["underwater", "underwater_2r", "--move-time", "1e9"], r"effect_series: move_time 1e\+09 s"),
    (["testprog", "planar_2r", "--kind", "iso-cube", "--cycles", "100000000"],
     r"iso_cube: cycles must be an integer in \[1, 10000\]"),
    (["testprog", "planar_2r", "--kind", "jointwise", "--speeds", "1e-9"],
     r"speeds must be fractions in \[0.001, 1\]"),
])
def test_time_bombs_exit_2_with_one_line(args, why, tmp_path, capsys):
    assert main([*args, "-o", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("robodyn: error: ")
    assert re.search(why, err[0])


def test_grid_limit_and_its_override(monkeypatch):
    assert time_grid_steps(10.0, 1e-3, "f") == 10_000
    assert max_grid_samples() == MAX_GRID_SAMPLES
    with pytest.raises(ValueError, match=r"f: run 100 s at step 1e-06 s is 1e\+08 samples"):
        time_grid_steps(100.0, 1e-6, "f", duration_name="run", dt_name="step")
    monkeypatch.setenv("ROBODYN_MAX_GRID_SAMPLES", "200000000")
    assert time_grid_steps(100.0, 1e-6, "f") == 100_000_000
    monkeypatch.setenv("ROBODYN_MAX_GRID_SAMPLES", "lots")
    with pytest.raises(ValueError, match="ROBODYN_MAX_GRID_SAMPLES='lots'"):
        max_grid_samples()
    for bad in (float("nan"), float("inf"), -1.0, 0.0, True):
        with pytest.raises(ValueError, match="must be a positive number of seconds"):
            time_grid_steps(bad, 1e-3, "f")
