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
