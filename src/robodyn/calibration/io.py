"""Calibration data in (CSV) and the calibrated description out (YAML, URDF, report).

Calibration CSV: a header row, then one row per measured pose; lines starting with ``#`` are
comments. Columns (any order, extra columns ignored):

* one per joint, named as the robot's joints (``q1`` ... for the built-in PUMA 560), in rad (m
  for prismatic joints);
* ``x``, ``y``, ``z``: the measured target position in the instrument frame, m;
* optional ``qw``, ``qx``, ``qy``, ``qz``: the measured target orientation as a unit quaternion;
* optional ``sigma``: the standard uncertainty of that pose's coordinates, m;
* ``x2``, ``y2``, ``z2`` ... ``xK``, ``yK``, ``zK``: further targets (reflectors) measured at the
  same pose (then the points are (N, K, 3)).

Lengths and angles may be in other units (``mm``, ``deg``): :func:`robodyn.calibration.calibrate`
converts them (``length_unit``, ``angle_unit``; CLI ``--length-unit``, ``--angle-unit``).

Joint mapping (controller columns to model joints: a recording spec, or the short form
``q3: {column: J3, sign: -1, offset: 0.0, coupling: {J2: 1.0}}``):
:mod:`robodyn.calibration.joint_map`.

Every error names the file, and the row (1-based line number in the file) and column where it
is.
"""

from __future__ import annotations

import csv
import io
import json
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from robodyn.calibration.joint_map import JointMap, identity_map, read_joint_map
from robodyn.calibration.result import Calibration, ErrorStats
from robodyn.output_names import output_path
from robodyn.robot.errors import DataFileError
from robodyn.robot.numbers import RobotNumbers

if TYPE_CHECKING:
    from robodyn.robot.model import Robot

__all__ = ["MAX_ABS_VALUE", "CalibrationData", "JointMap", "read_calibration_csv", "read_joint_map",
           "read_table", "write_calibration"]

#: Largest magnitude of a measured value (m, rad, or a quaternion component) in a calibration or
#: ISO 9283 file: 1000 km; beyond it squares overflow and nothing physical is measured.
MAX_ABS_VALUE = 1e6


def read_table(path: str | Path, required: Sequence[str], *, optional: Sequence[str] = (),
               text_columns: Sequence[str] = (), max_abs: float = math.inf) -> dict[str, list]:
    """Columns of a CSV file with a header row, as lists (numbers as floats).

    The file is UTF-8 text (a leading byte-order mark is accepted); blank lines and lines starting
    with ``#`` are skipped; every other line is one CSV record with exactly as many values as the
    header has columns.

    Parameters
    ----------
    path : str or Path
    required : sequence of str
        Columns that must be present.
    optional : sequence of str
        Columns read when present.
    text_columns : sequence of str
        Columns kept as text.
    max_abs : float
        Largest magnitude a number may have (a value beyond it is refused as out of range).

    Returns
    -------
    dict of str to list
        One list per wanted column (required, then the optional ones present), one entry per
        data row.

    Raises
    ------
    FileNotFoundError
        No such file.
    DataFileError
        Not a UTF-8 text file, no header or no data rows, a missing or repeated column, a row
        with more or fewer values than the header, a value that is not a finite number or is
        out of range: the message names the file, the line and the column.
    """
    return _read_table(path, required, optional, text_columns, max_abs)[0]


