"""The standalone C simulator's header comment describes the CSV it really writes."""

from __future__ import annotations

import re
import subprocess
import warnings

import pytest

import robodyn as rd
from robodyn.codegen.build import find_compiler
from robodyn.codegen.emit import generate


@pytest.mark.tool("gcc|cc")
def test_header_comment_names_the_columns_the_program_prints(tmp_path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        files = generate(rd.load("planar_2r"), "c", tmp_path)
    sim = next(p for p in files if p.name == "planar_2r_sim.c")
    text = sim.read_text()
    described = re.search(r"^// Output: CSV on stdout; header row (\S+);", text, re.M)
    assert described is not None, text[:800]
    exe = tmp_path / "planar_2r_sim"
    subprocess.run([find_compiler(), "-O1", "-std=c99", str(sim), str(tmp_path / "planar_2r.c"), "-lm",
                    "-o", str(exe)], check=True, capture_output=True)
    out = subprocess.run([str(exe), "0.002", "0.001", "0.1", "0.2"], capture_output=True, text=True,
                         check=True).stdout.splitlines()
    assert out[0] == described.group(1) == "t,q1,q2,qd1,qd2"
    assert len(out) == 1 + 3 and all(len(row.split(",")) == 5 for row in out[1:])
    assert "// Usage: planar_2r_sim [duration [dt [x0_1 ... x0_4]]]" in text
