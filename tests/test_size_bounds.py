"""Options that would ask for a time grid of terabytes are refused before anything is allocated."""

from __future__ import annotations

import re

import pytest

import robodyn as rd
from robodyn.cli import main
from robodyn.robot.sizes import MAX_GRID_SAMPLES, MAX_GRID_VALUES, max_grid_samples, time_grid_steps


@pytest.mark.parametrize("args, why", [
    (["excite", "planar_2r", "--dt", "0"], "excitation: dt must be a positive number of seconds"),
    (["excite", "planar_2r", "--duration", "1e9"], r"1e\+12 samples, more than 4.29e\+06"),
    (["underwater", "underwater_2r", "--dt", "1e-12"], "underwater: --move-time 2 s at --dt 1e-12 s"),
    (["underwater", "underwater_2r", "--move-time", "1e9"], r"underwater: --move-time 1e\+09 s"),
    (["testprog", "planar_2r", "--kind", "iso-cube", "--cycles", "100000000"],
     r"--cycles: must be an integer in \[1, 10000\]"),
    (["testprog", "planar_2r", "--kind", "iso-cube", "--dt", "0"],
     "--dt: the sample step must be a positive number of seconds, got 0"),
    (["testprog", "planar_2r", "--kind", "jointwise", "--dt", "nan"],
     "--dt: the sample step must be a positive number of seconds, got nan"),
    (["testprog", "planar_2r", "--kind", "jointwise", "--speeds", "1e-9"],
     r"--speeds: each must be a fraction in \[0.001, 1\] of the velocity limit, got 1e-09"),
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


def test_grid_values_bound_the_samples_of_what_is_written():
    # issue 23: excite and testprog evaluate and write 1 + 3 n values a sample
    assert max_grid_samples(7) == MAX_GRID_VALUES // 7 == 4_285_714
    assert time_grid_steps(4285.0, 1e-3, "f", values_per_sample=7) == 4_285_000
    with pytest.raises(ValueError, match=r"f: duration 4286 s at dt 0.001 s is 4.29e\+06 samples, "
                                         r"more than 4.29e\+06 .*ROBODYN_MAX_GRID_SAMPLES"):
        time_grid_steps(4286.0, 1e-3, "f", values_per_sample=7)
    assert max_grid_samples(1) == MAX_GRID_SAMPLES  # the sample bound still holds


def _one_line(capsys) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("robodyn: error: ")
    return err[0]


def test_excite_just_over_the_limit_is_refused_before_the_design(tmp_path, monkeypatch, capsys):
    import robodyn.studies.excitation as ex

    monkeypatch.setattr(ex, "minimize", _never)  # refused before the optimiser starts
    monkeypatch.setenv("ROBODYN_MAX_GRID_SAMPLES", "10000")
    out = tmp_path / "t.csv"
    assert main(["excite", "planar_2r", "-o", str(out), "--duration", "10", "--dt", "1e-3"]) == 2
    assert re.search(r"excitation: duration \(whole periods\) 10 s at dt 0.001 s is 1e\+04 samples, "
                     r"more than 1e\+04 .*ROBODYN_MAX_GRID_SAMPLES", _one_line(capsys))
    assert not out.exists()


def _never(*args, **kwargs):
    raise AssertionError("ran past the size check")


@pytest.mark.parametrize("args, why", [
    (["--kind", "iso-cube", "--cycles", "3"], r"iso_cube \(cycles 3\): program [\d.]+ s at dt 0.001 s"),
    (["--kind", "jointwise", "--dt", "1e-4"], r"jointwise: program [\d.]+ s at dt 0.0001 s"),
])
def test_testprog_just_over_the_limit_is_refused_before_sampling(args, why, tmp_path, monkeypatch,
                                                                 capsys):
    import robodyn.studies.testprog as tp

    robot = "puma560" if args[1] == "iso-cube" else "planar_2r"  # the cube is out of a 2R's reach
    prog = tp.iso_cube if args[1] == "iso-cube" else tp.jointwise
    kwargs = {"cycles": 3} if args[1] == "iso-cube" else {"dt": 1e-4}
    samples = prog(rd.load(robot), **kwargs).t.size
    monkeypatch.setattr(tp, "concatenate", _never)  # no sample array built
    monkeypatch.setenv("ROBODYN_MAX_GRID_SAMPLES", str(samples - 2))
    assert main(["testprog", robot, *args, "-o", str(tmp_path / "out")]) == 2
    line = _one_line(capsys)
    assert re.search(why + r" is [\d.e+]+ samples, more than .*ROBODYN_MAX_GRID_SAMPLES", line)


def test_underwater_just_over_the_limit_is_refused_before_simulating(tmp_path, monkeypatch, capsys):
    import robodyn.studies.underwater as uw

    monkeypatch.setattr(uw, "simulate", _never)
    monkeypatch.setattr(uw, "quintic", _never)
    # 6 variants of a 2-joint arm: 97 values a sample; 3e7 / 97 = 309,278 samples by default
    assert main(["underwater", "underwater_2r", "-o", str(tmp_path / "o"), "--move-time", "306",
                 "--series-only"]) == 2
    assert re.search(r"underwater: --move-time \+ --hold-time \+ --free-time 310 s at --dt 0.001 s "
                     r"is 3.1e\+05 samples, more than 3.09e\+05 \(a larger --dt or a shorter run; or "
                     r"set ROBODYN_MAX_GRID_SAMPLES\)", _one_line(capsys))
    # in Python the names of the arguments; lift is dropped for this arm: 5 variants, 83 values
    with pytest.raises(ValueError, match=r"effect_series: move_time \+ hold_time \+ free_time 404 s "
                                         r"at dt 0.001 s is 4.04e\+05 samples, more than 3.61e\+05"):
        uw.effect_series(rd.load("underwater_2r"), move_time=400.0)
