"""CSV/TSV recordings (optionally gzip-compressed): reading through a spec, robodyn's own layout.

Reading checks the file before trusting it: every row must have as many fields as the header
(or the first row), every used cell must be a finite number, and the time column must increase;
each error names the file, the column and the spec field that asked for it, and the 1-based line
of the file. The numbers themselves are parsed by ``pandas.read_csv``.

robodyn's own layout (written by :func:`write_csv`, read with ``spec=None``): a header
``t, q[NAME]..., qd[NAME]..., qdd[NAME]..., tau[NAME]..., current[NAME]..., temperature[NAME]...,
tool_t, tool_x, tool_y, tool_z`` in SI units with only the fields that were measured (estimated
ones are estimated again on reading); tool samples fill the first M rows of their columns, the
rest of those cells are empty. Numbers are written with 17 significant digits, so a round trip
is exact.
"""

from __future__ import annotations

import csv
import gzip
import io
import re
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from os import PathLike
from pathlib import Path
from typing import IO, Any

import numpy as np
import pandas as pd

from robodyn.measure.conversions import (
    counts_to_angle,
    current_to_torque,
    estimate_period,
    unwrap_counter,
    volts_to_current,
)
from robodyn.measure.recording import JOINT_FIELDS, PLAUSIBLE, Recording, check_plausible
from robodyn.measure.spec import (
    CURRENT_UNITS,
    POSITION_UNITS,
    TIME_UNITS,
    TORQUE_UNITS,
    VELOCITY_UNITS,
    Channel,
    RecordingSpec,
    load_spec,
)
from robodyn.robot.errors import RecordingError
from robodyn.robot.sizes import env_limit

__all__ = ["read_csv", "write_csv"]

_NATIVE = re.compile(r"^(q|qd|qdd|tau|current|temperature)\[(.+)\]$")
_TOOL = ("tool_t", "tool_x", "tool_y", "tool_z")


# ----------------------------------------------------------------------------------------------
# the table: lines, field counts, numbers
# ----------------------------------------------------------------------------------------------

#: Largest text a recording file may hold (decompressed), bytes; ``$ROBODYN_MAX_FILE_MB`` raises it.
MAX_FILE_BYTES = 512 * 2**20


def max_file_bytes() -> int:
    """The text size limit: ``$ROBODYN_MAX_FILE_MB`` (megabytes) when set, else the default."""
    return env_limit("ROBODYN_MAX_FILE_MB", MAX_FILE_BYTES, scale=2**20)


#: Most lines a recording file may hold (``$ROBODYN_MAX_ROWS`` raises it): 5 x 10^6 lines are
#: 83 minutes at 1 kHz.
MAX_ROWS = 5_000_000


def max_rows() -> int:
    """The line limit: ``$ROBODYN_MAX_ROWS`` when set to a positive integer, else the default."""
    return env_limit("ROBODYN_MAX_ROWS", MAX_ROWS)


#: Most cells (lines x fields) a recording file may hold (``$ROBODYN_MAX_CELLS`` raises it):
#: reading costs about 18 bytes a cell besides the text (the parsed numbers, pandas' chunks, the
#: columns used), so 2 x 10^7 cells stay under 1 GB even with 500 MB of text (a 7-joint log of 78
#: columns: 256,000 samples in 0.6 GB); a text of short cells ("0,0,0,...") under the size limit
#: would otherwise parse to several gigabytes.
MAX_CELLS = 20_000_000


def max_cells() -> int:
    """The cell limit: ``$ROBODYN_MAX_CELLS`` when set to a positive integer, else the default."""
    return env_limit("ROBODYN_MAX_CELLS", MAX_CELLS)


