"""Held-out figures: relative error against the raw and the filtered target, beside the noise floor.

One reference filter for every "against filtered" figure and every noise floor robodyn reports
(``rd.validate``, ``robodyn identify``/``validate``, the Kinova tests and benchmarks): a
zero-phase Butterworth low-pass of order 4 per pass, run forward and backward
(:func:`robodyn.measure.filtering.lowpass`), at ``REFERENCE_CUTOFF_HZ`` = 2.5 Hz (at most 0.4 x
the sampling rate).

Why 2.5 Hz: the Kinova data README (``../shared/data/kinova-gen3/README.md``) quotes its baseline
against "zero-phase-filtered current" with a noise floor (raw minus filtered current) of "about
0.26" on the last 30 % of the whole-arm runs, and does not state the cut-off. On those samples
this filter's noise floor is 0.264 at 2 Hz, 0.261 at 2.5 Hz, 0.258 at 3 Hz, 0.249 at 5 Hz and
0.224 at 10 Hz, so 2.5 Hz is the cut-off that reproduces the README's floor. (The identified
model's error against the filtered current moves little with it: 0.204-0.209 between 2 and
6 Hz, 0.229 at 10 Hz.) Manipulator motion lives below a few hertz; a faster arm should pass its
own ``noise_cutoff``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from robodyn.measure.filtering import lowpass

__all__ = ["REFERENCE_CUTOFF_HZ", "HeldOutError", "format_held_out", "held_out_error",
           "held_out_from_validation", "moving_joints", "reference_filter"]

#: Cut-off of the reference low-pass (Hz): see the module docstring.
REFERENCE_CUTOFF_HZ = 2.5
#: Butterworth order of one pass of the reference low-pass.
REFERENCE_ORDER = 4
#: A joint whose position spans less than this (rad or m) is held in a jointwise run.
HELD_SPAN = 0.05


def reference_filter(t: np.ndarray, y: np.ndarray, cutoff: float = REFERENCE_CUTOFF_HZ) -> np.ndarray:
    """The reference zero-phase low-pass of a measured target.

    Parameters
    ----------
    t : (N,) array_like
        Sample times, s.
    y : (N, n) array_like
        Measured target (N m or A).
    cutoff : float
        Hz; limited to 0.4 x the (median) sampling rate.

    Returns
    -------
    (N, n) ndarray
        Filtered target, same unit.
    """
    t = np.asarray(t, dtype=float)
    cut = min(float(cutoff), 0.4 / float(np.median(np.diff(t))))
    return lowpass(t, np.asarray(y, dtype=float), cut, order=REFERENCE_ORDER)


def moving_joints(q: np.ndarray, span: float = HELD_SPAN) -> np.ndarray:
    """Indices of the joints whose position ``q`` (N, n) spans more than ``span`` (rad or m)."""
    return np.flatnonzero(np.ptp(np.asarray(q, dtype=float), axis=0) > span)


@dataclass(frozen=True)
class HeldOutError:
    """Relative errors of a prediction on one recording (or several, pooled).

    Attributes
    ----------
    source : str
        The recording(s).
    joints : tuple of str
        The joints the figures pool (all, or a jointwise run's moving joint).
    raw : float
        ``||p - y|| / ||y||`` against the measured target.
    filtered : float
        ``||p - y_f|| / ||y_f||`` against the reference-filtered target ``y_f``.
    noise_floor : float
        ``||y - y_f|| / ||y||``: the raw error a perfect model of ``y_f`` would still show.
    samples : int
    cutoff : float
        The reference filter's cut-off, Hz.
    """

    source: str
    joints: tuple[str, ...]
    raw: float
    filtered: float
    noise_floor: float
    samples: int
    cutoff: float

    def row(self) -> list[str]:
        """``[source, joints, raw, filtered, noise floor, samples]`` formatted."""
        return [self.source, ",".join(self.joints), f"{self.raw:.3f}", f"{self.filtered:.3f}",
                f"{self.noise_floor:.3f}", str(self.samples)]


def held_out_error(t: Sequence[np.ndarray] | np.ndarray, measured: Sequence[np.ndarray] | np.ndarray,
                   predicted: Sequence[np.ndarray] | np.ndarray, joint_names: Sequence[str],
                   joints: Sequence[int] | None = None, source: str = "",
                   cutoff: float = REFERENCE_CUTOFF_HZ) -> HeldOutError:
    """Relative errors of ``predicted`` against ``measured``, raw and reference-filtered.

    Parameters
    ----------
    t : (N,) array_like or sequence of them
        Sample times of each recording, s (each recording is filtered on its own).
    measured, predicted : (N, n) array_like or sequences of them
        Measured and predicted target per recording (same unit).
    joint_names : sequence of str, length n
    joints : sequence of int, optional
        Columns pooled (default: all).
    source : str
    cutoff : float
        Reference filter cut-off, Hz.

    Returns
    -------
    HeldOutError
    """
    if isinstance(t, np.ndarray) and t.ndim == 1:
        t, measured, predicted = [t], [measured], [predicted]
    cols = list(range(len(joint_names))) if joints is None else list(joints)
    e2 = y2 = ef2 = yf2 = n2 = 0.0
    count = 0
    for ti, yi, pi in zip(t, measured, predicted, strict=True):
        y = np.asarray(yi, dtype=float)
        y_f = reference_filter(ti, y[:, cols], cutoff)  # the pooled columns only: a joint
        # without a sensor (an all-NaN column) is left out, not filtered
        y, p = y[:, cols], np.asarray(pi, dtype=float)[:, cols]
        # squared norms of p - y, y, p - y_f, y_f, y - y_f, pooled over recordings
        e2 += float(np.sum((p - y) ** 2))
        y2 += float(np.sum(y**2))
        ef2 += float(np.sum((p - y_f) ** 2))
        yf2 += float(np.sum(y_f**2))
        n2 += float(np.sum((y - y_f) ** 2))
        count += y.shape[0]
    return HeldOutError(source=source, joints=tuple(joint_names[c] for c in cols),
                        raw=float(np.sqrt(e2 / y2)), filtered=float(np.sqrt(ef2 / yf2)),
                        noise_floor=float(np.sqrt(n2 / y2)), samples=count, cutoff=float(cutoff))


def format_held_out(rows: Sequence[tuple[str, HeldOutError]]) -> str:
    """A fixed-width text table of ``(label, HeldOutError)`` rows."""
    head = ["case", "recording", "joints", "raw", "filtered", "noise floor", "samples"]
    body = [[label, *e.row()] for label, e in rows]
    width = [max(len(str(r[i])) for r in [head, *body]) for i in range(len(head))]
    cut = rows[0][1].cutoff if rows else REFERENCE_CUTOFF_HZ
    lines = ["  ".join(f"{c:<{w}}" for c, w in zip(head, width, strict=True))]
    lines += ["  ".join(f"{c:<{w}}" for c, w in zip(r, width, strict=True)) for r in body]
    lines.append(f"relative errors ||e|| / ||y||; filtered: zero-phase Butterworth (order 4 per pass) "
                 f"at {cut:g} Hz; noise floor ||y - y_f|| / ||y||")
    return "\n".join(lines)


def held_out_from_validation(val: object, label: str = "") -> tuple[str, HeldOutError]:
    """The held-out row of a :class:`robodyn.validation.Validation`: all joints with a
    measurement, or, when exactly one joint moves (a jointwise run), that joint alone.

    The filtered figure and the noise floor use the validation's own ``noise.cutoff`` (the
    reference cut-off unless ``noise_cutoff`` was passed to ``rd.validate``)."""
    names = tuple(val.joint_names)  # type: ignore[attr-defined]
    moving = np.flatnonzero(val.moving)  # type: ignore[attr-defined]
    has = ~np.all(np.isnan(val.measured), axis=0)  # type: ignore[attr-defined]
    cols = [int(moving[0])] if moving.size == 1 and len(names) > 1 else list(np.flatnonzero(has))
    err = held_out_error(val.t, val.measured, val.predicted, names, cols,  # type: ignore[attr-defined]
                         source=val.source, cutoff=val.noise.cutoff)  # type: ignore[attr-defined]
    return label, err
