"""``Recording``: one measured run of a robot arm as validated, read-only time series.

A recording holds joint signals on one time base ``t`` (N,) and, optionally, a tracker's tool
positions on a time base of their own. It is checked on construction (shapes, strictly
increasing time, NaN/inf named by field, row and column); gaps in the time stamps (steps over
1.5 x the median period) are reported in :attr:`Recording.gaps` and by a
:class:`~robodyn.robot.errors.RecordingWarning`, never filled in. Velocities and accelerations
that were not measured are estimated from the positions by
:func:`robodyn.measure.filtering.differentiate` and named in :attr:`Recording.estimated`.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from types import MappingProxyType

import numpy as np
from scipy.interpolate import make_interp_spline

from robodyn.measure.angles import unwrap_turns
from robodyn.measure.filtering import differentiate, lowpass
from robodyn.robot.errors import RecordingError, RecordingWarning

__all__ = ["JOINT_FIELDS", "Recording", "check_plausible"]

JOINT_FIELDS = ("q", "qd", "qdd", "tau", "current", "temperature")
# fields whose columns may be entirely NaN: "this joint has no such sensor"
_MAY_LACK_COLUMNS = ("tau", "current", "temperature")
DEFAULT_UNITS = {"t": "s", "q": "rad", "qd": "rad/s", "qdd": "rad/s^2", "tau": "N m",
                 "current": "A", "temperature": "degC", "tool_t": "s", "tool_points": "m"}
_GAP_FACTOR = 1.5


def _readonly(a: np.ndarray) -> np.ndarray:
    a = np.array(a, dtype=float, copy=True)
    a.flags.writeable = False
    return a


#: Largest joint position a recording may hold, rad or m (10^6 rad is 160,000 turns).
MAX_POSITION = 1e6

#: Median sample period (s) above which a recording's stamps are probably not seconds (a joint
#: logger samples at 10 Hz or faster; 10 ms stamps read as seconds give a period of 10 s):
#: a warning, not an error (a slow log of a slow motion is possible).
SLOW_PERIOD = 1.0

#: Per field: the largest magnitude a recording may hold and what the field is. Far beyond any
#: arm (10^5 rad/s is a million rpm at the joint; 10^8 N m, 10^6 A): one corrupt cell would
#: otherwise set every scale of the run (a filter's overflow, a duration of 1e304 s).
PLAUSIBLE = {"q": (MAX_POSITION, "joint position (rad or m)"),
             "qd": (1e5, "joint velocity (rad/s or m/s)"),
             "qdd": (1e9, "joint acceleration (rad/s^2 or m/s^2)"),
             "tau": (1e8, "joint torque (N m or N)"),
             "current": (1e6, "motor current (A)"),
             "temperature": (1e4, "temperature (deg C)")}


def check_plausible(where: str, name: str, a: np.ndarray, names: Sequence[str],
                    lines: np.ndarray | None = None) -> None:
    """Refuse a value of field ``name`` (``a``, (N, n)) beyond its :data:`PLAUSIBLE` bound: one
    corrupt cell would set every scale (a duration of 1e304 s, a filter at 1e-302 Hz).

    Parameters
    ----------
    where : str
        The message's start (file and field).
    name : str
        A key of :data:`PLAUSIBLE`.
    a : (N, n) ndarray
    names : sequence of str
        The joint names of the columns.
    lines : (N,) ndarray, optional
        The 1-based file line of each row: the message names ``line L`` of the file instead of
        the 0-based ``row``.

    Raises
    ------
    RecordingError
    """
    bound, what = PLAUSIBLE[name]
    big = np.abs(a) > bound
    if not big.any():
        return
    row, col = (int(v) for v in np.argwhere(big)[0])
    at = f"row {row}" if lines is None else f"line {int(lines[row])}"
    raise RecordingError(f"{where}: {a[row, col]:g} at {at}, column {col} ({names[col]!r}) is not a "
                         f"plausible {what} (|value| > {bound:g}); check the unit and that "
                         f"{at.split()[0]} of the file ({int(big.sum())} such value(s) in all)")


@dataclass(frozen=True, eq=False)
class Recording:
    """A measured run: joint signals on one time base, tracker points on another.

    Parameters
    ----------
    t : (N,) array_like
        Sample times, s, strictly increasing.
    q : (N, n) array_like
        Joint positions, rad (m for prismatic joints).
    qd, qdd : (N, n) array_like, optional
        Joint velocities (rad/s) and accelerations (rad/s^2); estimated from ``q`` when None
        (zero-phase Butterworth low-pass at the bandwidth cut-off, then central differences).
    tau : (N, n) array_like, optional
        Joint torques, N m. A column entirely NaN means that joint has no sensor.
    current : (N, n) array_like, optional
        Motor currents, A (entirely-NaN columns as for ``tau``).
    temperature : (N, n) array_like, optional
        Drive temperatures, deg C (entirely-NaN columns as for ``tau``).
    joint_names : sequence of str, optional
        n distinct names; ``"q1" .. "qn"`` when None.
    tool_t : (M,) array_like, optional
        Tracker time stamps, s, on the same clock as ``t`` (strictly increasing).
    tool_points : (M, 3) array_like, optional
        Tracker XYZ, m.
    units : mapping, optional
        Unit of each field (defaults: SI, rad, deg C); merged over the defaults.
    source : str
        Where the data came from (file name), used in messages.
    estimated : frozenset of str
        Fields estimated rather than measured; the constructor adds those it estimates.

    Raises
    ------
    RecordingError
        Wrong shapes, time not strictly increasing, NaN/inf (field, row, column named).
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray | None = None
    qdd: np.ndarray | None = None
    tau: np.ndarray | None = None
    current: np.ndarray | None = None
    temperature: np.ndarray | None = None
    joint_names: tuple[str, ...] | None = None
    tool_t: np.ndarray | None = None
    tool_points: np.ndarray | None = None
    units: Mapping[str, str] | None = None
    source: str = ""
    estimated: frozenset[str] = field(default_factory=frozenset)

    # -- construction ------------------------------------------------------------------------

    def _where(self, name: str) -> str:
        return f"{self.source}: {name}" if self.source else f"Recording.{name}"

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        t = np.asarray(self.t, dtype=float)
        if t.ndim != 1 or t.size < 2:
            raise RecordingError(f"{self._where('t')}: expected shape (N,) with N >= 2, got {t.shape}")
        self._finite("t", t, ())
        bad = np.nonzero(np.diff(t) <= 0)[0]
        if bad.size:
            k = int(bad[0]) + 1
            raise RecordingError(f"{self._where('t')}: not strictly increasing at row {k} "
                                 f"(t = {t[k]:.9g} s after {t[k - 1]:.9g} s)")
        set_(self, "t", _readonly(t))
        q = np.asarray(self.q, dtype=float)
        if q.ndim != 2 or q.shape[0] != t.size or q.shape[1] < 1:
            raise RecordingError(f"{self._where('q')}: expected shape (N, n) with N = {t.size} "
                                 f"(len(t)), got {q.shape}")
        n = q.shape[1]
        names = tuple(f"q{k + 1}" for k in range(n)) if self.joint_names is None else \
            tuple(self.joint_names)
        if len(names) != n or not all(isinstance(s, str) and s for s in names):
            raise RecordingError(f"{self._where('joint_names')}: expected {n} non-empty strings "
                                 f"(one per column of q), got {list(names)}")
        if len(set(names)) != n:
            dup = sorted({s for s in names if names.count(s) > 1})
            raise RecordingError(f"{self._where('joint_names')}: repeated names {dup}")
        set_(self, "joint_names", names)
        for name in JOINT_FIELDS:
            value = getattr(self, name)
            if value is None:
                continue
            a = np.asarray(value, dtype=float)
            if a.shape != (t.size, n):
                raise RecordingError(f"{self._where(name)}: expected shape ({t.size}, {n}) like q, "
                                     f"got {a.shape}")
            self._finite(name, a, names, allow_nan_columns=name in _MAY_LACK_COLUMNS)
            if name in PLAUSIBLE:
                check_plausible(self._where(name), name, a, names)
            set_(self, name, _readonly(a))
        self._tool()
        units = dict(DEFAULT_UNITS)
        units.update(dict(self.units or {}))
        set_(self, "units", MappingProxyType(units))
        self._estimate()

    def _finite(self, name: str, a: np.ndarray, names: Sequence[str],
                allow_nan_columns: bool = False) -> None:
        bad = ~np.isfinite(a)
        if allow_nan_columns and a.ndim == 2:
            bad &= ~np.all(np.isnan(a), axis=0)  # an all-NaN column: joint without that sensor
        if not bad.any():
            return
        row, *col = (int(v) for v in np.argwhere(bad)[0])
        value = a[(row, *col)]
        where = f"row {row}" + (f", column {col[0]} ({names[col[0]]!r})" if col else "")
        raise RecordingError(f"{self._where(name)}: {value} at {where} "
                             f"({int(bad.sum())} non-finite value(s) in all)")

    def _tool(self) -> None:
        if (self.tool_t is None) != (self.tool_points is None):
            raise RecordingError(f"{self._where('tool_t')}: tool_t and tool_points must be given "
                                 "together")
        if self.tool_t is None:
            return
        tt = np.asarray(self.tool_t, dtype=float)
        pts = np.asarray(self.tool_points, dtype=float)
        if tt.ndim != 1 or tt.size < 2:
            raise RecordingError(f"{self._where('tool_t')}: expected shape (M,) with M >= 2, "
                                 f"got {tt.shape}")
        if pts.shape != (tt.size, 3):
            raise RecordingError(f"{self._where('tool_points')}: expected shape ({tt.size}, 3), "
                                 f"got {pts.shape}")
        self._finite("tool_t", tt, ())
        self._finite("tool_points", pts, ("x", "y", "z"))
        bad = np.nonzero(np.diff(tt) <= 0)[0]
        if bad.size:
            raise RecordingError(f"{self._where('tool_t')}: not strictly increasing at row "
                                 f"{int(bad[0]) + 1}")
        object.__setattr__(self, "tool_t", _readonly(tt))
        object.__setattr__(self, "tool_points", _readonly(pts))

    def _estimate(self) -> None:
        if self.dt > SLOW_PERIOD:
            warnings.warn(f"{self._where('t')}: median period {self.dt:.6g} s ({1 / self.dt:.3g} "
                          "samples per second); robodyn's stamps are seconds: if these are "
                          "milliseconds, microseconds or nanoseconds, divide them by 1e3, 1e6 or "
                          "1e9 first", RecordingWarning, stacklevel=4)
        gaps = self.gaps
        if gaps:
            k, dt = gaps[0]
            warnings.warn(f"{self._where('t')}: {len(gaps)} gap(s) in the time stamps, the first "
                          f"of {dt:.6g} s after row {k} (median period {self.dt:.6g} s); they are "
                          "not filled in", RecordingWarning, stacklevel=4)
        estimated = set(self.estimated)
        if self.qd is None or self.qdd is None:
            if self.n_samples < 8:
                raise RecordingError(f"{self._where('qd')}: cannot estimate velocities from "
                                     f"{self.n_samples} samples (at least 8 are needed)")
            with np.errstate(over="ignore", invalid="ignore"):
                try:
                    # of the positions with wrap-around steps undone (a continuous joint)
                    _, qd, qdd = differentiate(self.t, unwrap_turns(self.q))
                except RecordingError as exc:  # the filter's own message, with the file
                    raise RecordingError(f"{self.source or 'Recording'}: {exc}") from None
            if not (np.all(np.isfinite(qd)) and np.all(np.isfinite(qdd))):
                raise RecordingError(f"{self._where('q')}: positions too large to differentiate "
                                     f"(largest magnitude {np.max(np.abs(self.q)):.3g}); check "
                                     "the units and the file")
            if self.qd is None:
                object.__setattr__(self, "qd", _readonly(qd))
                estimated.add("qd")
            if self.qdd is None:
                object.__setattr__(self, "qdd", _readonly(qdd))
                estimated.add("qdd")
        object.__setattr__(self, "estimated", frozenset(estimated))

    # -- properties ----------------------------------------------------------------------------

    @property
    def n_samples(self) -> int:
        """Number of joint samples N."""
        return int(self.t.size)

    @property
    def dof(self) -> int:
        """Number of joints n."""
        return int(self.q.shape[1])

    @property
    def dt(self) -> float:
        """Median sample period, s."""
        return float(np.median(np.diff(self.t)))

    @property
    def duration(self) -> float:
        """``t[-1] - t[0]``, s."""
        return float(self.t[-1] - self.t[0])

    @property
    def gaps(self) -> tuple[tuple[int, float], ...]:
        """``(row, step)`` for every step ``t[row + 1] - t[row]`` over 1.5 x the median period."""
        steps = np.diff(self.t)
        rows = np.nonzero(steps > _GAP_FACTOR * np.median(steps))[0]
        return tuple((int(k), float(steps[k])) for k in rows)

    # -- derived recordings --------------------------------------------------------------------

    def _joint_arrays(self) -> dict[str, np.ndarray | None]:
        return {name: getattr(self, name) for name in JOINT_FIELDS}

    def slice(self, t0: float, t1: float) -> Recording:
        """The samples with ``t0 <= t <= t1`` (tool samples too); nothing is re-estimated.

        Raises
        ------
        RecordingError
            Fewer than 2 joint samples in the window.
        """
        keep = (self.t >= t0) & (self.t <= t1)
        if keep.sum() < 2:
            raise RecordingError(f"{self._where('t')}: slice({t0:g}, {t1:g}) keeps {int(keep.sum())} "
                                 f"sample(s); the recording spans [{self.t[0]:g}, {self.t[-1]:g}] s")
        arrays = {k: (None if v is None else v[keep]) for k, v in self._joint_arrays().items()}
        tool = {"tool_t": None, "tool_points": None}
        if self.tool_t is not None:
            tk = (self.tool_t >= t0) & (self.tool_t <= t1)
            if tk.sum() >= 2:
                tool = {"tool_t": self.tool_t[tk], "tool_points": self.tool_points[tk]}
        return replace(self, t=self.t[keep], **arrays, **tool)

    def rows(self, keep: np.ndarray) -> Recording:
        """The joint samples where ``keep`` (N,) is true (tool samples unchanged). Fields that were
        estimated rather than measured (``estimated``: velocities, accelerations from ``q``) are
        estimated again from the kept samples, so a dropped glitch leaves no trace in them.

        Raises
        ------
        RecordingError
            ``keep`` of another length, or fewer than 2 samples kept.
        """
        keep = np.asarray(keep, dtype=bool)
        if keep.shape != self.t.shape or keep.sum() < 2:
            raise RecordingError(f"{self._where('t')}: rows() keeps {int(keep.sum())} of "
                                 f"{self.t.size} samples (a mask of {keep.size}); at least 2 needed")
        arrays = {k: (None if v is None or k in self.estimated else v[keep])
                  for k, v in self._joint_arrays().items()}
        return replace(self, t=self.t[keep], **arrays, estimated=frozenset())

    def select(self, joints: Sequence[str | int]) -> Recording:
        """A recording of some joints, in the order given (names or 0-based indices)."""
        idx = []
        for j in joints:
            if isinstance(j, str):
                if j not in self.joint_names:
                    raise RecordingError(f"{self._where('joint_names')}: no joint {j!r} "
                                         f"(has {', '.join(self.joint_names)})")
                idx.append(self.joint_names.index(j))
            elif isinstance(j, int | np.integer) and -self.dof <= int(j) < self.dof:
                idx.append(int(j) % self.dof)
            else:
                raise RecordingError(f"{self._where('joint_names')}: joint index {j!r} out of range "
                                     f"for {self.dof} joints")
        if not idx:
            raise RecordingError(f"{self._where('joint_names')}: select() needs at least one joint")
        arrays = {k: (None if v is None else v[:, idx]) for k, v in self._joint_arrays().items()}
        return replace(self, joint_names=tuple(self.joint_names[k] for k in idx), **arrays)

    def resample(self, dt: float) -> Recording:
        """The joint signals on a uniform grid ``t[0] + k dt`` (tool samples unchanged).

        Signals are interpolated by cubic splines; when ``dt`` is longer than the current period
        they are first low-passed (zero-phase Butterworth at 0.8 x the new Nyquist frequency,
        0.4 / dt) so that the coarser grid does not alias.
        """
        if not np.isfinite(dt) or dt <= 0:
            raise RecordingError(f"{self._where('t')}: resample dt must be a positive time, got {dt}")
        n_new = int(np.floor(self.duration / dt + 1e-9)) + 1
        if n_new < 2:
            raise RecordingError(f"{self._where('t')}: resample dt = {dt:g} s leaves fewer than 2 "
                                 f"samples in {self.duration:g} s")
        tu = self.t[0] + dt * np.arange(n_new)
        anti_alias = dt > 1.0001 * self.dt and 0.4 / dt < 0.5 / self.dt
        arrays = {}
        for name, value in self._joint_arrays().items():
            if value is None:
                arrays[name] = None
                continue
            ok = ~np.all(np.isnan(value), axis=0)
            out = np.full((n_new, value.shape[1]), np.nan)
            v = value[:, ok]
            if anti_alias and v.size:
                v = lowpass(self.t, v, 0.4 / dt)
            if v.size:
                out[:, ok] = make_interp_spline(self.t, v, k=3, axis=0)(tu)
            arrays[name] = out
        return replace(self, t=tu, **arrays)
