"""Fuzz the data-table readers: calibration pose CSVs and ISO 9283 cycle CSVs, generated and
mutated. The only outcomes allowed are a result or a :class:`DataFileError`, within the deadline.
"""

from __future__ import annotations

import tempfile
import warnings
from pathlib import Path

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

import robodyn as rd
from robodyn.calibration.io import read_calibration_csv
from robodyn.calibration.iso9283 import overshoot_from_csv, pose_characteristics_from_csv
from robodyn.robot.errors import DataFileError, DescriptionWarning
from tests.fuzz.strategies import TOKENS, fuzz_settings, mutated

with warnings.catch_warnings():
    warnings.simplefilter("ignore", DescriptionWarning)
    PUMA = rd.load("puma560")

_rng = np.random.default_rng(0)
CAL = ["q1,q2,q3,q4,q5,q6,x,y,z,qw,qx,qy,qz,sigma\n" + "".join(
    ",".join(f"{v:.6f}" for v in [*_rng.uniform(-2, 2, 6), *_rng.uniform(-1, 1, 3)])
    + ",1,0,0,0,0.0001\n" for _ in range(4)),
    "# tracker\nq1,q2,q3,q4,q5,q6,x,y,z\n0,0,0,0,0,0,0.4,0.1,0.6\n0.1,0.2,0.3,0.4,0.5,0.6,1,2,3\n"]
ISO = ["pose,x_cmd,y_cmd,z_cmd,x,y,z\n" + "".join(
    f"P{p},0.{p},0,0.5,0.{p}001,0.0002,0.4999\nP{p},0.{p},0,0.5,0.{p}003,-0.0001,0.5002\n"
    for p in range(1, 4))]
APPROACH = ["t,x,y,z\n" + "".join(f"{0.01 * k:.2f},{0.5 + 0.01 * 0.7 ** k:.6f},0,0\n"
                                  for k in range(12))]


def outcome(read, data: str | bytes) -> None:
    raw = data if isinstance(data, bytes) else data.encode("utf-8", "surrogatepass")
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "data.csv"
        path.write_bytes(raw)
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # a stray RuntimeWarning (NumPy) is a defect too
            try:
                read(path)
            except DataFileError as exc:
                assert str(exc).startswith(f"{path}: "), str(exc)  # names the file
        assert path.read_bytes() == raw


def read_cal(path: Path) -> None:
    data = read_calibration_csv(path, PUMA)
    assert data.q.shape[1] == 6 and data.points.shape == (len(data.q), 3)
    assert np.all(np.isfinite(data.q)) and np.all(np.isfinite(data.points))


def read_iso(path: Path) -> None:
    pc = pose_characteristics_from_csv(path)
    assert np.all(np.isfinite(pc.ap)) and np.all(np.isfinite(pc.rp))


_cell = st.one_of(st.floats(allow_nan=True, allow_infinity=True).map(repr),
                  st.sampled_from(TOKENS), st.text(max_size=8), st.integers().map(str))
_header = st.lists(st.sampled_from(["q1", "q2", "q3", "q4", "q5", "q6", "x", "y", "z", "qw",
                                    "qx", "qy", "qz", "sigma", "pose", "x_cmd", "y_cmd", "z_cmd",
                                    "note", ""]), min_size=1, max_size=16)
_table = st.builds(
    lambda head, rows, sep: sep.join([",".join(head)] + [",".join(r) for r in rows]),
    _header, st.lists(st.lists(_cell, max_size=16), max_size=6), st.sampled_from(["\n", "\r\n"]),
)


_number = st.one_of(st.floats(allow_nan=False, allow_infinity=False), st.integers(-3, 3),
                    st.floats(-2, 2)).map(repr)
_labels = st.sampled_from(["P1", "P2", "P3", "", "P1 "])
# the right header and well-formed rows: only the values and the row count vary
_cal_table = st.builds(
    lambda rows: "q1,q2,q3,q4,q5,q6,x,y,z,qw,qx,qy,qz,sigma\n"
    + "".join(",".join(r) + "\n" for r in rows),
    st.lists(st.lists(_number, min_size=14, max_size=14), max_size=5),
)
_iso_table = st.builds(
    lambda cmds, rows: "pose,x_cmd,y_cmd,z_cmd,x,y,z\n" + "".join(
        ",".join([f"P{k % len(cmds)}", *cmds[k % len(cmds)], *values]) + "\n"
        for k, values in rows),
    st.lists(st.lists(_number, min_size=3, max_size=3), min_size=1, max_size=3),
    st.lists(st.tuples(st.integers(0, 2), st.lists(_number, min_size=3, max_size=3)),
             max_size=7),
)


@fuzz_settings(deadline_s=10)
@given(st.one_of(mutated(CAL), _table, _cal_table, st.binary(max_size=512)))
def test_calibration_csv(data: str | bytes) -> None:
    outcome(read_cal, data)


@fuzz_settings(deadline_s=10)
@given(st.one_of(mutated(ISO), _table, _iso_table, st.binary(max_size=512)))
def test_iso9283_csv(data: str | bytes) -> None:
    outcome(read_iso, data)


def read_approach(path: Path) -> None:
    ov = overshoot_from_csv(path, band=1e-3)
    assert np.all(np.isfinite(ov.attained))


@fuzz_settings(deadline_s=10)
@given(st.one_of(mutated(APPROACH), _table, st.binary(max_size=512)))
def test_approach_csv(data: str | bytes) -> None:
    outcome(read_approach, data)
