"""Bad recordings and specs: each error names the file, the field or column, the line and why."""

import gzip

import numpy as np
import pytest

import robodyn as rd
from robodyn.robot.errors import RecordingError

SPEC = {"joints": ["a", "b"], "time": {"column": "time", "unit": "ms"},
        "position": {"columns": "pos{k}", "unit": "deg"}}
GOOD = "time,pos1,pos2\n" + "".join(f"{k},{k * 0.1},{k * 0.2}\n" for k in range(20))


def _read(tmp_path, text, spec=SPEC, name="run.csv"):
    path = tmp_path / name
    path.write_text(text)
    before = path.read_bytes()
    try:
        return rd.read_recording(path, spec=spec)
    finally:
        assert path.read_bytes() == before  # input never modified


def test_good_file_reads(tmp_path):
    rec = _read(tmp_path, GOOD)
    assert rec.n_samples == 20 and rec.dt == pytest.approx(1e-3)


def test_missing_column(tmp_path):
    text = GOOD.replace("pos2", "posX")
    with pytest.raises(RecordingError, match=r"run.csv: position.columns\[1\]: column 'pos2' not in "
                                             r"the file \(the file's columns: time, pos1, posX\)"):
        _read(tmp_path, text)


def test_spec_names_column_not_in_file(tmp_path):
    spec = dict(SPEC, current={"columns": ["i1", "i2"], "unit": "A"})
    with pytest.raises(RecordingError, match=r"run.csv: current.columns\[0\]: column 'i1' not in"):
        _read(tmp_path, GOOD, spec)


def test_non_monotonic_time(tmp_path):
    text = GOOD.replace("\n7,", "\n5,")
    with pytest.raises(RecordingError, match=r"run.csv: column 'time' \(time.column\): not strictly "
                                             r"increasing at line 9 \(5 after 6 on line 8\)"):
        _read(tmp_path, text)


def test_nan_reports_row_and_column(tmp_path):
    text = GOOD.replace("\n12,1.2000000000000002,2.4000000000000004", "\n12,NaN,2.4")
    assert "12,NaN" in text
    with pytest.raises(RecordingError, match=r"run.csv: column 'pos1' \(position.columns\[0\]\): "
                                             r"'NaN' is not a finite number at line 14"):
        _read(tmp_path, text)


def test_unit_typo(tmp_path):
    spec = dict(SPEC, position={"columns": "pos{k}", "unit": "degs"})
    with pytest.raises(RecordingError, match=r"spec: position.unit: unknown unit 'degs' \(expected "
                                             r"one of rad, deg, counts, m, mm\)"):
        _read(tmp_path, GOOD, spec)


def test_unknown_key_in_spec_file(tmp_path):
    spec = tmp_path / "arm.yaml"
    spec.write_text("joints: 2\ntime: {column: time, unit: ms}\n"
                    "position: {columns: 'pos{k}', unit: deg, gear: 100}\n")
    with pytest.raises(RecordingError, match=r"arm.yaml: position.gear: unknown key \(expected one "
                                             r"of columns, unit, sign, offset, gear_ratio"):
        _read(tmp_path, GOOD, spec)


def test_mixed_row_lengths(tmp_path):
    text = GOOD.replace("\n4,0.4,0.8", "\n4,0.4,0.8,9")
    with pytest.raises(RecordingError, match=r"run.csv: line 6: 4 fields, but the header \(line 1\) "
                                             r"has 3"):
        _read(tmp_path, text)


def test_empty_file_and_header_only(tmp_path):
    with pytest.raises(RecordingError, match=r"run.csv: empty file \(no header and no data rows\)"):
        _read(tmp_path, "")
    with pytest.raises(RecordingError, match=r"run.csv: header only, no data rows \(line 1\)"):
        _read(tmp_path, "time,pos1,pos2\n")


def test_gzip_and_headerless_tsv(tmp_path):
    path = tmp_path / "run.tsv.gz"
    path.write_bytes(gzip.compress(GOOD.split("\n", 1)[1].replace(",", "\t").encode()))
    spec = {"header": False, "joints": 2, "time": {"column": 0, "unit": "s"},
            "position": {"columns": [1, 2], "unit": "rad"}}
    rec = rd.read_recording(path, spec=spec)
    assert rec.joint_names == ("q1", "q2") and rec.q[3, 1] == pytest.approx(0.6)
    spec["position"]["columns"] = [1, 5]
    with pytest.raises(RecordingError, match=r"run.tsv.gz: position.columns\[1\]: column 5 "
                                             r"\(0-based\) not in the file \(the file has 3 columns\)"):
        rd.read_recording(path, spec=spec)