def _read_table(path: str | Path, required: Sequence[str], optional: Sequence[str],
                text_columns: Sequence[str], max_abs: float = math.inf,
                ) -> tuple[dict[str, list], list[int]]:
    """:func:`read_table` and the line number of each data row."""
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"{path}: no such file")
    lines = _records(path)
    if not lines:
        raise DataFileError(f"{path}: empty file (a header row and data rows are needed)")
    header_line, raw_header = lines[0]
    header = [h.strip() for h in raw_header]
    where = {name: k for k, name in enumerate(header)}
    repeated = sorted({h for h in header if h and header.count(h) > 1})
    if repeated:
        raise DataFileError(f"{path}: line {header_line}: column(s) {', '.join(repeated)} "
                            "appear more than once in the header")
    missing = [c for c in required if c not in where]
    if missing:
        raise DataFileError(f"{path}: line {header_line}: missing column(s) "
                            f"{', '.join(missing)} (the header has {', '.join(header)})")
    if len(lines) < 2:
        raise DataFileError(f"{path}: no data rows after the header")
    wanted = list(required) + [c for c in optional if c in where]
    out: dict[str, list] = {c: [] for c in wanted}
    for lineno, row in lines[1:]:
        if len(row) != len(header):
            # a value too many or too few shifts every column after it: never guess
            raise DataFileError(f"{path}: line {lineno}: {len(row)} values, but the header "
                                f"(line {header_line}) has {len(header)} columns")
        for c in wanted:
            text = row[where[c]].strip()
            if c in text_columns:
                out[c].append(text)
                continue
            try:
                value = float(text)
            except ValueError:
                raise DataFileError(f"{path}: line {lineno}, column {c!r}: {text[:40]!r} is not "
                                    "a number") from None
            if not math.isfinite(value):
                raise DataFileError(f"{path}: line {lineno}, column {c!r}: {text} is not a "
                                    "finite number")
            if abs(value) > max_abs:
                raise DataFileError(f"{path}: line {lineno}, column {c!r}: {text} is out of "
                                    f"range (at most {max_abs:g} in magnitude)")
            out[c].append(value)
    return out, [lineno for lineno, _ in lines[1:]]


def _records(path: Path) -> list[tuple[int, list[str]]]:
    """(line number, CSV values) of each line that is not blank or a ``#`` comment."""
    data = path.read_bytes()
    if b"\0" in data:
        raise DataFileError(f"{path}: a binary file (NUL bytes), not a CSV text file")
    try:
        text = data.decode("utf-8-sig")  # a byte-order mark some spreadsheets write is dropped
    except UnicodeDecodeError as exc:
        raise DataFileError(f"{path}: not a UTF-8 text file (byte {exc.start}: {exc.reason}); "
                            "save it as UTF-8 CSV") from None
    records = []
    for k, line in enumerate(io.StringIO(text, newline=""), start=1):
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        try:
            # one record per line: a quoted value may not span lines
            records.append((k, next(csv.reader([line.rstrip("\r\n")], strict=True))))
        except csv.Error as exc:
            raise DataFileError(f"{path}: line {k}: not a CSV record ({exc})") from None
    return records


@dataclass(frozen=True, eq=False)
class CalibrationData:
    """Measured poses read from a file.

    Attributes
    ----------
    q : numpy.ndarray, shape (N, n)
    points : numpy.ndarray, shape (N, 3)
    orientations : numpy.ndarray or None, shape (N, 3, 3)
    sigma : numpy.ndarray or None, shape (N,)
    source : str
    """

    q: np.ndarray
    points: np.ndarray
    orientations: np.ndarray | None
    sigma: np.ndarray | None
    source: str


def _quaternion_matrix(w, x, y, z) -> np.ndarray:
    """Rotation matrices of unit quaternions (arrays of shape (N,)), shape (N, 3, 3)."""
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
    ], 1)


def _target_count(path: Path) -> int:
    """Number of targets in a calibration CSV's header (``x, y, z``, ``x2, y2, z2`` ...)."""
    records = _records(path)
    header = {h.strip() for h in records[0][1]} if records else set()
    k = 1
    while {f"x{k + 1}", f"y{k + 1}", f"z{k + 1}"} & header:
        k += 1
    return k


