"""Data tables (calibration poses, ISO 9283 cycles): every malformed file is a clear error.

The messages name the file, the line (as an editor counts it) and, where one is at fault, the
column; nothing is guessed. A row with a value too many used to be read with every column shifted
(a 302 mm error at exit 0).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from robodyn.calibration.io import read_calibration_csv, read_table
from robodyn.calibration.iso9283 import (
    overshoot_from_csv,
    overshoot_stabilisation,
    pose_characteristics,
    pose_characteristics_from_csv,
)
from robodyn.robot.errors import DataFileError
from tests.calibration.helpers import robot

HEADER = "q1,q2,q3,q4,q5,q6,x,y,z\n"
ROW = "0.1,0.2,0.3,0.4,0.5,0.6,1.0,0.5,0.25\n"
ISO_HEADER = "pose,x_cmd,y_cmd,z_cmd,x,y,z\n"
ISO_ROWS = ["P1,0.5,0,0.5,0.5001,0.0002,0.4999\n", "P1,0.5,0,0.5,0.5003,-0.0001,0.5002\n",
            "P2,0.6,0.1,0.5,0.6002,0.1001,0.5\n", "P2,0.6,0.1,0.5,0.5999,0.0998,0.5001\n"]


def write(tmp_path: Path, data: str | bytes, name: str = "data.csv") -> Path:
    path = tmp_path / name
    if isinstance(data, bytes):
        path.write_bytes(data)
    else:
        path.write_text(data, encoding="utf-8")
    return path


def raises(path: Path, pattern: str, read=None) -> None:
    read = read or (lambda p: read_calibration_csv(p, robot("puma560")))
    with pytest.raises(DataFileError, match=f"^{re.escape(str(path))}: {pattern}"):
        read(path)


def test_a_row_with_a_leading_extra_value_is_refused(tmp_path):
    # the row of the issue: a stray value in front shifts every column by one
    path = write(tmp_path, HEADER + ROW + "9," + ROW + ROW)
    raises(path, r"line 3: 10 values, but the header \(line 1\) has 9 columns$")


def test_a_row_with_a_value_too_few_is_refused_even_past_the_wanted_columns(tmp_path):
    # an optional trailing column the reader does not use: the short row is still refused
    path = write(tmp_path, "# poses\n" + HEADER.strip() + ",note\n" + ROW.strip() + ",a\n" + ROW)
    raises(path, r"line 4: 9 values, but the header \(line 2\) has 10 columns$")


def test_iso9283_cycles_with_a_row_too_long_or_short_are_refused(tmp_path):
    read = pose_characteristics_from_csv
    long_row = ISO_ROWS[1].strip() + ",0.1\n"
    raises(write(tmp_path, ISO_HEADER + ISO_ROWS[0] + long_row + "".join(ISO_ROWS[2:])),
           r"line 3: 8 values, but the header \(line 1\) has 7 columns$", read)
    raises(write(tmp_path, ISO_HEADER + "".join(ISO_ROWS[:3]) + "P2,0.6,0.1,0.5,0.6\n"),
           r"line 5: 5 values, but the header \(line 1\) has 7 columns$", read)


def test_iso9283_csv_reads_what_the_formulas_give(tmp_path):
    pc = pose_characteristics_from_csv(write(tmp_path, ISO_HEADER + "".join(ISO_ROWS)))
    rows = np.array([[float(v) for v in r.split(",")[1:]] for r in ISO_ROWS])
    ref = pose_characteristics(rows[[0, 2], :3], rows[:, 3:].reshape(2, 2, 3))
    np.testing.assert_array_equal(pc.ap, ref.ap)
    np.testing.assert_array_equal(pc.rp, ref.rp)
    assert tuple(pc.labels) == ("P1", "P2")


@pytest.mark.parametrize(
    ("data", "pattern"),
    [
        (b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR", r"a binary file \(NUL bytes\), not a CSV text file$"),
        (b"q1,q2\n\xff\xfe0,1\n", r"not a UTF-8 text file \(byte 6: invalid start byte\)"),
        ("q1,q2,q3,q4,q5,q6,x,y,z,x\n" + ROW.strip() + ",1\n",
         r"line 1: column\(s\) x appear more than once in the header$"),
        (HEADER + '0,0,0,0,0,0,1,2,"3\n', r"line 2: not a CSV record \(unexpected end of data\)$"),
        (HEADER + ROW.replace("0.25", "inf"), r"line 2, column 'z': inf is not a finite number$"),
        (HEADER.strip() + ",qw,qx,qy,qz\n" + ROW.strip() + ",1,0,0,0\n" + ROW.strip()
         + ",1,1,0,0\n", r"line 3: quaternion \(qw, qx, qy, qz\) has norm 1\.41421, not 1$"),
        (HEADER.strip() + ",sigma\n" + ROW.strip() + ",0.001\n\n" + ROW.strip() + ",-1\n",
         r"line 4, column 'sigma': -1 is not positive$"),
    ],
)
def test_malformed_files_name_file_line_and_reason(tmp_path, data, pattern):
    raises(write(tmp_path, data), pattern)


def test_utf8_byte_order_mark_is_accepted(tmp_path):
    # Excel's "CSV UTF-8" starts with a BOM: it used to turn the first column into "\ufeffq1"
    plain = read_calibration_csv(write(tmp_path, HEADER + ROW, "plain.csv"), robot("puma560"))
    bom = write(tmp_path, ("\ufeff" + HEADER + ROW).encode("utf-8"), "bom.csv")
    data = read_calibration_csv(bom, robot("puma560"))
    np.testing.assert_array_equal(data.q, plain.q)
    np.testing.assert_array_equal(data.points, [[1.0, 0.5, 0.25]])


def test_crlf_comments_and_text_columns(tmp_path):
    path = write(tmp_path, b"# tracker export\r\nlabel,t,x\r\n  \r\nA,0.5,1\r\n# pause\r\nB,1.5,2\r\n")
    table = read_table(path, ["t", "x"], optional=["label", "absent"], text_columns=("label",))
    assert table == {"t": [0.5, 1.5], "x": [1.0, 2.0], "label": ["A", "B"]}


def test_the_file_is_not_modified(tmp_path):
    data = (HEADER + "9," + ROW).encode()
    path = write(tmp_path, data)
    with pytest.raises(DataFileError):
        read_calibration_csv(path, robot("puma560"))
    assert path.read_bytes() == data


def test_iso9283_single_cycle_and_huge_values_are_data_errors(tmp_path):
    # found by tests/fuzz: a bare ValueError from the formulas, and an overflow RuntimeWarning
    # (1.3e154 squared) turning into non-finite AP/RP
    read = pose_characteristics_from_csv
    raises(write(tmp_path, ISO_HEADER + ISO_ROWS[0] + ISO_ROWS[2]),
           r"one cycle per pose; repeatability needs at least 2$", read)
    huge = ISO_HEADER + ISO_ROWS[0] + ISO_ROWS[1].replace("0.5002", "1.3407807929942597e+154")
    raises(write(tmp_path, huge), r"line 3, column 'z': 1\.3407807929942597e\+154 is out of range "
           r"\(at most 1e\+06 in magnitude\)$", read)


def test_calibration_values_beyond_1000_km_are_refused(tmp_path):
    raises(write(tmp_path, HEADER + ROW.replace("1.0,", "2e6,")),
           r"line 2, column 'x': 2e6 is out of range \(at most 1e\+06 in magnitude\)$")


def test_approach_csv_errors_name_the_file(tmp_path):
    # before: the CLI printed "t must be (T,) ..." / "trajectory times must increase" without
    # naming the file or the line
    read = lambda p: overshoot_from_csv(p, band=1e-3)  # noqa: E731
    raises(write(tmp_path, "t,x,y,z\n0,0,0,0\n0.1,0,0,0\n"),
           r"2 data row\(s\); an approach needs at least 3$", read)
    raises(write(tmp_path, "t,x,y,z\n0,0,0,0\n# pause\n0.2,0,0,0\n0.1,0,0,0\n"),
           r"line 5, column 't': times must increase \(0\.1 after 0\.2\)$", read)


def test_approach_csv_matches_the_array_function(tmp_path):
    t = np.linspace(0, 1, 11)
    x = np.column_stack([0.5 + 0.01 * np.exp(-5 * t) * np.cos(20 * t), 0 * t, 0 * t])
    rows = np.column_stack([t, x])
    text = "t,x,y,z\n" + "".join(",".join(repr(float(v)) for v in r) + "\n" for r in rows)
    ov = overshoot_from_csv(write(tmp_path, text), band=1e-3)
    ref = overshoot_stabilisation(t, x, band=1e-3)
    assert ov == ref


def test_cli_bad_calibration_csv_is_exit_2_in_one_line_and_writes_nothing(tmp_path, capsys):
    from robodyn.cli import main

    data = (HEADER + "9," + ROW).encode()
    path = write(tmp_path, data)
    out = tmp_path / "out"
    assert main(["calibrate", "puma560", "--data", str(path), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert err == (f"robodyn: error: {path}: line 2: 10 values, but the header (line 1) has 9 "
                   "columns\n")
    assert not out.exists() and path.read_bytes() == data