def test_spec_value_errors(tmp_path):
    bad = [
        (dict(SPEC, time={"column": "time", "unit": "index"}), r"time.period: with unit 'index'"),
        (dict(SPEC, position={"columns": "pos", "unit": "rad"}),
         r"position.columns: a column pattern must contain \{k\}"),
        (dict(SPEC, position={"columns": "pos{k}", "unit": "counts"}), r"position.counts_per_rev: needed"),
        (dict(SPEC, position={"columns": "pos{k}", "unit": "rad", "sign": [1, 2]}),
         r"position.sign: each sign must be 1 or -1"),
        (dict(SPEC, couplings=[{"joint": "c", "add": {"a": 1}}]), r"couplings\[0\].joint: 'c'"),
        (dict(SPEC, torque={"from": "current", "torque_constant": 0.1}),
         r"torque.from: 'current' needs a current block"),
        (dict(SPEC, current={"columns": "pos{k}", "unit": "V"}), r"current.gain: needed for unit 'V'"),
    ]
    for spec, message in bad:
        with pytest.raises(RecordingError, match=r"spec: " + message):
            _read(tmp_path, GOOD, spec)


def test_spec_numbers_outside_their_plausible_range_are_refused(tmp_path):
    index = {"column": "time", "unit": "index"}
    bad = [
        (dict(SPEC, time=dict(index, period=1e300)), r"time.period: 1e\+300 is outside the plausible"),
        (dict(SPEC, time=dict(index, period=1e-300)), r"time.period: 1e-300 is outside the plausible"),
        (dict(SPEC, position={"columns": "pos{k}", "unit": "deg", "gear_ratio": 1e300}),
         r"position.gear_ratio\[0\]: 1e\+300 is outside the plausible"),
        (dict(SPEC, position={"columns": "pos{k}", "unit": "deg", "gear_ratio": [1.0, "1e-300"]}),
         r"position.gear_ratio\[1\]: 1e-300 is outside the plausible"),
        (dict(SPEC, position={"columns": "pos{k}", "unit": "deg", "offset": "one"}),
         r"position.offset\[0\]: expected a finite number, got 'one'"),
    ]
    for spec, message in bad:
        with pytest.raises(RecordingError, match=r"spec: " + message):
            _read(tmp_path, GOOD, spec)
    # "1e-3" is a number although YAML 1.1 reads it as text
    rec = _read(tmp_path, GOOD, dict(SPEC, time=dict(index, period="1e-3")))
    assert rec.dt == pytest.approx(1e-3)


def test_not_own_layout_without_spec(tmp_path):
    with pytest.raises(RecordingError, match=r"run.csv: spec: the file is not in robodyn's own layout"):
        _read(tmp_path, GOOD, None)


BOMB = "a: &a [x, x, x, x, x, x, x, x, x]\n" + "".join(
    f"{c}: &{c} [*{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}]\n"
    for p, c in zip("abcdefgh", "bcdefghi", strict=True)) + "joints: *i\n"


@pytest.mark.parametrize("text, why", [
    (BOMB, r"spec.yaml: line 2, column \d+: YAML alias \*a is not allowed"),
    ("joints: " + "[" * 40 + "]" * 40 + "\n", r"spec.yaml: line 1, column \d+: nested more than 32"),
    ("joints: 2\njoints: 3\n", r"spec.yaml: line 2, column \d+: .*duplicate key 'joints'"),
    ("joints: 1\ntime: {column: t, unit: [s]}\nposition: {columns: [q1], unit: rad}\n",
     r"spec.yaml: time.unit: unknown unit \['s'\]"),
    ("joints: 1\ntime: {column: t, unit: {a: 1}}\nposition: {columns: [q1], unit: rad}\n",
     r"spec.yaml: time.unit: unknown unit \{'a': 1\}"),
    ("joints: 100000000\ntime: {column: t, unit: s}\nposition: {columns: 'q{k}', unit: rad}\n",
     r"spec.yaml: joints: 100000000 joints, more than 256"),
])
def test_spec_yaml_bombs_and_values_of_the_wrong_kind_or_size(tmp_path, text, why):
    # issue 23: an alias bomb in a spec ran past 120 s and 0.8-1.4 GB (now refused from the
    # event stream, before anything expands); a unit given as a list or mapping was a TypeError
    # traceback; 10^8 joints took 11 GB and a minute
    spec = tmp_path / "spec.yaml"
    spec.write_text(text)
    (tmp_path / "run.csv").write_text("t,q1\n0,0\n")
    with pytest.raises(RecordingError, match=why):
        rd.read_recording(tmp_path / "run.csv", spec=spec)


