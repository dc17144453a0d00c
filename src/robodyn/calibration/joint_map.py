"""Controller columns to model joints: one linear map, read from a recording spec or a short form.

A calibration file holds what the controller logged, which need not be the model's joints: a
sign flip, a zero offset, a parallelogram joint measured against its neighbour, encoder counts.
:class:`JointMap` is that correspondence as one affine map per pose,
``q = W c + b`` (``c`` the listed columns of a row), and :func:`read_joint_map` reads it from
either of two spellings of the same conventions:

* **a recording spec** (``docs/recording-spec.md``): the same YAML file, or built-in name, that
  reads the arm's logs with ``rd.read_recording``. Its ``joints``, ``position`` (``columns``,
  ``unit``, ``sign``, ``offset``, ``gear_ratio``, ``counts_per_rev``) and ``couplings`` apply
  exactly as they do to a recording, through :func:`robodyn.measure.spec.load_spec`: the same
  parser and the same checks; the ``time`` block and the other signals may be there and are not
  used. The joints then come out in rad (m): the spec's ``position.unit`` says the file's unit,
  so the calibration's own ``angle_unit`` must stay ``"rad"``.
* **the short form**, one entry per model joint that is not read from its own column, in the
  file's units::

      q1: J1
      q3: {column: J3, sign: -1, offset: 10.0, coupling: {J2: 1.0}}   # q3 = -J3 + 10 + J2

A file whose top level has ``position`` (or ``joints``) is a recording spec; any other mapping is
the short form.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from robodyn.robot.errors import DataFileError
from robodyn.robot.numbers import RobotNumbers

if TYPE_CHECKING:
    from robodyn.robot.model import Robot

__all__ = ["JointMap", "identity_map", "read_joint_map"]

#: Top-level keys that make a joint-mapping file a recording spec.
SPEC_KEYS = ("position", "joints")


@dataclass(frozen=True, eq=False)
class JointMap:
    """Model joints from a row's columns: ``q = weights @ c + offset``.

    Attributes
    ----------
    columns : tuple of str
        The file columns ``c`` that enter (c,).
    weights : numpy.ndarray, shape (n, c)
        Row ``j``: how model joint ``j`` is made from the columns (sign, unit, couplings).
    offset : numpy.ndarray, shape (n,)
        Added last, in the unit of the result.
    si : bool
        True: the result is in rad (m), the spec's unit applied (a recording spec); False: in the
        file's own unit, converted later by the calibration's ``angle_unit`` (the short form).
    source : str
        The spec's file name (or ``"<mapping>"``) for error messages.
    """

    columns: tuple[str, ...]
    weights: np.ndarray
    offset: np.ndarray
    si: bool = False
    source: str = "<mapping>"

    def apply(self, table: Mapping[str, Any]) -> np.ndarray:
        """Joint values (N, n) of a table of columns (each (N,))."""
        c = np.column_stack([np.asarray(table[name], dtype=float) for name in self.columns])
        return c @ self.weights.T + self.offset  # q = W c + b


def identity_map(robot: Robot | RobotNumbers) -> JointMap:
    """Each model joint read from the column of its own name."""
    return JointMap(tuple(robot.joint_names), np.eye(robot.dof), np.zeros(robot.dof))


def read_joint_map(spec: Any, robot: Robot | RobotNumbers) -> JointMap:
    """Read a joint mapping (a recording spec or the short form; module notes) for ``robot``.

    Parameters
    ----------
    spec : mapping, str or Path
        A mapping, a YAML file, or the name of a built-in recording spec.
    robot : Robot or RobotNumbers

    Returns
    -------
    JointMap

    Raises
    ------
    DataFileError
        The short form: a joint the robot does not have, an unknown key, a sign other than +-1, a
        non-numeric offset or coupling factor. A recording spec: joints other than the robot's,
        columns given by index, a counter with ``wrap_bits`` (separate poses cannot be
        unwrapped). The message names the spec and the joint or field.
    RecordingError
        A recording spec that its own checks refuse (named as ``spec: field.path``).
    """
    source = "<mapping>"
    if isinstance(spec, (str, Path)):
        if not Path(spec).exists():
            # the recording readers (and their SciPy) load only when a spec is used
            from robodyn.measure.spec import builtin_specs

            if str(spec) in builtin_specs():
                return _from_spec(str(spec), str(spec), robot)
        from robodyn.robot.safe_yaml import safe_yaml

        source = str(spec)
        try:
            text = Path(spec).read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            raise DataFileError(f"{source}: cannot read the joint mapping: {exc}") from None
        data = safe_yaml(text, source, DataFileError)
        if isinstance(data, dict) and any(k in data for k in SPEC_KEYS):
            return _from_spec(Path(spec), source, robot)
        spec = data
    if isinstance(spec, Mapping) and any(k in spec for k in SPEC_KEYS):
        return _from_spec(dict(spec), source, robot)
    return _short_form(spec, source, robot)


def _from_spec(spec: Any, source: str, robot: Robot | RobotNumbers) -> JointMap:
    """The recording spec's position conversion and couplings as ``q = W c + b`` in rad (m)."""
    from robodyn.measure.spec import POSITION_UNITS, load_spec

    rs = load_spec(spec, need_time=False)
    if sorted(rs.joint_names) != sorted(robot.joint_names):
        raise DataFileError(f"{source}: joints: the spec names {', '.join(rs.joint_names)}; "
                            f"{robot.name} has {', '.join(robot.joint_names)}")
    ch = rs.channels["position"]
    if not all(isinstance(c, str) for c in ch.columns):
        raise DataFileError(f"{source}: position.columns: a calibration file has a header; give "
                            "column names, not indices")
    if ch.wrap_bits is not None:
        raise DataFileError(f"{source}: position.wrap_bits: a counter that wraps cannot be "
                            "unwrapped over separate poses; give the counts unwrapped")
    if ch.unit == "counts":
        scale = 2.0 * math.pi / (ch.counts_per_rev * ch.gear_ratio)  # counts -> rad
    else:
        scale = POSITION_UNITS[ch.unit] / ch.gear_ratio
    coupling = rs.coupling_matrix()
    # q_measured = sign * scale * c + offset, then q = C q_measured (as a recording reads them)
    weights = coupling @ np.diag(ch.sign * scale)
    offset = coupling @ ch.offset
    order = [rs.joint_names.index(j) for j in robot.joint_names]
    return JointMap(tuple(ch.columns), weights[order], offset[order], si=True, source=source)


