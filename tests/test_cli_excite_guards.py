"""``robodyn testprog --kind iso-cube --size`` and ``robodyn excite -o``: bad input refused in one
line with exit code 2 (probe 23: an unreachable cube was an internal error, exit 1; a missing or
folder ``-o`` failed with a raw OSError only after the whole optimisation)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

import robodyn as rd
from robodyn.calibration.iso9283 import cube_points
from robodyn.cli import main
from robodyn.errors import InputError, RobodynError
from robodyn.simulation import UnreachableError

FAST_EXCITE = ["--harmonics", "3", "--frequency", "0.5", "--starts", "1", "--dt", "0.01"]


def _one_line_error(capsys: pytest.CaptureFixture[str]) -> str:
    err = capsys.readouterr().err.strip()
    assert err.startswith("robodyn: error: ") and "\n" not in err, err
    assert "internal error" not in err
    return err


@pytest.mark.parametrize("size", ["5", "1e9"])
def test_cube_out_of_reach_is_bad_input_naming_size(tmp_path, capsys, size):
    argv = ["testprog", "puma560", "--kind", "iso-cube", "--size", size, "-o", str(tmp_path / "p")]
    assert main(argv) == 2
    err = _one_line_error(capsys)
    assert f"--size {float(size):g}: iso_cube: test point P" in err
    assert "is out of reach of 'puma560'" in err and "choose a smaller cube" in err
    assert not (tmp_path / "p").exists()


@pytest.mark.parametrize("size", ["0", "-0.5", "nan", "inf"])
def test_non_positive_cube_size_is_refused(tmp_path, capsys, size):
    argv = ["testprog", "puma560", "--kind", "iso-cube", "--size", size, "-o", str(tmp_path / "p")]
    assert main(argv) == 2
    err = _one_line_error(capsys)
    assert "--size: the cube edge must be a positive number of metres, got " in err
    assert not (tmp_path / "p").exists()


@pytest.mark.parametrize("size", [0.0, -1.0, float("nan"), float("inf"), True, "0.5"])
def test_cube_points_refuse_a_size_that_is_not_a_positive_length(size):
    with pytest.raises(InputError, match="ISO 9283 cube: size must be a positive finite edge length"):
        cube_points(np.zeros(3), size)


def test_unreachable_error_is_a_robodyn_input_error():
    assert issubclass(UnreachableError, InputError)
    assert issubclass(UnreachableError, RobodynError) and issubclass(UnreachableError, ValueError)


def _no_design(*args, **kwargs):
    raise AssertionError("the excitation was designed before -o was checked")


def test_excite_output_folder_refused_before_the_design(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(rd, "excitation", _no_design)
    assert main(["excite", "planar_2r", *FAST_EXCITE, "-o", str(tmp_path)]) == 2
    err = _one_line_error(capsys)
    assert f"-o {str(tmp_path)!r} names a folder, not a file" in err
    assert str(tmp_path / "excitation.csv") in err
    missing = tmp_path / "new"
    assert main(["excite", "planar_2r", *FAST_EXCITE, "-o", f"{missing}/"]) == 2
    assert "names a folder, not a file" in _one_line_error(capsys)
    assert not missing.exists()
    blocker = tmp_path / "afile"
    blocker.write_text("mine")
    assert main(["excite", "planar_2r", *FAST_EXCITE, "-o", str(blocker / "t.csv")]) == 2
    assert f"{blocker} is a file, not a folder" in _one_line_error(capsys)
    assert blocker.read_text() == "mine"


def test_excite_creates_the_missing_folder_of_its_output(tmp_path, capsys):
    out = tmp_path / "nodir" / "deeper" / "t.csv"
    assert main(["excite", "planar_2r", *FAST_EXCITE, "-o", str(out)]) == 0
    assert f"wrote {out}" in capsys.readouterr().out
    assert len(pd.read_csv(out)) == 201
