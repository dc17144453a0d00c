"""``robodyn excite`` and ``robodyn testprog`` from the command line."""

import numpy as np
import pandas as pd

from robodyn.cli import main


def test_excite_writes_a_rest_to_rest_trajectory(tmp_path, capsys):
    out = tmp_path / "traj.csv"
    assert main(["excite", "planar_2r", "--harmonics", "3", "--frequency", "0.5", "--starts", "1",
                 "--dt", "0.01", "-o", str(out)]) == 0
    text = capsys.readouterr().out
    assert "condition number" in text and f"wrote {out}" in text
    table = pd.read_csv(out)
    assert len(table) == 201  # one 2 s period at 10 ms, both ends
    qd = table[[c for c in table.columns if c.startswith("qd[")]].to_numpy()
    assert qd.shape[1] == 2
    # the program starts and ends at rest
    assert np.allclose(qd[0], 0.0, atol=1e-9) and np.allclose(qd[-1], 0.0, atol=1e-9)


def test_testprog_jointwise_moves_one_joint_at_a_time(tmp_path, capsys):
    assert main(["testprog", "planar_2r", "--kind", "jointwise", "--dt", "0.01",
                 "-o", str(tmp_path / "prog")]) == 0
    assert "moves" in capsys.readouterr().out
    traj = pd.read_csv(tmp_path / "prog" / "jointwise.csv")
    assert (tmp_path / "prog" / "jointwise_segments.csv").is_file()
    qd = traj[[c for c in traj.columns if c.startswith("qd[")]].to_numpy()
    # never two joints moving at once
    assert np.all((np.abs(qd) > 1e-9).sum(axis=1) <= 1)
    assert np.any(np.abs(qd[:, 0]) > 0) and np.any(np.abs(qd[:, 1]) > 0)


def test_bad_arguments_exit_2_with_one_line(tmp_path, capsys):
    assert main(["excite", "planar_2r", "--harmonics", "1", "-o", str(tmp_path / "t.csv")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("robodyn: error:") and "harmonics" in err and "\n" not in err
    assert main(["testprog", "no_such_robot", "--kind", "jointwise", "-o", str(tmp_path)]) == 2
    assert "no_such_robot" in capsys.readouterr().err
    # sizes and rates that would ask for terabytes or an aliased trajectory: one line, exit 2
    for argv, why in ((["excite", "planar_2r", "--frequency", "1e-9", "--dt", "1000"], "base_frequency"),
                      (["excite", "planar_2r", "--frequency", "1", "--dt", "0.1"], "fewer than 4 times"),
                      (["testprog", "planar_2r", "--kind", "jointwise", "--dt", "1e-12"], "more than")):
        assert main([*argv, "-o", str(tmp_path / "x.csv")]) == 2
        err = capsys.readouterr().err.strip()
        assert why in err and "\n" not in err, err