def read_calibration_csv(path: str | Path, robot: Robot | RobotNumbers, *, targets: int | None = None,
                         joint_map: JointMap | None = None) -> CalibrationData:
    """Read measured poses for ``robot`` from a calibration CSV (module docstring).

    Parameters
    ----------
    path : str or Path
    robot : Robot or RobotNumbers
    targets : int, optional
        Expected number of targets per pose (checked against the columns); default: as found.
    joint_map : JointMap, optional
        Controller columns to model joints (:func:`read_joint_map`); default: each joint from
        the column of its name. With a recording spec's map the joints come out in rad (m).

    Raises
    ------
    DataFileError
        Besides the table errors: a target count that differs from the data's columns, a
        mapping column the file does not have.
    """
    found = _target_count(Path(path)) if Path(path).exists() else 1
    if targets is not None and targets != found:
        raise DataFileError(f"{path}: {targets} target(s) per pose were declared but the columns hold "
                            f"{found} (x, y, z" + "".join(f", x{k}, y{k}, z{k}" for k in range(2, found + 1))
                            + ")")
    xyz = [f"{a}{k if k > 1 else ''}" for k in range(1, found + 1) for a in "xyz"]
    jmap = joint_map if joint_map is not None else identity_map(robot)
    table, lines = _read_table(path, list(jmap.columns) + xyz,
                               ["qw", "qx", "qy", "qz", "sigma"], (), MAX_ABS_VALUE)
    q = jmap.apply(table)  # q = W c + b (sign, offset, couplings; a spec's unit)
    points = np.stack([np.column_stack([table[f"{a}{k if k > 1 else ''}"] for a in "xyz"])
                       for k in range(1, found + 1)], axis=1)
    if found == 1:
        points = points[:, 0]
    orientations = None
    quat = [c for c in ("qw", "qx", "qy", "qz") if c in table]
    if quat and len(quat) != 4:
        raise DataFileError(f"{path}: orientation needs all of qw, qx, qy, qz (found "
                            f"{', '.join(quat)})")
    if quat:
        qq = np.column_stack([table[c] for c in ("qw", "qx", "qy", "qz")])
        norm = np.linalg.norm(qq, axis=1)
        bad = np.flatnonzero(np.abs(norm - 1) > 1e-3)
        if bad.size:
            raise DataFileError(f"{path}: line {lines[bad[0]]}: quaternion (qw, qx, qy, qz) has "
                                f"norm {norm[bad[0]]:.6g}, not 1")
        qq = qq / norm[:, None]
        orientations = _quaternion_matrix(*qq.T)
    sigma = None
    if "sigma" in table:
        sigma = np.array(table["sigma"])
        bad = np.flatnonzero(~(sigma > 0))
        if bad.size:
            raise DataFileError(f"{path}: line {lines[bad[0]]}, column 'sigma': "
                                f"{sigma[bad[0]]:g} is not positive")
    return CalibrationData(q, points, orientations, sigma, str(path))


