"""The files in examples/ work with the commands examples/README.md gives for them."""

from __future__ import annotations

import re
from pathlib import Path

from robodyn.cli import main

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def test_calibration_example_calibrates_to_the_noise(tmp_path, capsys):
    rc = main(["calibrate", "puma560", "--data", str(EXAMPLES / "poses.csv"), "--validate",
               str(EXAMPLES / "held.csv"), "-o", str(tmp_path)])
    assert rc == 0
    out = capsys.readouterr().out
    before = float(re.search(r"before: .*RMS ([0-9.]+) mm", out).group(1))
    held = float(re.search(r"held-out .*RMS ([0-9.]+) mm", out).group(1))
    # several mm of manufacturing error before; near the 0.05 mm/coordinate noise (0.087 mm RMS) after
    assert before > 2.0 and held < 1.5 * 0.05 * 3**0.5


def test_iso9283_examples(capsys):
    assert main(["iso9283", str(EXAMPLES / "cycles.csv")]) == 0
    out = capsys.readouterr().out
    assert "(30 cycles)" in out and len(re.findall(r"^[1-5] ", out, re.M)) == 5
    assert main(["iso9283", "--approach", str(EXAMPLES / "approach.csv"), "--band", "0.1"]) == 0
    overshoot = float(re.search(r"position overshoot\s+([0-9.]+) mm", capsys.readouterr().out).group(1))
    assert 0.5 < overshoot < 2.0


def test_sample_bag_reads_plots_and_converts(tmp_path, capsys):
    import numpy as np

    import robodyn as rd

    bag = EXAMPLES / "run.mcap"
    assert main(["record", "info", str(bag)]) == 0
    assert "401 samples of 6 joints (q1, q2, q3, q4, q5, q6)" in capsys.readouterr().out
    assert main(["record", "plot", str(bag), "-o", str(tmp_path / "plots")]) == 0
    assert len(list((tmp_path / "plots").glob("*.png"))) == 6
    assert main(["record", "convert", str(bag), "-o", str(tmp_path / "run.csv")]) == 0
    rec = rd.read_recording(bag, robot=rd.load("puma560"))
    back = rd.read_recording(tmp_path / "run.csv")
    assert np.array_equal(back.q, rec.q) and np.array_equal(back.tau, rec.tau)
