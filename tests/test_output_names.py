"""Output names built from user text (``--stem``, a robot's name) stay inside ``-o``."""

from __future__ import annotations

from pathlib import Path

import pytest

from robodyn.cli import main
from robodyn.output_names import check_stem, output_path

BAD_STEMS = ["../../x", "/tmp/abs", "sub/x", "..\\..\\x", "..", ".", "", "a\nb", "x" * 201]


@pytest.mark.parametrize("stem", BAD_STEMS)
def test_stems_that_leave_the_folder_are_refused(stem: str, tmp_path: Path) -> None:
    with pytest.raises(ValueError, match=r"^--stem .* is not a plain file name: "):
        output_path(tmp_path, stem, ".yaml")


@pytest.mark.parametrize("stem", ["puma560_calibrated", "run 1", "a.b", "..x", "héllo"])
def test_plain_names_are_kept(stem: str, tmp_path: Path) -> None:
    assert check_stem(stem) == stem
    assert output_path(tmp_path, stem, "_report.json") == tmp_path / f"{stem}_report.json"


def test_calibrate_stem_outside_output_is_exit_2_before_any_work(tmp_path, capsys) -> None:
    # before: --stem ../../x wrote x.yaml, x.urdf, ... two folders above -o
    out = tmp_path / "a" / "b" / "out"
    rc = main(["calibrate", "puma560", "--data", str(tmp_path / "none.csv"), "-o", str(out),
               "--stem", "../../x"])
    err = capsys.readouterr().err.strip()
    assert rc == 2
    assert err == ("robodyn: error: --stem '../../x' is not a plain file name: it contains a "
                   "path separator; give only a file name (the folder is -o)")
    assert sorted(p.name for p in tmp_path.rglob("*")) == []


def test_simulate_robot_name_with_a_path_is_exit_2(tmp_path, capsys) -> None:
    desc = tmp_path / "evil.yaml"
    desc.write_text("name: ../../evil\njoints:\n  - {name: j, type: revolute, dh: {a: 1}, "
                    "link: {mass: 1, com: [-0.5, 0, 0], inertia: {ixx: 0, iyy: 0.1, izz: 0.1}}}\n")
    out = tmp_path / "deep" / "out"
    rc = main(["simulate", str(desc), "--duration", "0.01", "-o", str(out)])
    assert rc == 2
    assert "robot name '../../evil' is not a plain file name" in capsys.readouterr().err
    assert not list(tmp_path.rglob("*evil_simulation*"))


EVIL = ("name: ../../escaped_by_robotname\njoints:\n  - {name: j, type: revolute, dh: {a: 1}, "
        "link: {mass: 1, com: [-0.5, 0, 0], inertia: {ixx: 0, iyy: 0.1, izz: 0.1}}}\n")


@pytest.mark.parametrize("lang", ["c", "python", "julia"])
def test_codegen_robot_name_with_a_path_stays_in_the_folder(tmp_path, lang) -> None:
    # before: robodyn codegen wrote escaped_by_robotname.c/.h two folders above -o
    desc = tmp_path / "evil.yaml"
    desc.write_text(EVIL)
    out = tmp_path / "a" / "b" / "gen"
    assert main(["codegen", str(desc), "--lang", lang, "-o", str(out)]) == 0
    written = [p for p in tmp_path.rglob("*") if p.is_file() and p != desc]
    assert written and all(p.parent == out for p in written)
    assert all("/" not in p.name and "escaped_by_robotname" in p.name for p in written)


def test_identify_robot_name_with_a_path_is_exit_2(tmp_path, capsys) -> None:
    desc = tmp_path / "evil.yaml"
    desc.write_text(EVIL)
    data = tmp_path / "run.csv"
    data.write_text("t,q[j],tau[j]\n" + "".join(f"{k * 0.01},{0.01 * k},{0.1}\n" for k in range(50)))
    out = tmp_path / "deep" / "out"
    rc = main(["identify", str(desc), "--data", str(data), "--cutoff", "none", "-o", str(out)])
    assert rc == 2
    assert "robot name '../../escaped_by_robotname_identified' is not a plain file name" in \
        capsys.readouterr().err
    assert not list(tmp_path.rglob("*escaped*"))