def write_calibration_csv(path: str | Path, robot: Robot | RobotNumbers, q: np.ndarray,
                          points: np.ndarray) -> None:
    """Write poses in the calibration CSV format (for tests and simulated data)."""
    with Path(path).open("w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow([*robot.joint_names, "x", "y", "z"])
        for qi, pi in zip(q, points, strict=True):
            w.writerow([repr(float(v)) for v in (*qi, *pi)])


def _report_data(cal: Calibration) -> dict:
    """The report as plain data (SI units)."""
    return {
        "robot": cal.robot.name,
        "model": cal.model.name,
        "initial": cal.initial,
        "loss": cal.loss,
        "poses": cal.pose_count,
        "sigma_m": cal.sigma,
        "variance_factor": cal.variance_factor,
        "converged": cal.converged,
        "message": cal.message,
        "before_m": cal.before.__dict__,
        "after_m": cal.after.__dict__,
        "parameters": [p.__dict__ for p in cal.parameters],
        "unidentifiable": [
            {"name": u.name, "value": u.value, "kind": u.kind, "reason": u.reason,
             "combination": [list(c) for c in u.combination]}
            for u in cal.unidentifiable
        ],
        "observability": cal.observability.as_dict(),
        "targets_m": cal.target_offsets().tolist(),
        "nongeometric": cal.nongeometric,
        "residuals_m": np.asarray(cal.residuals).tolist(),
        **({} if cal.rotation_residuals is None else {
            "orientation_after_rad": ErrorStats.from_residuals(cal.rotation_residuals).__dict__,
            "rotation_residuals_rad": np.asarray(cal.rotation_residuals).tolist()}),
    }


def terms_data(cal: Calibration) -> dict:
    """Every target's offset and the non-geometric terms, with their names and units.

    Targets are positions in the calibrated robot's last link frame (the first is the robot's
    tool; a description has one tool, so the others live only here); the terms are
    ``q_link = q + B(q) theta`` (:mod:`robodyn.calibration.nongeometric`), which the YAML
    description also carries as joint-reading corrections (:mod:`robodyn.robot.corrections`).
    """
    return {"robot": cal.robot.name, "model": cal.model.name,
            "targets_in_last_frame_m": cal.target_offsets().tolist(),
            "nongeometric": cal.nongeometric}


def write_calibration(cal: Calibration, out_dir: str | Path, *,
                      stem: str | None = None) -> dict[str, Path | None]:
    """Write the calibrated description and a report into ``out_dir``.

    Files: ``<stem>.yaml`` (robodyn description, :func:`robodyn.robot.yaml_writer.dump_yaml`),
    ``<stem>.urdf`` (:func:`robodyn.export.urdf.to_urdf`, when that exporter is available),
    ``<stem>_terms.yaml`` (every target's offset and the non-geometric terms, when there are
    several targets or non-geometric terms: :func:`terms_data`; the YAML description carries
    the terms too, the URDF cannot),
    ``<stem>_report.txt`` (:meth:`Calibration.summary`), ``<stem>_report.json`` (the same as
    data, with the residuals) and ``<stem>_residuals.csv``.

    Returns
    -------
    dict
        Paths by kind (``"yaml"``, ``"urdf"``, ``"report"``, ``"json"``, ``"residuals"``); ``"urdf"``
        is None when no URDF writer is available (``"note"`` then says so).

    Raises
    ------
    ValueError
        ``stem`` is not a plain file name (a path separator, ``..``): nothing is written outside
        ``out_dir``.
    """
    from robodyn.robot.yaml_writer import dump_yaml

    out = Path(out_dir)
    stem = stem if stem is not None else cal.robot.name
    # every name is checked before anything is written: all files inside out_dir, or none
    names = {kind: output_path(out, stem, suffix)
             for kind, suffix in (("yaml", ".yaml"), ("terms", "_terms.yaml"), ("urdf", ".urdf"),
                                  ("report", "_report.txt"),
                                  ("json", "_report.json"), ("residuals", "_residuals.csv"))}
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OSError(f"{out}: cannot create the output directory: {exc}") from None
    paths: dict[str, Path | None] = {}
    paths["yaml"] = names["yaml"]
    paths["yaml"].write_text(dump_yaml(cal.robot), encoding="utf-8")
    paths["terms"] = None
    if cal.model.targets > 1 or cal.model.nongeometric is not None:
        import yaml

        # the other targets (and the terms by their calibration names): a companion file
        paths["terms"] = names["terms"]
        paths["terms"].write_text(yaml.safe_dump(terms_data(cal), sort_keys=False), encoding="utf-8")
    try:
        from robodyn.export.urdf import to_urdf
    except ImportError:
        to_urdf = None
    if to_urdf is not None:
        import warnings

        from robodyn.robot.errors import DescriptionWarning

        paths["urdf"] = names["urdf"]
        with warnings.catch_warnings():
            # drive data and gravity direction are kept in the YAML; URDF cannot hold them
            warnings.simplefilter("ignore", DescriptionWarning)
            to_urdf(cal.robot, paths["urdf"])
    else:
        paths["urdf"] = None  # no URDF exporter in this installation: YAML only
    paths["report"] = names["report"]
    paths["report"].write_text(cal.summary() + "\n", encoding="utf-8")
    paths["json"] = names["json"]
    paths["json"].write_text(json.dumps(_report_data(cal), indent=1) + "\n", encoding="utf-8")
    paths["residuals"] = names["residuals"]
    with paths["residuals"].open("w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow(["pose", "target", "dx", "dy", "dz", "distance"])
        res = np.asarray(cal.residuals).reshape(cal.pose_count, -1, 3)
        for k, per_pose in enumerate(res):
            for t, r in enumerate(per_pose, start=1):
                w.writerow([k, t, repr(float(r[0])), repr(float(r[1])), repr(float(r[2])),
                            repr(float(np.linalg.norm(r)))])
    return paths