def read_text_bytes(path: Path, error: type[Exception]) -> bytes:
    """The bytes of a text file, gunzipped when its name ends in ``.gz``, refused (``error``)
    beyond :func:`max_file_bytes`: a gzip bomb of 0.8 MB expanding to gigabytes is stopped
    while it is read, not after."""
    limit = max_file_bytes()
    name = path.name
    if path.suffix.lower() != ".gz":
        if path.stat().st_size > limit:
            raise error(f"{name}: {path.stat().st_size / 2**20:.1f} MB, more than the "
                        f"{limit / 2**20:g} MB read (set ROBODYN_MAX_FILE_MB to read it)")
        return path.read_bytes()
    out = bytearray()
    try:
        with gzip.open(path, "rb") as fh:
            while chunk := fh.read(1 << 20):
                out += chunk
                if len(out) > limit:
                    raise error(f"{name}: expands to more than {limit / 2**20:g} MB when "
                                "decompressed (set ROBODYN_MAX_FILE_MB to read it)")
    except (OSError, EOFError) as exc:
        raise error(f"{name}: not a readable gzip file ({exc})") from None
    return out  # type: ignore[return-value]  # a bytearray decodes like bytes, without a copy


#: The ``delimiter`` of a recording spec for fields separated by runs of spaces or tabs.
WHITESPACE = "whitespace"

_BOM = b"\xef\xbb\xbf"


