"""Fuzz the command line: mutated recording specs, study files and argument lists.

For every generated input the only outcomes allowed are exit 0 or exit 2 with one line on
stderr (bad input). Exit 1 here would be an internal error (a bug, see robodyn.cli), a traceback
escaping ``main`` fails the test, the input files are unchanged, nothing is written outside
the output folder or file given (``-o``), and the memory the command allocates stays under ``MEMORY_CAP``
(``tests.fuzz.strategies``: measured by ``tracemalloc``, which sees NumPy's arrays too, so a
small input that expands into gigabytes fails here rather than on a user's machine).
"""

from __future__ import annotations

import hashlib
import io
import os
import tempfile
import tracemalloc
import warnings
from contextlib import redirect_stderr, redirect_stdout
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from robodyn.cli import main
from robodyn.errors import StudyError
from robodyn.studies.study_file import read_study
from tests.fuzz.strategies import MEMORY_CAP, TOKENS, fuzz_settings, memory_capped, mutated

SPEC = """\
description: two joints
header: true
joints: [a, b]
time: {column: t, unit: s}
position: {columns: "p{k}", unit: deg}
velocity: {columns: "v{k}", unit: deg/s}
torque: {columns: "tau{k}", unit: N m}
"""


def _csv() -> str:
    t = np.arange(120) * 0.01
    q, qd = np.degrees([np.sin(t), np.cos(t)]), np.degrees([np.cos(t), -np.sin(t)])
    rows = ["t,p1,p2,v1,v2,tau1,tau2"]
    rows += [f"{t[i]:.4f},{q[0, i]:.5f},{q[1, i]:.5f},{qd[0, i]:.5f},{qd[1, i]:.5f},"
             f"{0.1 * q[0, i]:.4f},{0.2 * q[1, i]:.4f}" for i in range(t.size)]
    return "\n".join(rows) + "\n"


CSV = _csv()
STUDY = (Path(__file__).resolve().parents[2] / "examples" / "studies" / "aa300_sizing.yaml").read_text(
    encoding="utf-8")


def _digest(folder: Path) -> dict[str, str]:
    return {str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file()}


def _run(argv: list[str], folder: Path) -> None:
    """``main(argv)`` run in ``folder``: exit 0, or 2 with one line; inputs and folder unchanged
    apart from ``folder/out``."""
    before = _digest(folder)
    cwd = os.getcwd()
    os.chdir(folder)
    out, errors = io.StringIO(), io.StringIO()
    tracemalloc.start()
    try:
        with warnings.catch_warnings(), redirect_stdout(out), redirect_stderr(errors):
            warnings.simplefilter("ignore")
            try:
                code = main(argv)
            except SystemExit as exc:  # argparse: usage errors exit 2, --help exits 0
                code = exc.code
    finally:
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        os.chdir(cwd)
    err = errors.getvalue().strip()
    assert code in (0, 2), (argv, code, err)
    assert peak < MEMORY_CAP, (argv, f"{peak / 2**20:.0f} MiB allocated")
    if code == 2 and err.startswith("robodyn: error:"):
        assert len(err.splitlines()) == 1, err
    # what the command was told to write (-o PATH: any name the arguments give) may appear
    told = {str(Path(argv[i + 1])) for i in range(len(argv) - 1) if argv[i] == "-o" and argv[i + 1]}
    after = {k: v for k, v in _digest(folder).items() if not k.startswith("out") and k not in told}
    assert after == {k: v for k, v in before.items() if k not in told}, argv


@pytest.mark.slow
@fuzz_settings(deadline_s=20)
@given(spec=mutated([SPEC]))
def test_record_info_and_convert_with_a_mutated_spec(spec: str) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        (folder / "run.csv").write_text(CSV, encoding="utf-8")
        (folder / "spec.yaml").write_text(spec, encoding="utf-8", errors="surrogatepass")
        _run(["record", "info", "run.csv", "--spec", "spec.yaml"], folder)
        _run(["record", "convert", "run.csv", "--spec", "spec.yaml", "-o", "out/run.csv"], folder)


@fuzz_settings(deadline_s=10)
@given(text=mutated([STUDY]))
def test_mutated_study_file_reads_or_is_refused(text: str) -> None:
    # reading only (running a study is a sweep on Dask): a Study or a StudyError naming the file
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "study.yaml"
        path.write_text(text, encoding="utf-8", errors="surrogatepass")
        with memory_capped():
            try:
                read_study(path)
            except StudyError as exc:
                assert "study.yaml" in str(exc), str(exc)


_ARG = st.one_of(st.sampled_from(TOKENS), st.sampled_from(
    ["planar_2r", "trolley_pendulum", "--method", "kane", "lagrange", "--format", "json", "latex",
     "--samples", "3", "-o", "out/x", "--tool", "tool0", "--spec", "spec.yaml", "run.csv",
     "--robot"]))


@fuzz_settings(deadline_s=30)
@given(command=st.sampled_from(["show", "derive", "check", "record info"]),
       args=st.lists(_ARG, max_size=6))
def test_random_arguments_exit_0_or_2(command: str, args: list[str]) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        (folder / "run.csv").write_text(CSV, encoding="utf-8")
        (folder / "spec.yaml").write_text(SPEC, encoding="utf-8")
        argv = [*command.split(), *(a for a in args if "\x00" not in a)]
        _run(argv, folder)
