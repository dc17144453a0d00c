"""Joint-reading corrections a kinematic calibration found: compliance and transmission errors.

A calibrated description carries them so that, loaded alone, it predicts what the calibration
predicted. They map the joint readings ``q`` (what the encoders say) to the link angles the
geometry is evaluated at (:func:`robodyn.numeric.joint_corrections.link_positions`)::

    u_j = q_j + k_j q_j + a_j cos(q_j) + b_j sin(q_j) + a'_j cos(G_j q_j) + b'_j sin(G_j q_j)
    x   = u - C tau(q)          (deflection "linear": the holding torque at the readings)
    x   = u - C tau(x)          (deflection "exact": at the deflected pose, a fixed point)

with ``k`` the transmission ratio error, ``a, b`` the first harmonic of the joint angle, ``a', b'``
the motor's first harmonic seen at the link (``G`` the joint's drive gear ratio), ``C = diag(c)``
the joint compliances (rad/(N m), m/N) and ``tau`` the holding torque of point masses riding on a
*reference geometry* (:class:`HoldingTorque`): the kinematics the calibration evaluated the
torques on (the nominal robot), stored with the corrections so that the torques are the very ones
the calibration used, not those of the corrected geometry (they differ by the geometric
corrections times the compliances, second order).

In a YAML description::

    corrections:
      deflection: linear
      joints:
        joint2: {compliance: 2.1e-05}
        joint3: {ratio: 1.2e-04, cos1: 3.0e-05, sin1: -1.1e-05}
      holding_torque:
        source: gravity model
        gravity: [0.0, 0.0, -9.81]
        axes:                     # reference geometry at zero readings, one per joint
          - {point: [0, 0, 0], direction: [0, 0, 1], type: revolute}
        masses:                   # kg; first moment m p at zero readings, kg m; moved by joints 1..k
          - {mass: 3.1, moment: [0.0, 0.0, 1.2], moved_by: 1}

This module holds the data (immutable, validated); the evaluation is numeric and lives in
:mod:`robodyn.numeric.joint_corrections`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from robodyn.robot.errors import DescriptionError

__all__ = ["CORRECTION_KINDS", "DEFLECTIONS", "HoldingTorque", "JointCorrections",
           "corrections_from_plain"]

#: Per-joint correction coefficients, in the order of :attr:`JointCorrections.table`.
CORRECTION_KINDS = ("ratio", "cos1", "sin1", "motor_cos1", "motor_sin1", "compliance")
#: Where the holding torque of the compliance is evaluated.
DEFLECTIONS = ("linear", "exact")
_JOINT_TYPES = ("revolute", "prismatic")


@dataclass(frozen=True)
class HoldingTorque:
    """Static holding torques of point masses on a reference serial geometry.

    Joint ``j`` is a screw axis through ``axis_points[j]`` along ``axis_directions[j]`` at zero
    readings (world frame); point mass ``k`` rides on the link moved by joints ``1 .. moved_by[k]``
    and is given by its mass and first moment ``m p`` at zero readings. Then
    ``tau_j(q) = -gravity . (u_j x (S_j - M_j p_j))`` (revolute) or ``-M_j gravity . u_j``
    (prismatic), with ``S_j, M_j`` the first moments and masses moved by joint ``j``.

    Attributes
    ----------
    axis_points, axis_directions : tuple of (float, float, float), length n
        m; unit vectors.
    joint_types : tuple of str, length n
        ``"revolute"`` or ``"prismatic"``.
    masses : tuple of float, length K
        kg (a payload identified by its first moments may carry mass 0 and a moment).
    moments : tuple of (float, float, float), length K
        First moments ``m p`` at zero readings, kg m.
    moved_by : tuple of int, length K
        How many joints from the base move each mass (1 .. n).
    gravity : (float, float, float)
        m/s^2, in the frame of the axes.
    source : str
        What the masses are (``"gravity model"``, ``"gravity-shaped basis"``, ``" + payload"``).
    """

    axis_points: tuple[tuple[float, float, float], ...]
    axis_directions: tuple[tuple[float, float, float], ...]
    joint_types: tuple[str, ...]
    masses: tuple[float, ...]
    moments: tuple[tuple[float, float, float], ...]
    moved_by: tuple[int, ...]
    gravity: tuple[float, float, float]
    source: str = ""

    def __post_init__(self) -> None:
        n, k = len(self.joint_types), len(self.masses)
        where = "corrections.holding_torque"
        if len(self.axis_points) != n or len(self.axis_directions) != n:
            raise DescriptionError(f"{where}: {n} joint types but {len(self.axis_points)} axis points "
                                   f"and {len(self.axis_directions)} directions")
        if len(self.moments) != k or len(self.moved_by) != k:
            raise DescriptionError(f"{where}: {k} masses but {len(self.moments)} moments and "
                                   f"{len(self.moved_by)} moved_by entries")
        for j, t in enumerate(self.joint_types):
            if t not in _JOINT_TYPES:
                raise DescriptionError(f"{where}.axes[{j}].type: expected revolute or prismatic, got {t!r}")
        for name in ("axis_points", "axis_directions", "moments"):
            for i, v in enumerate(getattr(self, name)):
                _finite_vector(v, f"{where}.{name}[{i}]")
        for j, d in enumerate(self.axis_directions):
            if abs(math.hypot(*d) - 1.0) > 1e-9:
                raise DescriptionError(f"{where}.axes[{j}].direction: not a unit vector (norm "
                                       f"{math.hypot(*d):.12g})")
        for i, (m, b) in enumerate(zip(self.masses, self.moved_by, strict=True)):
            if not (isinstance(m, float | int) and math.isfinite(m) and m >= 0):
                raise DescriptionError(f"{where}.masses[{i}].mass: expected a finite number >= 0, got {m!r}")
            if isinstance(b, bool) or not isinstance(b, int) or not 1 <= b <= n:
                raise DescriptionError(f"{where}.masses[{i}].moved_by: expected a joint count 1..{n}, "
                                       f"got {b!r}")
        _finite_vector(self.gravity, f"{where}.gravity")

    def as_plain(self) -> dict[str, Any]:
        """The YAML block (plain data)."""
        return {
            "source": self.source,
            "gravity": list(self.gravity),
            "axes": [{"point": list(p), "direction": list(d), "type": t} for p, d, t in
                     zip(self.axis_points, self.axis_directions, self.joint_types, strict=True)],
            "masses": [{"mass": m, "moment": list(h), "moved_by": b} for m, h, b in
                       zip(self.masses, self.moments, self.moved_by, strict=True)],
        }


@dataclass(frozen=True)
class JointCorrections:
    """Joint-reading corrections of a calibrated robot (module docstring).

    Attributes
    ----------
    table : tuple of tuple of float, shape (n, 6)
        Per joint: ratio error (1), cos1, sin1, motor_cos1, motor_sin1 (rad) and compliance
        (rad/(N m) or m/N), in the order of :data:`CORRECTION_KINDS`. A compliance is an estimate
        and is kept as estimated (a slightly negative one says the joint's stiffness was not
        resolved).
    holding : HoldingTorque or None
        The compliance's holding torque; needed when a compliance is not zero.
    deflection : {"linear", "exact"}
    """

    table: tuple[tuple[float, ...], ...]
    holding: HoldingTorque | None = None
    deflection: str = "linear"

    def __post_init__(self) -> None:
        for j, row in enumerate(self.table):
            if len(row) != len(CORRECTION_KINDS):
                raise DescriptionError(f"corrections: joint {j + 1} has {len(row)} values, expected "
                                       f"{len(CORRECTION_KINDS)}")
            for kind, v in zip(CORRECTION_KINDS, row, strict=True):
                if not math.isfinite(v):
                    raise DescriptionError(f"corrections: joint {j + 1} {kind} is not finite ({v!r})")
        if self.deflection not in DEFLECTIONS:
            raise DescriptionError(f"corrections.deflection: expected one of {', '.join(DEFLECTIONS)}, "
                                   f"got {self.deflection!r}")
        if self.holding is not None and len(self.holding.joint_types) != len(self.table):
            raise DescriptionError(f"corrections.holding_torque: {len(self.holding.joint_types)} axes "
                                   f"for {len(self.table)} joints")
        if self.holding is None and any(row[-1] for row in self.table):
            raise DescriptionError("corrections: a joint has a compliance but there is no "
                                   "holding_torque block to say what loads it")

    @property
    def array(self) -> np.ndarray:
        """:attr:`table` as an array, shape (n, 6) (a fresh copy)."""
        return np.array(self.table, dtype=float).reshape(len(self.table), len(CORRECTION_KINDS))

    def as_plain(self, joint_names: Sequence[str]) -> dict[str, Any]:
        """The YAML block: only the non-zero coefficients of each joint."""
        joints = {}
        for name, row in zip(joint_names, self.table, strict=True):
            entry = {k: float(v) for k, v in zip(CORRECTION_KINDS, row, strict=True) if v != 0.0}
            if entry:
                joints[name] = entry
        out: dict[str, Any] = {"deflection": self.deflection, "joints": joints}
        if self.holding is not None:
            out["holding_torque"] = self.holding.as_plain()
        return out


def _finite_vector(v: Any, where: str) -> None:
    if len(v) != 3 or not all(isinstance(x, float | int) and not isinstance(x, bool) and math.isfinite(x)
                              for x in v):
        raise DescriptionError(f"{where}: expected 3 finite numbers, got {list(v)!r}")


def _mapping(value: Any, where: str, keys: Sequence[str], required: Sequence[str]) -> Mapping:
    if not isinstance(value, Mapping):
        raise DescriptionError(f"{where}: expected a mapping, got {type(value).__name__}")
    unknown = [k for k in value if k not in keys]
    if unknown:
        raise DescriptionError(f"{where}.{unknown[0]}: unknown key; expected {', '.join(keys)}")
    missing = [k for k in required if k not in value]
    if missing:
        raise DescriptionError(f"{where}: missing key {missing[0]!r}")
    return value


def _number(v: Any, where: str) -> float:
    if isinstance(v, bool) or not isinstance(v, float | int) or not math.isfinite(v):
        raise DescriptionError(f"{where}: expected a finite number, got {v!r}")
    return float(v)


def _vector(v: Any, where: str) -> tuple[float, float, float]:
    if not isinstance(v, list | tuple) or len(v) != 3:
        raise DescriptionError(f"{where}: expected a list of 3 numbers, got {v!r}")
    return tuple(_number(x, f"{where}[{i}]") for i, x in enumerate(v))  # type: ignore[return-value]


def _holding_from_plain(value: Any, where: str) -> HoldingTorque:
    block = _mapping(value, where, ("source", "gravity", "axes", "masses"), ("gravity", "axes", "masses"))
    axes, masses = block["axes"], block["masses"]
    for key, items in (("axes", axes), ("masses", masses)):
        if not isinstance(items, list):
            raise DescriptionError(f"{where}.{key}: expected a list, got {type(items).__name__}")
    pts, dirs, types = [], [], []
    for j, a in enumerate(axes):
        a = _mapping(a, f"{where}.axes[{j}]", ("point", "direction", "type"), ("point", "direction", "type"))
        pts.append(_vector(a["point"], f"{where}.axes[{j}].point"))
        dirs.append(_vector(a["direction"], f"{where}.axes[{j}].direction"))
        types.append(a["type"] if isinstance(a["type"], str) else repr(a["type"]))
    ms, hs, bs = [], [], []
    for k, m in enumerate(masses):
        keys = ("mass", "moment", "moved_by")
        m = _mapping(m, f"{where}.masses[{k}]", keys, keys)
        ms.append(_number(m["mass"], f"{where}.masses[{k}].mass"))
        hs.append(_vector(m["moment"], f"{where}.masses[{k}].moment"))
        bs.append(m["moved_by"])
    source = block.get("source", "")
    if not isinstance(source, str):
        raise DescriptionError(f"{where}.source: expected a text, got {source!r}")
    return HoldingTorque(tuple(pts), tuple(dirs), tuple(types), tuple(ms), tuple(hs), tuple(bs),
                         _vector(block["gravity"], f"{where}.gravity"), source)


def corrections_from_plain(value: Any, joint_names: Sequence[str], source: str) -> JointCorrections:
    """The ``corrections`` block of a YAML description (module docstring), checked.

    Raises
    ------
    DescriptionError
        Naming ``source`` and the field: an unknown joint or key, a value that is not a finite
        number, a negative mass, a compliance without a holding torque.
    """
    where = f"{source}: corrections"
    block = _mapping(value, where, ("deflection", "joints", "holding_torque"), ("joints",))
    joints = block["joints"]
    if not isinstance(joints, Mapping):
        raise DescriptionError(f"{where}.joints: expected a mapping joint name: coefficients")
    table = [[0.0] * len(CORRECTION_KINDS) for _ in joint_names]
    for name, entry in joints.items():
        if name not in joint_names:
            raise DescriptionError(f"{where}.joints.{name}: no such joint; the joints are "
                                   f"{', '.join(joint_names)}")
        entry = _mapping(entry, f"{where}.joints.{name}", CORRECTION_KINDS, ())
        j = list(joint_names).index(name)
        for kind, v in entry.items():
            table[j][CORRECTION_KINDS.index(kind)] = _number(v, f"{where}.joints.{name}.{kind}")
    deflection = block.get("deflection", "linear")
    try:
        holding = None
        if "holding_torque" in block:
            holding = _holding_from_plain(block["holding_torque"], "corrections.holding_torque")
        return JointCorrections(tuple(tuple(r) for r in table), holding,
                                deflection if isinstance(deflection, str) else repr(deflection))
    except DescriptionError as e:
        raise DescriptionError(f"{source}: {e}") from None
