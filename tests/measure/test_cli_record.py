"""``robodyn record info|plot|convert``."""

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