def _scan_lines(raw: bytes | bytearray, name: str, delimiter: str, comment: str | None
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The data lines of ``raw``, one line at a time (no decoded copy of the whole text):
    0-based line numbers, start and end byte offsets of the kept lines (not blank, not a
    comment) and each kept line's field separators (runs of spaces for ``WHITESPACE``)."""
    mark = comment.encode() if comment else None
    sep = delimiter.encode()
    keep: list[int] = []
    starts: list[int] = []
    ends: list[int] = []
    counts: list[int] = []
    pos, size, k = (3 if raw[:3] == _BOM else 0), len(raw), 0
    while pos < size:
        end = raw.find(b"\n", pos)
        end = size if end < 0 else end
        line = raw[pos:end]
        try:
            line.decode("utf-8")
        except UnicodeDecodeError as exc:
            raise RecordingError(f"{name}: not UTF-8 text (byte {pos + exc.start})") from None
        stripped = line.strip()
        if stripped and not (mark and stripped.startswith(mark)):
            keep.append(k)
            starts.append(pos)
            ends.append(end)
            counts.append(len(stripped.split()) - 1 if delimiter == WHITESPACE else line.count(sep))
        pos, k = end + 1, k + 1
    return tuple(np.asarray(v, dtype=np.int64)  # type: ignore[return-value]
                 for v in (keep, starts, ends, counts))


class _Lines:
    """The kept lines of a text as a binary file for ``pandas.read_csv``: ``read(size)`` returns
    whole lines (stripped when ``strip``), so no second copy of the text is made."""

    mode = "rb"

    def __init__(self, raw: bytes | bytearray, starts: np.ndarray, ends: np.ndarray, strip: bool):
        self.raw, self.starts, self.ends, self.strip, self.k = memoryview(raw), starts, ends, strip, 0
        # every line kept and none to strip: contiguous slices of the text
        self.whole = not strip and bool(starts.size) and int(ends[-1] - starts[0]) == \
            int(np.sum(ends - starts)) + starts.size - 1
        self.pos = int(starts[0]) if starts.size else 0

    def read(self, size: int = -1) -> bytes:
        size = len(self.raw) if size is None or size < 0 else max(size, 1)
        if self.whole:
            stop = min(self.pos + size, int(self.ends[-1]))
            out = bytes(self.raw[self.pos:stop])
            self.pos = stop
            return out
        parts, total = [], 0
        while self.k < self.starts.size and total < size:
            line = bytes(self.raw[self.starts[self.k]:self.ends[self.k]])
            line = line.strip() if self.strip else line
            parts.append(line + b"\n")
            total += len(line) + 1
            self.k += 1
        return b"".join(parts)

    def __iter__(self) -> Any:
        return iter(lambda: self.read(1 << 16), b"")


class _Table:
    """The data rows of a delimited text file, with the file's line number of every row
    (``delimiter=WHITESPACE``: fields separated by runs of spaces or tabs)."""

    def __init__(self, path: Path, delimiter: str | None, header: bool, comment: str | None):
        self.name = path.name
        raw = read_text_bytes(path, RecordingError)
        # lines and cells counted on the bytes, before a decoded copy exists
        rows, limit = raw.count(b"\n"), max_rows()
        if rows > limit:
            raise RecordingError(f"{self.name}: {rows} lines, more than the {limit} read (set "
                                 "ROBODYN_MAX_ROWS to read it)")
        end = raw.find(b"\n")
        first = bytes(raw[:end if end >= 0 else len(raw)])
        sep = [b",", b"\t", b";"] + ([delimiter.encode()] if delimiter not in (None, WHITESPACE) else [])
        fields = max([len(first.split())] + [first.count(d) + 1 for d in sep])
        if rows * fields > max_cells():
            raise RecordingError(f"{self.name}: {rows} lines of {fields} fields, more than the "
                                 f"{max_cells():g} cells read (set ROBODYN_MAX_CELLS to read it)")
        if b"\r" in raw and raw.count(b"\r") != raw.count(b"\r\n"):
            raw = raw.replace(b"\r\n", b"\n").replace(b"\r", b"\n")  # old Mac line ends
        if delimiter is None:
            delimiter = "\t" if ".tsv" in [s.lower() for s in path.suffixes] else ","
        keep, starts, ends, counts = _scan_lines(raw, self.name, delimiter, comment)
        if not keep.size:
            raise RecordingError(f"{self.name}: empty file (no header and no data rows)")
        if header and keep.size == 1:
            raise RecordingError(f"{self.name}: header only, no data rows (line {keep[0] + 1})")
        # every row has as many fields as the first (header) row
        bad = np.nonzero(counts != counts[0])[0] if b'"' not in raw else ()
        if len(bad):
            k = int(bad[0])
            first_row = "header" if header else "first row"
            raise RecordingError(f"{self.name}: line {keep[k] + 1}: {counts[k] + 1} fields, but the "
                                 f"{first_row} (line {keep[0] + 1}) has {counts[0] + 1}")
        spaces = delimiter == WHITESPACE
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", pd.errors.DtypeWarning)  # columns read in chunks
                frame = pd.read_csv(_Lines(raw, starts, ends, spaces), sep=r"\s+" if spaces else delimiter,
                                    header=0 if header else None, skip_blank_lines=False,
                                    engine="c", keep_default_na=False, encoding="utf-8")
        except (pd.errors.ParserError, ValueError) as exc:
            raise RecordingError(f"{self.name}: cannot parse as delimited text "
                                 f"({' '.join(str(exc).split())})") from None
        del raw
        self.frame = frame
        self.line = (keep[1:] if header else keep) + 1  # 1-based line of each row
        self.header = header
        self.columns = [str(c) for c in frame.columns] if header else list(range(frame.shape[1]))

    def has(self, column: str | int) -> bool:
        if isinstance(column, int):
            return column < self.frame.shape[1]
        return self.header and column in self.columns

    def _label(self, column: str | int) -> str:
        return f"column {column!r}" if isinstance(column, str) else f"column {column} (0-based)"

    def column(self, column: str | int, field: str, allow_empty: bool = False) -> np.ndarray:
        """Column as floats; missing, non-numeric and non-finite cells are errors."""
        if not self.has(column):
            if isinstance(column, int):
                why = f"the file has {self.frame.shape[1]} columns"
            elif not self.header:
                why = "the spec says header: false, so columns are 0-based indices"
            else:
                shown = ", ".join(self.columns[:12]) + (", ..." if len(self.columns) > 12 else "")
                why = f"the file's columns: {shown}"
            raise RecordingError(f"{self.name}: {field}: {self._label(column)} not in the file ({why})")
        series = self._series(column)
        values = pd.to_numeric(series, errors="coerce").to_numpy(dtype=float, copy=True)
        bad = ~np.isfinite(values)
        if allow_empty:
            bad &= (series != "").to_numpy()
        if bad.any():
            self.fail(column, field, bad)
        if allow_empty:
            values[(series == "").to_numpy()] = np.nan
        return values

    def _series(self, column: str | int) -> pd.Series:
        return self.frame.iloc[:, column] if isinstance(column, int) else self.frame[column]

    def fail(self, column: str | int, field: str, bad: np.ndarray) -> None:
        """Raise for the first bad cell of ``column`` (a boolean mask over the rows)."""
        k = int(np.argmax(bad))
        cell = self._series(column).iloc[k]
        if isinstance(cell, str):
            reason = "empty cell" if cell.strip() == "" else f"{cell!r} is not a finite number"
        else:
            reason = f"{cell} is not a finite number"
        raise RecordingError(f"{self.name}: {self._label(column)} ({field}): {reason} at line "
                             f"{self.line[k]} ({int(bad.sum())} bad cell(s) in this column)")


# ----------------------------------------------------------------------------------------------
# reading through a spec
# ----------------------------------------------------------------------------------------------


def _block(table: _Table, ch: Channel) -> np.ndarray:
    assert ch.columns is not None
    return np.column_stack([table.column(c, f"{ch.field}.columns[{k}]")
                            for k, c in enumerate(ch.columns)])


def _no_sensor(values: np.ndarray, ch: Channel) -> np.ndarray:
    """All-zero columns become NaN (joint without that sensor) when the spec says missing: zero."""
    if ch.missing == "zero":
        values = values.copy()
        values[:, np.all(values == 0.0, axis=0)] = np.nan
    return values


def _position(table: _Table, ch: Channel) -> np.ndarray:
    raw = _block(table, ch)
    if ch.unit == "counts":
        if ch.wrap_bits is not None:
            raw = unwrap_counter(raw, ch.wrap_bits)
        value = counts_to_angle(raw, ch.counts_per_rev, ch.gear_ratio)
    else:
        value = raw * POSITION_UNITS[ch.unit] / ch.gear_ratio
    return ch.sign * value + ch.offset  # joint = sign * converted + offset


def _velocity(table: _Table, ch: Channel) -> np.ndarray:
    raw = _block(table, ch)
    if ch.unit == "counts/s":
        value = counts_to_angle(raw, ch.counts_per_rev, ch.gear_ratio)
    else:
        value = raw * VELOCITY_UNITS[ch.unit] / ch.gear_ratio
    return ch.sign * value


def _current(table: _Table, ch: Channel) -> np.ndarray:
    raw = _block(table, ch)
    if ch.unit == "V":
        value = volts_to_current(raw, ch.offset, ch.gain)  # I = (V - offset) / gain
    else:
        value = raw * CURRENT_UNITS[ch.unit] - ch.offset
    return _no_sensor(ch.sign * value, ch)


def _time(table: _Table, spec: RecordingSpec) -> np.ndarray:
    raw = table.column(spec.time_column, "time.column")
    steps = np.diff(raw)
    if np.any(steps <= 0):
        k = int(np.argmax(steps <= 0)) + 1
        raise RecordingError(f"{table.name}: {table._label(spec.time_column)} (time.column): not "
                             f"strictly increasing at line {table.line[k]} ({raw[k]:.9g} after "
                             f"{raw[k - 1]:.9g} on line {table.line[k - 1]})")
    return raw


#: A time unit whose stamps step by more than this factor from the period that positions and
#: measured velocities imply is refused.
TIME_UNIT_FACTOR = 5.0


def _check_time_unit(name: str, unit: str, t: np.ndarray, q: np.ndarray, qd: np.ndarray) -> None:
    """Refuse a ``time.unit`` the data contradict: the median step of the stamps against the
    period the position increments and measured velocities imply (``time.unit: s`` on a sample
    index gave 1 Hz for a 1 kHz log)."""
    if t.size < 3 or not np.any(np.abs(qd) > 0):
        return
    try:
        implied = estimate_period(q, qd)
    except ValueError:
        return
    step = float(np.median(np.diff(t)))
    if implied > 0 and not 1 / TIME_UNIT_FACTOR <= step / implied <= TIME_UNIT_FACTOR:
        raise RecordingError(
            f"{name}: time.unit {unit!r} makes the samples {step:.6g} s apart, but the positions "
            f"and measured velocities imply {implied:.6g} s: check time.unit (a sample index is "
            "unit: index, with period: estimate or the period in seconds)")


def read_csv(path: str | PathLike[str], spec: Any = None, robot: Any = None) -> Recording:
    """Read a CSV/TSV recording (``.gz`` decompressed) through a recording spec.

    Parameters
    ----------
    path : str or path
        The file; it is only read.
    spec : str, path or mapping, optional
        Built-in spec name, YAML file or dict (:func:`robodyn.measure.spec.load_spec`); None for
        robodyn's own layout (:func:`write_csv`).
    robot : Robot, optional
        Joints are matched by name and returned in the robot's chain order.

    Returns
    -------
    Recording
        SI units; positions after unwrapping, scaling, gear ratio, sign, offset and couplings.
    """
    p = Path(path)
    if spec is None:
        return _select_robot(_read_native(p), robot)
    sp = load_spec(spec)
    table = _Table(p, sp.delimiter, sp.header, sp.comment)
    ch = sp.channels
    raw_t = _time(table, sp)
    q = _position(table, ch["position"])
    qd = _velocity(table, ch["velocity"]) if "velocity" in ch else None
    coupling = sp.coupling_matrix()
    if sp.couplings:
        q = q @ coupling.T  # q_true = C q_measured, row by row
        qd = None if qd is None else qd @ coupling.T
    units = {}
    if sp.time_unit == "index":
        if sp.period == "estimate":
            try:
                period = estimate_period(q, qd)
            except ValueError as exc:
                raise RecordingError(f"{table.name}: time.period: estimate: {exc}") from None
            units["sample_period"] = (f"{period:.6g} s, estimated from position increments "
                                      "against measured velocity")
        else:
            period = float(sp.period)
        t = (raw_t - raw_t[0]) * period
    else:
        t = raw_t * TIME_UNITS[sp.time_unit]
        if qd is not None:
            _check_time_unit(table.name, sp.time_unit, t, q, qd)
    current = _current(table, ch["current"]) if "current" in ch else None
    tau = None
    if "torque" in ch:
        tc = ch["torque"]
        if tc.columns is None:
            tau = current_to_torque(current, tc.gear_ratio, tc.torque_constant) * tc.sign
        else:
            tau = _no_sensor(tc.sign * _block(table, tc) * TORQUE_UNITS[tc.unit], tc)
    temperature = _no_sensor(_block(table, ch["temperature"]), ch["temperature"]) \
        if "temperature" in ch else None
    tau, current, temperature = (None if a is None or np.isnan(a).all() else a
                                 for a in (tau, current, temperature))
    for field, value in (("q", q), ("qd", qd), ("tau", tau), ("current", current),
                         ("temperature", temperature)):
        if value is not None:  # an implausible cell named by its line of the file
            check_plausible(f"{table.name}: {field}", field, value, sp.joint_names, table.line)
    rec = Recording(t=t, q=q, qd=qd, tau=tau, current=current, temperature=temperature,
                    joint_names=sp.joint_names, units=units, source=p.name)
    return _select_robot(rec, robot)


def _select_robot(rec: Recording, robot: Any) -> Recording:
    if robot is None:
        return rec
    wanted = tuple(robot.joint_names)
    missing = [j for j in wanted if j not in rec.joint_names]
    if missing:
        raise RecordingError(f"{rec.source}: joint names {list(rec.joint_names)} do not match the "
                             f"robot {robot.name!r} ({list(wanted)}): missing {missing}")
    return rec.select(list(wanted))


# ----------------------------------------------------------------------------------------------
# robodyn's own layout
# ----------------------------------------------------------------------------------------------


def _read_native(p: Path) -> Recording:
    table = _Table(p, None, True, "#")
    if not table.columns or table.columns[0] != "t":
        raise RecordingError(f"{p.name}: spec: the file is not in robodyn's own layout (first column "
                             f"'t', then 'q[NAME]', ...); pass spec= (a built-in name, a YAML file "
                             f"or a dict) to say which columns hold what")
    fields: dict[str, list[str]] = {}
    for c in table.columns[1:]:
        m = _NATIVE.match(c)
        if m:
            fields.setdefault(m.group(1), []).append(m.group(2))
        elif c not in _TOOL:
            raise RecordingError(f"{p.name}: column {c!r}: not a column of robodyn's layout "
                                 "(t, q[NAME], qd[NAME], ..., tool_t, tool_x, tool_y, tool_z)")
    names = fields.get("q")
    if not names:
        raise RecordingError(f"{p.name}: no q[NAME] columns (joint positions are required)")
    t_all = table.column("t", "t", allow_empty=True)
    n = int(np.argmax(np.isnan(t_all))) if np.isnan(t_all).any() else t_all.size
    if not np.isnan(t_all[n:]).all():
        table.fail("t", "t", np.arange(t_all.size) == n)
    arrays: dict[str, Any] = {}
    for field, cols in fields.items():
        if cols != names:
            raise RecordingError(f"{p.name}: {field}[...] columns name the joints {cols}, but the "
                                 f"q[...] columns name {names}")
        block = np.column_stack([table.column(f"{field}[{j}]", field, allow_empty=True)
                                 for j in names])
        head = block[:n]
        # empty cells: allowed below the last joint sample, and as a whole sensor column
        bad = np.isnan(head)
        if field in ("tau", "current", "temperature"):
            bad &= ~np.all(bad, axis=0)
        if bad.any():
            c = int(np.argwhere(bad)[0][1])
            table.fail(f"{field}[{names[c]}]", field, bad[:, c])
        if field in PLAUSIBLE:
            check_plausible(f"{p.name}: {field}", field, head, names, table.line)
        arrays[field] = head
    tool: dict[str, Any] = {}
    if "tool_t" in table.columns:
        cols = [table.column(c, c, allow_empty=True) for c in _TOOL]
        m = int(np.sum(~np.isnan(cols[0])))
        for c, v in zip(_TOOL, cols, strict=True):
            if np.isnan(v[:m]).any() or not np.isnan(v[m:]).all():
                k = int(np.argmax(np.isnan(v[:m]))) if np.isnan(v[:m]).any() else m
                raise RecordingError(f"{p.name}: column {c!r}: the tool samples must fill the first "
                                     f"rows without gaps (line {table.line[min(k, len(v) - 1)]})")
        tool = {"tool_t": cols[0][:m], "tool_points": np.column_stack(cols[1:])[:m]}
    return Recording(t=t_all[:n], joint_names=tuple(names), source=p.name, **arrays, **tool)


def write_csv(rec: Recording, path: str | PathLike[str]) -> Path:
    """Write a recording in robodyn's own CSV layout (gzip-compressed when the name ends in .gz).

    Only measured fields are written (those in ``rec.estimated`` are estimated again when the file
    is read), with 17 significant digits so that :func:`read_csv` returns the same numbers.

    Returns
    -------
    Path
        The file written.
    """
    p = Path(path)
    n_rows = max(rec.n_samples, 0 if rec.tool_t is None else rec.tool_t.size)
    cols: dict[str, np.ndarray] = {"t": rec.t}
    for field in JOINT_FIELDS:
        value = getattr(rec, field)
        if value is None or field in rec.estimated:
            continue
        for k, name in enumerate(rec.joint_names):
            cols[f"{field}[{name}]"] = value[:, k]
    if rec.tool_t is not None:
        cols["tool_t"] = rec.tool_t
        for k, axis in enumerate("xyz"):
            cols[f"tool_{axis}"] = rec.tool_points[:, k]
    with _text_out(p) as fh:
        csv.writer(fh, lineterminator="\n").writerow(list(cols))
        _write_rows(fh, list(cols.values()), n_rows)
    return p


#: Rows formatted at a time by :func:`write_csv` (a few MB of text).
_WRITE_ROWS = 20_000


@contextmanager
def _text_out(p: Path) -> Iterator[IO[str]]:
    """A text file for writing, gzip-compressed (without a time stamp) when the name ends in .gz."""
    if p.suffix.lower() != ".gz":
        with p.open("w", encoding="utf-8", newline="") as fh:
            yield fh
        return
    with p.open("wb") as raw, gzip.GzipFile(filename="", mode="wb", fileobj=raw, mtime=0) as gz, \
            io.TextIOWrapper(gz, encoding="utf-8", newline="") as fh:
        yield fh


def _write_rows(fh: IO[str], columns: list[np.ndarray], n_rows: int) -> None:
    """Columns (each at most ``n_rows`` long, the rest of its cells empty) as rows of 17
    significant digits, a block of rows at a time: no text of the whole file in memory."""
    line = ",".join(["%.17g"] * len(columns))
    for start in range(0, n_rows, _WRITE_ROWS):
        stop = min(start + _WRITE_ROWS, n_rows)
        block = np.full((stop - start, len(columns)), np.nan)
        for k, c in enumerate(columns):
            part = c[start:stop]
            block[:part.size, k] = part
        text = "\n".join([line % tuple(row) for row in block.tolist()])
        fh.write(text.replace("nan", "") + "\n")  # NaN: an empty cell
