"""``robodyn simulate`` and ``robodyn demo`` on inputs that used to crash: one line, exit 2."""

from __future__ import annotations

import csv

import pytest

from robodyn.cli import main
from robodyn.codegen import build
from robodyn.report.demo import demo_backend


def _error_lines(err: str) -> list[str]:
    assert "Traceback" not in err
    return [line for line in err.splitlines() if line.startswith("robodyn: error:")]


@pytest.mark.parametrize("duration", ["1e9", "1e5", "1e4"])
def test_a_huge_simulation_is_refused_before_it_starts(tmp_path, capsys, duration):
    # 1e9 s used to ask for 7 TiB, 1e5 s to eat all memory, 1e4 s to write a 1.5 GB CSV
    out = tmp_path / "sim"
    code = main(["simulate", "planar_2r", "--duration", duration, "-o", str(out)])
    (line,) = _error_lines(capsys.readouterr().err)
    assert code == 2
    assert "above --max-samples 1,000,000" in line and "--decimate" in line and "MB" in line
    assert not out.exists()


def test_decimate_and_max_samples_decide_what_is_written(tmp_path, capsys):
    args = ["simulate", "planar_2r", "--q0", "1,0", "--duration", "4", "-o", str(tmp_path)]
    assert main([*args, "--max-samples", "1000"]) == 2
    assert "--decimate k (k >= 5)" in _error_lines(capsys.readouterr().err)[0]
    assert main([*args, "--max-samples", "1000", "--decimate", "5"]) == 0
    with (tmp_path / "planar_2r_simulation.csv").open() as fh:
        rows = list(csv.reader(fh))[1:]
    assert len(rows) == 801 and float(rows[1][0]) == pytest.approx(5e-3)
    assert float(rows[-1][0]) == pytest.approx(4.0)


def test_a_simulation_that_blows_up_is_exit_2_without_a_traceback(tmp_path, capsys):
    code = main(["simulate", "planar_2r", "--controller", "pd", "--kp", "1e6", "--kd", "0",
                 "--target", "1,1", "--dt", "0.5", "--duration", "20", "-o", str(tmp_path)])
    (line,) = _error_lines(capsys.readouterr().err)
    assert code == 2 and "stopped being finite" in line and "reduce dt" in line


def _no_compiler():
    raise build.CompilerNotFoundError("no C compiler found (tried $CC, cc, gcc, clang)")


def test_without_a_compiler_simulate_falls_back_to_numpy_or_names_it(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(build, "find_compiler", _no_compiler)
    # an empty cache: a library built before would load without a compiler (the cache index)
    monkeypatch.setenv("ROBODYN_CACHE", str(tmp_path / "cache"))
    # the default (auto): the NumPy backend, with a note
    assert main(["simulate", "planar_2r", "--duration", "0.1", "-o", str(tmp_path)]) == 0
    err = capsys.readouterr().err
    assert "robodyn: note: no C compiler found" in err and "using the NumPy backend" in err
    # C asked for explicitly: one line naming the NumPy backend, exit 2
    code = main(["simulate", "planar_2r", "--duration", "0.1", "--backend", "c", "-o", str(tmp_path)])
    (line,) = _error_lines(capsys.readouterr().err)
    assert code == 2 and "--backend numpy" in line


def test_without_a_compiler_the_demo_falls_back_to_numpy_with_a_note(capsys, monkeypatch):
    assert demo_backend() == "c"
    monkeypatch.setattr(build, "find_compiler", _no_compiler)
    assert demo_backend() == "numpy"
    out = capsys.readouterr().out
    assert out.startswith("note: no C compiler found") and "NumPy backend" in out
