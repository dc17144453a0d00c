"""Input checks of ``rd.identify``: the recordings, the options and the payloads (step 1).

Every problem is an :class:`~robodyn.robot.errors.IdentificationError` naming the recording (its
``source``, or ``recordings[i]``), the field and the reason.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from typing import Any

import numpy as np

from robodyn.identification.payload import Payload
from robodyn.measure.angles import wrap_steps
from robodyn.robot.errors import IdentificationError, RecordingWarning
from robodyn.robot.model import Robot

__all__ = ["TARGETS", "check_payloads", "check_recording", "checked_inputs"]

TARGETS = ("tau", "current")


def _src(rec: Any, index: int) -> str:
    return str(getattr(rec, "source", "") or f"recordings[{index}]")


def _first_bad(a: np.ndarray) -> tuple[int, int]:
    rows, cols = np.nonzero(~np.isfinite(a))
    return int(rows[0]), int(cols[0])


def check_recording(robot: Robot, rec: Any, index: int, target: str | None,
                    unobserved: bool = False) -> None:
    """Raise :class:`IdentificationError` when ``rec`` cannot be used with ``robot``.

    Checks: joint names equal the robot's (same order), ``q`` (N, n), finite ``t``/``q``/target
    (the first bad row and column named), and the target signal present. ``unobserved``: a
    target column that is not finite in any row (a joint without a sensor, as
    :class:`~robodyn.measure.recording.Recording` marks it) is allowed, unless every column is.
    """
    src = _src(rec, index)
    names = getattr(rec, "joint_names", None)
    n = robot.dof
    q = np.asarray(rec.q, dtype=float)
    if q.ndim != 2 or q.shape[1] != n:
        raise IdentificationError(f"{src}: q: expected shape (N, {n}) for robot {robot.name!r} "
                                  f"({n} joints), got {q.shape}")
    if names is not None and tuple(names) != tuple(f"q{j + 1}" for j in range(n)) \
            and tuple(names) != robot.joint_names:
        missing = [j for j in robot.joint_names if j not in names]
        extra = [j for j in names if j not in robot.joint_names]
        why = (f"missing {missing}, unknown {extra}" if missing or extra
               else f"order {list(names)} is not the chain order {list(robot.joint_names)}")
        raise IdentificationError(f"{src}: joint_names do not match robot {robot.name!r}: {why} "
                                  f"(use rec.select(robot.joint_names))")
    fields = [("t", np.asarray(rec.t, dtype=float).reshape(-1, 1)), ("q", q)]
    if target is not None:
        y = getattr(rec, target, None)
        if y is None:
            raise IdentificationError(f"{src}: {target}: the recording has no {target!r} signal to "
                                      f"fit (target={target!r})")
        y = np.asarray(y, dtype=float)
        if y.shape != q.shape:
            raise IdentificationError(f"{src}: {target}: shape {y.shape} differs from q {q.shape}")
        empty = ~np.isfinite(y).any(axis=0) if unobserved and y.size else np.zeros(n, bool)
        if empty.all():
            raise IdentificationError(f"{src}: {target}: no joint has a finite value (no sensor "
                                      f"data to fit)")
        fields.append((target, y[:, ~empty]))
    for name, a in fields:
        if not np.all(np.isfinite(a)):
            row, col = _first_bad(a)
            value = a[row, col]
            if name == target:  # the column among the joints with data
                col = int(np.flatnonzero(~empty)[col])
            column = "" if name == "t" else f", column {col} ({robot.joint_names[col]})"
            raise IdentificationError(f"{src}: {name}: value {value} is not finite at row "
                                      f"{row}{column}")
    check_within_limits(robot, q, src)


def check_within_limits(robot: Robot, q: np.ndarray, src: str) -> None:
    """Refuse positions a whole turn (2 pi) or more beyond a revolute joint's limits: no reading
    of that joint in radians can be there, while degrees read as radians are (a joint at 60 deg
    reads 60 "rad"), and so can be a recording of another robot or in another joint order.
    (Trajectories that merely leave the limits, as simulated ones may, are left alone.)"""
    subs = robot.defaults()
    for j, joint in enumerate(robot.joints):
        if joint.type != "revolute" or joint.lower is None or joint.upper is None:
            continue
        lo, hi = float(joint.lower.xreplace(subs)), float(joint.upper.xreplace(subs))
        if not (np.isfinite(lo) and np.isfinite(hi)) or hi <= lo:
            continue
        beyond = np.maximum(lo - q[:, j], q[:, j] - hi)
        k = int(np.argmax(beyond))
        if beyond[k] > 2 * np.pi:
            raise IdentificationError(
                f"{src}: q: joint {joint.name} reaches {q[k, j]:.4g} rad at row {k}, "
                f"{beyond[k]:.3g} rad beyond its limits [{lo:.4g}, {hi:.4g}] in {robot.name!r}: "
                "positions in degrees? (a recording spec declares position: {unit: deg}); or a "
                "recording of another robot or joint order")


def checked_inputs(robot: Robot, recordings: Any, target: str | None, sensor: str,
                   payloads: Sequence[Payload | None] | None
                   ) -> tuple[list[Any], str, list[Payload | None]]:
    """The recordings as a list, the resolved target and one payload per recording (step 1;
    the options are checked by :class:`~robodyn.identification.options.IdentifyOptions`).

    Raises :class:`IdentificationError` on no recordings, an unknown target, a link-side
    ``sensor`` without torques, a recording that does not fit ``robot``
    (:func:`check_recording`) or malformed payloads.
    """
    recs = [recordings] if hasattr(recordings, "q") else list(recordings)
    if not recs:
        raise IdentificationError("recordings: none given")
    if target is None:
        target = "tau" if all(getattr(r, "tau", None) is not None for r in recs) else "current"
    if target not in TARGETS:
        raise IdentificationError(f"target: expected one of {TARGETS}, got {target!r}")
    if sensor == "link" and target != "tau":
        raise IdentificationError("sensor: 'link' (a joint torque sensor after the gear) needs "
                                  f"target='tau', got target={target!r}")
    for i, rec in enumerate(recs):
        check_recording(robot, rec, i, target, unobserved=True)
        _note_wraps(robot, rec, i)
    return recs, target, check_payloads(payloads, len(recs))


def _note_wraps(robot: Robot, rec: Any, index: int) -> None:
    """A warning naming the joints of ``rec`` whose angle is logged modulo a turn (the wrap
    steps are undone before filtering, :mod:`robodyn.measure.angles`; the fit is unaffected)."""
    counts = wrap_steps(rec.q)
    if counts.any():
        joints = ", ".join(f"{robot.joint_names[j]} ({int(c)})" for j, c in enumerate(counts) if c)
        warnings.warn(f"{_src(rec, index)}: q: angle logged modulo a turn on {joints} (steps of a "
                      "whole turn undone before filtering and differentiating; the recording is "
                      "unchanged)", RecordingWarning, stacklevel=4)


def check_payloads(payloads: Any, count: int) -> list[Payload | None]:
    """One ``Payload`` or None per recording (an error naming the entry otherwise)."""
    if payloads is None:
        return [None] * count
    if isinstance(payloads, Payload):
        raise IdentificationError("payloads: expected a sequence with one Payload or None per "
                                  "recording, got a single Payload")
    pays = list(payloads)
    if len(pays) != count:
        raise IdentificationError(f"payloads: expected one per recording ({count}), got {len(pays)}")
    for i, p in enumerate(pays):
        if p is not None and not isinstance(p, Payload):
            raise IdentificationError(f"payloads[{i}]: expected a Payload or None, got "
                                      f"{type(p).__name__}")
    return pays