def test_huge_spec_refused_before_parsing(tmp_path):
    spec = tmp_path / "spec.yaml"
    spec.write_text("# padding\n" * 500_000 + "joints: 2\n")
    (tmp_path / "run.csv").write_text("t,q1\n0,0\n")
    with pytest.raises(RecordingError, match=r"spec.yaml: \d+ characters of YAML; at most"):
        rd.read_recording(tmp_path / "run.csv", spec=spec)


def test_study_file_alias_refused(tmp_path):
    from robodyn.robot.errors import StudyError
    from robodyn.studies.study_file import read_study

    path = tmp_path / "study.yaml"
    path.write_text(BOMB)
    with pytest.raises(StudyError, match=r"study.yaml: line 2, column \d+: YAML alias \*a"):
        read_study(path)


def test_gzip_bomb_and_long_files_refused_while_reading(tmp_path, monkeypatch, capsys):
    # issue 23: a 0.8 MB gzip expanding to 800 MB reached 3.3 GB (19 GB here) and a traceback
    from robodyn.cli import main

    bomb = tmp_path / "bomb.csv.gz"
    with gzip.open(bomb, "wb") as fh:
        fh.write(b"t,q1\n" + b"0,0\n" * 300_000)  # 1.2 MB of text
    monkeypatch.setenv("ROBODYN_MAX_FILE_MB", "1")
    assert main(["record", "info", str(bomb)]) == 2
    err = capsys.readouterr().err.strip()
    assert err == ("robodyn: error: bomb.csv.gz: expands to more than 1 MB when decompressed "
                   "(set ROBODYN_MAX_FILE_MB to read it)")
    plain = tmp_path / "long.csv"
    plain.write_bytes(b"t,q1\n" + b"0,0\n" * 300_000)
    with pytest.raises(RecordingError, match=r"long.csv: 1.1 MB, more than the 1 MB read"):
        rd.read_recording(plain)
    monkeypatch.setenv("ROBODYN_MAX_FILE_MB", "10")
    monkeypatch.setenv("ROBODYN_MAX_ROWS", "1000")
    with pytest.raises(RecordingError, match=r"long.csv: 300001 lines, more than the 1000 read "
                                             r"\(set ROBODYN_MAX_ROWS"):
        rd.read_recording(plain)
    # short cells under the size limit: refused by their count (2 x 10^7 by default), before parsing
    monkeypatch.setenv("ROBODYN_MAX_ROWS", "1000000")
    monkeypatch.setenv("ROBODYN_MAX_CELLS", "100000")
    with pytest.raises(RecordingError, match=r"long.csv: 300001 lines of 2 fields, more than the "
                                             r"100000 cells read \(set ROBODYN_MAX_CELLS"):
        rd.read_recording(plain)


def test_time_unit_contradicted_by_positions_and_velocities(tmp_path):
    # issue 23: time.unit s on a sample-index column gave 1 Hz for a 1 kHz log, silently
    k = np.arange(3000)
    t = k * 1e-3
    rows = ["idx,p1,v1"] + [f"{i},{float(np.sin(2 * x))!r},{float(2 * np.cos(2 * x))!r}"
                            for i, x in zip(k, t, strict=True)]
    path = tmp_path / "log.csv"
    path.write_text("\n".join(rows) + "\n")
    spec = {"joints": 1, "time": {"column": "idx", "unit": "s"},
            "position": {"columns": ["p1"], "unit": "rad"}, "velocity": {"columns": ["v1"], "unit": "rad/s"}}
    with pytest.raises(RecordingError, match=r"log.csv: time.unit 's' makes the samples 1 s apart, but "
                                             r"the positions and measured velocities imply 0.001 s"):
        rd.read_recording(path, spec=spec)
    ok = rd.read_recording(path, spec={**spec, "time": {"column": "idx", "unit": "index",
                                                         "period": "estimate"}})
    assert ok.dt == pytest.approx(1e-3, rel=1e-3)


