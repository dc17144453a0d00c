"""``robodyn record info|plot|convert``."""

import os

import numpy as np

import robodyn as rd
from robodyn.cli import main
from robodyn.measure.mcap_io import write_mcap


def _bag(tmp_path):
    t = 1e-3 * np.arange(200)
    rec = rd.Recording(t=t, q=np.sin(np.outer(t, [1.0, 2.0])), joint_names=("a", "b"),
                       tau=np.ones((200, 2)))
    return write_mcap(rec, tmp_path / "run.mcap"), rec


def test_info_plot_convert(tmp_path, capsys):
    bag, rec = _bag(tmp_path)
    assert main(["record", "info", str(bag)]) == 0
    out = capsys.readouterr().out
    assert "200 samples of 2 joints (a, b)" in out and "median period 1 ms" in out
    assert "gaps: none" in out and "qd (estimated)" in out
    assert main(["record", "plot", str(bag), "-o", str(tmp_path / "plots")]) == 0
    pngs = sorted(p.name for p in (tmp_path / "plots").glob("*.png"))
    assert pngs == ["run_a.png", "run_b.png"]
    assert (tmp_path / "plots" / "run_a.png").read_bytes()[:4] == b"\x89PNG"
    assert main(["record", "convert", str(bag), "-o", str(tmp_path / "run.csv")]) == 0
    back = rd.read_recording(tmp_path / "run.csv")
    assert np.array_equal(back.q, rec.q) and np.array_equal(back.tau, rec.tau)


def test_errors_exit_2_with_one_line(tmp_path, capsys):
    bad = tmp_path / "bad.csv"
    bad.write_text("t,q[a]\n0,1\n0.001,nan\n")
    assert main(["record", "info", str(bad)]) == 2
    err = capsys.readouterr().err.strip()
    assert err == ("robodyn: error: bad.csv: column 'q[a]' (q): 'nan' is not a finite number at line 3 "
                   "(1 bad cell(s) in this column)")
    assert main(["record", "info", str(bad), "--spec", "nonesuch"]) == 2
    assert "neither a built-in spec" in capsys.readouterr().err
    assert main(["record", "info", str(tmp_path / "missing.csv")]) == 2
    assert "missing.csv: no such file" in capsys.readouterr().err


def test_convert_never_overwrites_its_input(tmp_path, capsys):
    _, rec = _bag(tmp_path)
    csv_path = tmp_path / "same.csv"
    assert main(["record", "convert", str(tmp_path / "run.mcap"), "-o", str(csv_path)]) == 0
    before = csv_path.read_bytes()
    capsys.readouterr()
    hard = tmp_path / "hard.csv"
    os.link(csv_path, hard)  # a hard link: another name of the same file
    for target in (csv_path, tmp_path / "." / "same.csv", hard):
        assert main(["record", "convert", str(csv_path), "-o", str(target)]) == 2
        assert "-o is the file being converted" in capsys.readouterr().err
    assert csv_path.read_bytes() == before


def test_convert_to_a_bag_says_what_it_cannot_carry(tmp_path, capsys):
    t = 1e-3 * np.arange(200)
    rec = rd.Recording(t=t, q=np.sin(np.outer(t, [1.0, 2.0])), joint_names=("a", "b"),
                       current=np.ones((200, 2)), temperature=np.full((200, 2), 30.0))
    from robodyn.measure.csv_io import write_csv

    src = write_csv(rec, tmp_path / "amps.csv")
    assert main(["record", "convert", str(src), "-o", str(tmp_path / "amps.mcap")]) == 0
    err = capsys.readouterr().err
    assert "has no field for current and temperature: not written" in err
