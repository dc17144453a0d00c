"""Recording specs: which columns of a CSV/TSV file hold which signal, in which unit.

A spec is a small YAML mapping (see ``docs/recording-spec.md`` for a commented example):
``delimiter``, ``header``, ``joints``, ``time``, ``position``, ``velocity``, ``current``,
``torque``, ``temperature`` and ``couplings``. It is validated strictly when loaded: unknown keys,
unit typos and values of the wrong kind are refused with the spec's name and the field path.
Built-in specs live in ``robodyn/measure/specs/*.yaml``.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass
from importlib import resources
from os import PathLike
from pathlib import Path
from typing import Any

import numpy as np

from robodyn.robot.errors import RecordingError
from robodyn.robot.safe_yaml import safe_yaml

__all__ = ["Channel", "Coupling", "RecordingSpec", "builtin_specs", "load_spec"]

TIME_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9, "index": None}
POSITION_UNITS = {"rad": 1.0, "deg": math.pi / 180.0, "counts": None, "m": 1.0, "mm": 1e-3}
VELOCITY_UNITS = {"rad/s": 1.0, "deg/s": math.pi / 180.0, "counts/s": None, "m/s": 1.0,
                  "mm/s": 1e-3}
CURRENT_UNITS = {"A": 1.0, "mA": 1e-3, "V": None}
TORQUE_UNITS = {"N m": 1.0, "N mm": 1e-3, "N": 1.0}
TEMPERATURE_UNITS = {"degC": 1.0}

#: Most joints a recording spec may name (a robot arm has a handful; a typo of 10^8 allocated GBs).
MAX_JOINTS = 256

_TOP = ("description", "delimiter", "header", "comment", "joints", "time", "position", "velocity",
        "current", "torque", "temperature", "couplings")
_ALLOWED = {
    "position": ("columns", "unit", "sign", "offset", "gear_ratio", "counts_per_rev", "wrap_bits"),
    "velocity": ("columns", "unit", "sign", "gear_ratio", "counts_per_rev"),
    "current": ("columns", "unit", "sign", "offset", "gain", "missing"),
    "torque": ("columns", "unit", "sign", "missing", "from", "gear_ratio", "torque_constant"),
    "temperature": ("columns", "unit", "missing"),
}
_UNITS = {"position": POSITION_UNITS, "velocity": VELOCITY_UNITS, "current": CURRENT_UNITS,
          "torque": TORQUE_UNITS, "temperature": TEMPERATURE_UNITS}


@dataclass(frozen=True)
class Channel:
    """One per-joint signal block of a spec (position, velocity, current, torque, temperature).

    ``columns`` holds n column names (str) or 0-based indices (int); None for a torque computed
    from current. Per-joint numbers are (n,) arrays.
    """

    field: str
    columns: tuple[str | int, ...] | None
    unit: str
    sign: np.ndarray
    offset: np.ndarray
    gear_ratio: np.ndarray
    counts_per_rev: np.ndarray | None = None
    wrap_bits: int | None = None
    gain: np.ndarray | None = None
    torque_constant: np.ndarray | None = None
    missing: str = "error"  # "error" | "zero": an all-zero column means "no sensor"


@dataclass(frozen=True)
class Coupling:
    """``q[joint] += sum(factor * q_measured[other])`` for positions and velocities."""

    joint: int
    terms: tuple[tuple[int, float], ...]


@dataclass(frozen=True)
class RecordingSpec:
    """A validated recording spec (see the module notes)."""

    name: str
    joint_names: tuple[str, ...]
    delimiter: str | None
    header: bool
    comment: str | None
    time_column: str | int | None  # None: a spec of joint conventions only (need_time=False)
    time_unit: str
    period: float | str | None  # seconds per sample for unit "index", or "estimate"
    channels: Mapping[str, Channel]
    couplings: tuple[Coupling, ...]

    @property
    def dof(self) -> int:
        return len(self.joint_names)

    def coupling_matrix(self) -> np.ndarray:
        """(n, n) matrix C with ``q_true = C q_measured``."""
        c = np.eye(self.dof)
        for cp in self.couplings:
            for other, factor in cp.terms:
                c[cp.joint, other] += factor
        return c


def builtin_specs() -> tuple[str, ...]:
    """Names of the built-in specs."""
    root = resources.files("robodyn.measure") / "specs"
    return tuple(sorted(p.name[:-5] for p in root.iterdir() if p.name.endswith(".yaml")))


def load_spec(spec: str | PathLike[str] | Mapping[str, Any], *, need_time: bool = True) -> RecordingSpec:
    """A :class:`RecordingSpec` from a built-in name, a YAML file or a mapping.

    ``need_time=False`` accepts a spec without a ``time`` block (``time_column`` is then None):
    the joint conventions alone (``joints``, ``position``, ``couplings``), as a calibration
    reads them (:func:`robodyn.calibration.io.read_joint_map`).

    Raises
    ------
    RecordingError
        Unknown built-in, unreadable YAML, or an invalid field (named as ``spec: field.path``).
    """
    if isinstance(spec, Mapping):
        return _parse(dict(spec), "spec", need_time)
    text_name = str(spec)
    if text_name in builtin_specs():
        path = resources.files("robodyn.measure") / "specs" / f"{text_name}.yaml"
        name = text_name
        text = path.read_text(encoding="utf-8")
    else:
        p = Path(spec)
        if p.suffix.lower() not in (".yaml", ".yml"):
            raise RecordingError(f"spec: {text_name!r} is neither a built-in spec "
                                 f"({', '.join(builtin_specs())}) nor a .yaml/.yml file")
        if not p.is_file():
            raise RecordingError(f"{p}: spec file not found")
        name, text = p.name, p.read_text(encoding="utf-8")
    data = safe_yaml(text, name, RecordingError)
    if not isinstance(data, dict):
        raise RecordingError(f"{name}: a spec must be a mapping of fields, got {type(data).__name__}")
    return _parse(data, name, need_time)


# ----------------------------------------------------------------------------------------------
# validation helpers
# ----------------------------------------------------------------------------------------------


def _keys(data: Mapping[str, Any], allowed: tuple[str, ...], name: str, path: str) -> None:
    for key in data:
        if key not in allowed:
            where = f"{path}.{key}" if path else str(key)
            raise RecordingError(f"{name}: {where}: unknown key (expected one of {', '.join(allowed)})")


def _unit(value: Any, table: Mapping[str, Any], name: str, path: str) -> str:
    if not isinstance(value, str) or value not in table:
        raise RecordingError(f"{name}: {path}: unknown unit {value!r} (expected one of "
                             f"{', '.join(table)})")
    return str(value)


#: A number written in exponent form without a dot (``1e-3``): YAML 1.1 reads it as text.
_EXPONENT_NUMBER = re.compile(r"[-+]?[0-9]+[eE][-+]?[0-9]+")

#: Magnitudes a spec's per-joint numbers may take: beyond them a value is a typo or a unit
#: mistake, and it would turn every sample into nonsense (1e-300 rad per count, a 1e300 s period).
SPANS = {"gear_ratio": (1e-6, 1e6), "counts_per_rev": (1.0, 1e12), "torque_constant": (1e-6, 1e6),
         "gain": (1e-9, 1e9), "offset": (0.0, 1e6), "period": (1e-7, 3600.0)}


def spec_number(v: Any, name: str, path: str, span: tuple[float, float] | None = None) -> float:
    """A finite number of a spec (``1e-3`` accepted although YAML 1.1 reads it as text), with
    its magnitude in ``span`` when given, else :class:`RecordingError` naming ``path``."""
    if isinstance(v, str) and _EXPONENT_NUMBER.fullmatch(v.strip()):
        v = float(v)
    if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
        raise RecordingError(f"{name}: {path}: expected a finite number, got {v!r}")
    if span is not None and not (span[0] <= abs(v) <= span[1] or v == 0.0 and span[0] == 0.0):
        raise RecordingError(f"{name}: {path}: {v!r} is outside the plausible range "
                             f"{span[0]:g} .. {span[1]:g} in magnitude (a typo or a unit mistake?)")
    return float(v)


def _per_joint(value: Any, n: int, name: str, path: str, default: float,
               positive: bool = False, nonzero: bool = False) -> np.ndarray:
    if value is None:
        return np.full(n, float(default))
    items = value if isinstance(value, list) else [value] * n
    if len(items) != n:
        raise RecordingError(f"{name}: {path}: expected one number or a list of {n} (one per joint), "
                             f"got {len(items)}")
    out = np.empty(n)
    span = SPANS.get(path.rsplit(".", 1)[-1])
    for k, v in enumerate(items):
        v = spec_number(v, name, f"{path}[{k}]")
        if positive and v <= 0 or nonzero and v == 0:
            raise RecordingError(f"{name}: {path}[{k}]: must be {'positive' if positive else 'non-zero'}, "
                                 f"got {v!r}")
        spec_number(v, name, f"{path}[{k}]", span)
        out[k] = v
    return out


def _columns(value: Any, n: int, name: str, path: str) -> tuple[str | int, ...]:
    if isinstance(value, str):
        if "{k}" not in value:
            raise RecordingError(f"{name}: {path}: a column pattern must contain {{k}} (the joint "
                                 f"number 1..{n}), got {value!r}; or give a list of {n} columns")
        return tuple(value.replace("{k}", str(k + 1)) for k in range(n))
    if not isinstance(value, list) or len(value) != n:
        raise RecordingError(f"{name}: {path}: expected a list of {n} columns (names or 0-based "
                             f"indices) or a pattern such as 'Position{{k}}', got {value!r}")
    for k, c in enumerate(value):
        if isinstance(c, bool) or not (isinstance(c, str) and c or isinstance(c, int) and c >= 0):
            raise RecordingError(f"{name}: {path}[{k}]: expected a column name or a 0-based index, "
                                 f"got {c!r}")
    return tuple(value)


def _channel(field: str, data: Any, n: int, name: str) -> Channel:
    if not isinstance(data, dict):
        raise RecordingError(f"{name}: {field}: expected a mapping, got {data!r}")
    _keys(data, _ALLOWED[field], name, field)
    from_current = field == "torque" and "from" in data
    if "unit" not in data and not from_current:
        raise RecordingError(f"{name}: {field}.unit: missing (one of {', '.join(_UNITS[field])})")
    unit = _unit(data.get("unit", "N m"), _UNITS[field], name, f"{field}.unit")
    if from_current:
        if data["from"] != "current":
            raise RecordingError(f"{name}: torque.from: only 'current' is supported, got {data['from']!r}")
        if "columns" in data:
            raise RecordingError(f"{name}: torque: give either columns (a sensor) or from: current")
        columns = None
    elif "columns" not in data:
        raise RecordingError(f"{name}: {field}.columns: missing")
    else:
        columns = _columns(data["columns"], n, name, f"{field}.columns")
    counts = unit in ("counts", "counts/s")
    if counts and "counts_per_rev" not in data:
        raise RecordingError(f"{name}: {field}.counts_per_rev: needed for unit {unit!r}")
    if not counts and ("counts_per_rev" in data or "wrap_bits" in data):
        key = "counts_per_rev" if "counts_per_rev" in data else "wrap_bits"
        raise RecordingError(f"{name}: {field}.{key}: only meaningful with unit 'counts'")
    wrap = data.get("wrap_bits")
    if wrap is not None and (isinstance(wrap, bool) or not isinstance(wrap, int) or not 2 <= wrap <= 64):
        raise RecordingError(f"{name}: {field}.wrap_bits: expected an integer 2..64, got {wrap!r}")
    if unit == "V" and "gain" not in data:
        raise RecordingError(f"{name}: current.gain: needed for unit 'V' (transducer volts per "
                             "ampere, I = (V - offset) / gain)")
    if unit != "V" and "gain" in data:
        raise RecordingError(f"{name}: current.gain: only meaningful with unit 'V'")
    if from_current and "torque_constant" not in data:
        raise RecordingError(f"{name}: torque.torque_constant: needed with from: current (N m/A)")
    missing = data.get("missing", "error")
    if missing not in ("error", "zero"):
        raise RecordingError(f"{name}: {field}.missing: expected 'error' or 'zero', got {missing!r}")
    sign = _per_joint(data.get("sign"), n, name, f"{field}.sign", 1.0)
    if not np.all(np.abs(sign) == 1.0):
        raise RecordingError(f"{name}: {field}.sign: each sign must be 1 or -1, got {sign.tolist()}")
    return Channel(
        field=field, columns=columns, unit=unit, sign=sign,
        offset=_per_joint(data.get("offset"), n, name, f"{field}.offset", 0.0),
        gear_ratio=_per_joint(data.get("gear_ratio"), n, name, f"{field}.gear_ratio", 1.0,
                              nonzero=True),
        counts_per_rev=(_per_joint(data["counts_per_rev"], n, name, f"{field}.counts_per_rev", 1.0,
                                   positive=True) if counts else None),
        wrap_bits=wrap,
        gain=(_per_joint(data["gain"], n, name, "current.gain", 1.0, nonzero=True)
              if unit == "V" else None),
        torque_constant=(_per_joint(data["torque_constant"], n, name, "torque.torque_constant", 1.0,
                                    nonzero=True) if from_current else None),
        missing=missing)


def _parse(data: dict[str, Any], name: str, need_time: bool = True) -> RecordingSpec:
    _keys(data, _TOP, name, "")
    joints = data.get("joints")
    count = joints if isinstance(joints, int) and not isinstance(joints, bool) else \
        len(joints) if isinstance(joints, list) else 0
    if count > MAX_JOINTS:
        raise RecordingError(f"{name}: joints: {count} joints, more than {MAX_JOINTS}")
    if isinstance(joints, int) and not isinstance(joints, bool) and joints > 0:
        names = tuple(f"q{k + 1}" for k in range(joints))
    elif isinstance(joints, list) and joints and all(isinstance(j, str) and j for j in joints):
        names = tuple(joints)
        if len(set(names)) != len(names):
            raise RecordingError(f"{name}: joints: repeated names")
    else:
        raise RecordingError(f"{name}: joints: expected a joint count or a list of names, got {joints!r}")
    n = len(names)
    header = data.get("header", True)
    if not isinstance(header, bool):
        raise RecordingError(f"{name}: header: expected true or false, got {header!r}")
    delimiter = data.get("delimiter")
    if delimiter is not None and delimiter != "whitespace" and (not isinstance(delimiter, str)
                                                                 or len(delimiter) != 1):
        raise RecordingError(f"{name}: delimiter: expected one character or 'whitespace', got "
                             f"{delimiter!r}")
    comment = data.get("comment")
    if comment is not None and (not isinstance(comment, str) or len(comment) != 1):
        raise RecordingError(f"{name}: comment: expected one character, got {comment!r}")
    if data.get("time") is None and not need_time:
        tcol, tunit, period = None, "s", None  # joint conventions only: no time column
    else:
        tcol, tunit, period = _time(data.get("time"), name)
    channels = {f: _channel(f, data[f], n, name) for f in _ALLOWED if f in data}
    if "position" not in channels:
        raise RecordingError(f"{name}: position: missing (joint positions are required)")
    if period == "estimate" and "velocity" not in channels:
        raise RecordingError(f"{name}: time.period: 'estimate' needs a velocity block (the period is "
                             "regressed from position increments on measured velocity)")
    if "torque" in channels and channels["torque"].columns is None and "current" not in channels:
        raise RecordingError(f"{name}: torque.from: 'current' needs a current block")
    return RecordingSpec(name=name, joint_names=names, delimiter=delimiter, header=header,
                         comment=comment, time_column=tcol, time_unit=tunit, period=period,
                         channels=channels, couplings=_couplings(data.get("couplings"), names, name))


def _time(time: Any, name: str) -> tuple[str | int, str, float | str | None]:
    """The ``time`` block: column, unit and (for unit ``index``) the period or ``"estimate"``."""
    if not isinstance(time, dict):
        raise RecordingError(f"{name}: time: missing (a mapping with column and unit)")
    _keys(time, ("column", "unit", "period"), name, "time")
    if "column" not in time:
        raise RecordingError(f"{name}: time.column: missing")
    tcol = _columns([time["column"]], 1, name, "time.column")[0]
    tunit = _unit(time.get("unit"), TIME_UNITS, name, "time.unit")
    period = time.get("period")
    if tunit == "index":
        if period != "estimate" and period is not None:
            period = spec_number(period, name, "time.period")
        ok = period == "estimate" or (isinstance(period, float) and period > 0)
        if ok and period != "estimate":
            spec_number(period, name, "time.period", SPANS["period"])
        if not ok:
            raise RecordingError(f"{name}: time.period: with unit 'index' give the sample period in s "
                                 f"or 'estimate', got {period!r}")
    elif period is not None:
        raise RecordingError(f"{name}: time.period: only meaningful with unit 'index'")
    return tcol, tunit, period


def _couplings(data: Any, names: tuple[str, ...], name: str) -> tuple[Coupling, ...]:
    if data is None:
        return ()
    if not isinstance(data, list):
        raise RecordingError(f"{name}: couplings: expected a list of {{joint: NAME, add: {{NAME: factor}}}}")
    out = []
    for k, item in enumerate(data):
        path = f"couplings[{k}]"
        if not isinstance(item, dict):
            raise RecordingError(f"{name}: {path}: expected a mapping with joint and add")
        _keys(item, ("joint", "add"), name, path)
        if item.get("joint") not in names:
            raise RecordingError(f"{name}: {path}.joint: {item.get('joint')!r} is not one of the joints "
                                 f"({', '.join(names)})")
        add = item.get("add")
        if not isinstance(add, dict) or not add:
            raise RecordingError(f"{name}: {path}.add: expected a mapping {{joint name: factor}}")
        terms = []
        for other, factor in add.items():
            if other not in names:
                raise RecordingError(f"{name}: {path}.add.{other}: not one of the joints "
                                     f"({', '.join(names)})")
            if isinstance(factor, bool) or not isinstance(factor, int | float) or not math.isfinite(factor):
                raise RecordingError(f"{name}: {path}.add.{other}: expected a finite number, got {factor!r}")
            terms.append((names.index(other), float(factor)))
        out.append(Coupling(joint=names.index(item["joint"]), terms=tuple(terms)))
    return tuple(out)