def test_one_corrupt_cell_of_any_field_or_stamp_is_named():
    t = 1e-3 * np.arange(100)
    q = np.sin(np.outer(t, [1.0, 2.0]))
    for field, value, what in (("qd", 1e300, "joint velocity"), ("tau", -1e300, "joint torque"),
                               ("current", 1e7, "motor current")):
        arr = np.ones_like(q)
        arr[40, 1] = value
        with pytest.raises(RecordingError, match=rf"run.csv: {field}: .* at row 40, column 1 \('b'\) "
                                                 rf"is not a plausible {what}"):
            rd.Recording(t=t, q=q, joint_names=("a", "b"), source="run.csv", **{field: arr})
    # a last stamp far off: the filter's uniform grid would need 10^10 samples
    far = t.copy()
    far[-1] = 1e7
    with pytest.raises(RecordingError, match=r"run.csv: t: a step of 1e\+07 s after row 98 .* split the "
                                             r"recording at the gap"):
        rd.Recording(t=far, q=q, joint_names=("a", "b"), source="run.csv")


def test_default_cell_limit_keeps_a_read_under_1_gb():
    # issue 23: 5 x 10^7 cells of a 7-joint log peaked at 3.4 GB; about 18 bytes a cell besides
    # the text now, so the default admits 2 x 10^7
    from robodyn.measure.csv_io import MAX_CELLS, max_cells

    assert MAX_CELLS == max_cells() == 20_000_000


def test_estimated_period_of_a_motionless_log_names_the_file(tmp_path):
    spec = dict(SPEC, time={"column": "time", "unit": "index", "period": "estimate"},
                velocity={"columns": "vel{k}", "unit": "deg/s"})
    text = "time,pos1,pos2,vel1,vel2\n" + "".join(f"{k},1,2,0,0\n" for k in range(20))
    with pytest.raises(RecordingError, match=r"^run.csv: time.period: estimate: cannot estimate the "
                                             r"sample period: the measured velocity is zero"):
        _read(tmp_path, text, spec=spec)


def test_implausible_cell_is_named_by_its_file_line(tmp_path):
    # issue 23: "row 99" was the 0-based sample, the value is on line 101 of the file
    rows = GOOD.splitlines()
    rows[5] = "4,1e308,0.8"
    text = "# a comment line\n\n" + "\n".join(rows) + "\n"  # two lines above the header
    with pytest.raises(RecordingError, match=r"run.csv: q: 1e\+308 at line 8, column 0 \('a'\) is "
                                             r"not a plausible joint position .* that line of"):
        _read(tmp_path, text, spec=dict(SPEC, comment="#", position={"columns": "pos{k}",
                                                                     "unit": "rad"}))
    native = tmp_path / "own.csv"
    native.write_text("t,q[a]\n" + "".join(f"{k * 1e-3},{1e308 if k == 3 else 0}\n"
                                          for k in range(20)))
    with pytest.raises(RecordingError, match=r"own.csv: q: 1e\+308 at line 5, column 0 \('a'\)"):
        rd.read_recording(native)


@pytest.mark.parametrize("newline", ["\n", "\r\n", "\r"])
def test_lines_numbered_through_blank_comment_and_cr_lines(tmp_path, newline):
    rows = GOOD.splitlines()
    rows[4] = "3,x,0.6"
    text = newline.join(["# header comment", rows[0], "", *rows[1:3], "  # note", *rows[3:]])
    with pytest.raises(RecordingError, match=r"column 'pos1' \(position.columns\[0\]\): 'x' is not "
                                             r"a finite number at line 8 "):
        _read(tmp_path, text + newline, spec=dict(SPEC, comment="#"))
    ok = _read(tmp_path, newline.join(["# c", *GOOD.splitlines(), "", ""]),
               spec=dict(SPEC, comment="#"))
    assert ok.n_samples == 20 and ok.q[3, 1] == pytest.approx(np.radians(0.6))