def _short_form(spec: Any, source: str, robot: Robot | RobotNumbers) -> JointMap:
    """``{joint: column or {column, sign, offset, coupling}}`` as ``q = W c + b`` (file units)."""
    if not isinstance(spec, Mapping):
        raise DataFileError(f"{source}: a joint mapping is a recording spec (position, couplings) "
                            "or a mapping of model joint -> {column, sign, offset, coupling}")
    rows = {j: (j, 1.0, 0.0, {}) for j in robot.joint_names}
    for joint, item in spec.items():
        if joint not in robot.joint_names:
            raise DataFileError(f"{source}: joint mapping names joint {joint!r}, which {robot.name} "
                                f"does not have (its joints: {', '.join(robot.joint_names)})")
        item = {"column": item} if isinstance(item, str) else item
        if not isinstance(item, dict):
            raise DataFileError(f"{source}: joint {joint!r}: expected a column name or a mapping")
        unknown = set(item) - {"column", "sign", "offset", "coupling"}
        if unknown:
            raise DataFileError(f"{source}: joint {joint!r}: unknown key(s) {', '.join(sorted(unknown))} "
                                "(allowed: column, sign, offset, coupling)")
        sign, offset = item.get("sign", 1), item.get("offset", 0.0)
        coupling = item.get("coupling", {}) or {}
        if sign not in (1, -1):
            raise DataFileError(f"{source}: joint {joint!r}, field 'sign': {sign!r} is not 1 or -1")
        numbers = [("offset", offset)] + [(f"coupling.{k}", v) for k, v in dict(coupling).items()]
        for field_name, v in numbers:
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                raise DataFileError(f"{source}: joint {joint!r}, field {field_name!r}: {v!r} is not a "
                                    "finite number")
        rows[joint] = (str(item.get("column", joint)), float(sign), float(offset),
                       {str(k): float(v) for k, v in coupling.items()})
    columns = list(dict.fromkeys(c for col, _, _, cp in rows.values() for c in (col, *cp)))
    weights = np.zeros((robot.dof, len(columns)))
    for j, (col, sign, _, coupling) in enumerate(rows.values()):
        # q_j = sign * column + offset + sum(factor * other column)
        weights[j, columns.index(col)] += sign
        for other, factor in coupling.items():
            weights[j, columns.index(other)] += factor
    offset = np.array([row[2] for row in rows.values()])
    return JointMap(tuple(columns), weights, offset, si=False, source=source)
