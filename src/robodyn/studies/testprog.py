"""Test programs of the thesis (ch. 4): one joint at a time, and the ISO 9283 cube poses.

``jointwise``
    Each joint in turn moves through a stroke (180 deg by default, shortened to fit its limits)
    with a trapezoidal velocity profile, out and back (both directions), at each speed fraction
    (50 % and 100 % of its speed limit by default), with a dwell at rest after each move; the other
    joints hold their home positions. One joint moving at a time separates the joints' friction
    and makes each drive's gain observable on its own.
``iso_cube``
    The five ISO 9283 test points P1..P5 on the diagonal plane of a cube placed in the workspace
    (:func:`robodyn.calibration.iso9283.cube_points`), reached by damped-least-squares inverse
    kinematics (:func:`robodyn.simulation.inverse_kinematics`, each solution warm-started from the
    previous one), visited in the order P1 P2 P3 P4 P5 (back to P1) for a number of cycles with
    synchronised joint-space trapezoidal moves and a dwell at each pose.

Both return a :class:`TestProgram`: a :class:`~robodyn.simulation.trajectory.JointTrajectory`
(``t, q, qd, qdd``; a reference for :func:`robodyn.simulation` controllers and for
:func:`robodyn.studies.virtual_lab.virtual_lab`) and the list of its segments, writable as CSV.
"""

from __future__ import annotations

import csv
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from robodyn.calibration.iso9283 import cube_points
from robodyn.numeric.model import Model, compile_model
from robodyn.robot.errors import InputError
from robodyn.robot.model import Robot
from robodyn.robot.sizes import time_grid_steps
from robodyn.simulation.ik import UnreachableError, inverse_kinematics
from robodyn.simulation.trajectory import JointTrajectory, concatenate, trapezoidal
from robodyn.studies.excitation import excitation_limits, write_trajectory_csv

__all__ = ["Segment", "TestProgram", "default_cube_center", "iso_cube", "jointwise"]


@dataclass(frozen=True)
class Segment:
    """One part of a test program.

    Attributes
    ----------
    kind : {"move", "dwell", "approach"}
        A test move, a rest, or a positioning move between test moves.
    t0, t1 : float
        Start and end time, s.
    joint : str or None
        The moving joint of a jointwise move (None for a multi-joint move or a dwell).
    speed : float
        Fraction of the speed limit used (0 for a dwell).
    direction : int
        +1 or -1 for a jointwise move, 0 otherwise.
    label : str
        Human-readable description (e.g. "q2 +180.0 deg at 50 %", "P3").
    """

    kind: str
    t0: float
    t1: float
    joint: str | None
    speed: float
    direction: int
    label: str


@dataclass(frozen=True, eq=False)
class TestProgram:
    """A test program: the planned motion and its segments.

    Attributes
    ----------
    name : str
        "jointwise" or "iso-cube".
    trajectory : JointTrajectory
        The whole motion, sampled every ``dt`` (``t``, ``q``, ``qd``, ``qdd``).
    segments : tuple of Segment
    joint_names : tuple of str
    points : (P, 3) ndarray or None
        The ISO cube test points P1..P5 (m, base frame), for ``iso_cube``.
    poses : (P, n) ndarray or None
        Joint values reaching ``points``.
    """

    __test__ = False  # not a pytest test class

    name: str
    trajectory: JointTrajectory
    segments: tuple[Segment, ...]
    joint_names: tuple[str, ...]
    points: np.ndarray | None = None
    poses: np.ndarray | None = None

    @property
    def t(self) -> np.ndarray:
        """(N,) s."""
        return self.trajectory.t

    @property
    def q(self) -> np.ndarray:
        """(N, n) rad (m)."""
        return self.trajectory.q

    @property
    def qd(self) -> np.ndarray:
        """(N, n) rad/s (m/s)."""
        return self.trajectory.qd

    @property
    def qdd(self) -> np.ndarray:
        """(N, n) rad/s^2 (m/s^2)."""
        return self.trajectory.qdd

    @property
    def duration(self) -> float:
        """s."""
        return self.trajectory.duration

    def to_csv(self, directory: str | Path) -> tuple[Path, Path]:
        """Write ``<name>.csv`` (t, q_*, qd_*, qdd_*, SI units) and ``<name>_segments.csv`` into
        ``directory`` (created if missing). Returns both paths."""
        out = Path(directory)
        out.mkdir(parents=True, exist_ok=True)
        traj = write_trajectory_csv(out / f"{self.name}.csv", self.t, self.q, self.qd, self.qdd,
                                    self.joint_names)
        seg_path = out / f"{self.name}_segments.csv"
        with seg_path.open("w", newline="", encoding="utf-8") as fh:
            w = csv.writer(fh)
            w.writerow(["kind", "t0", "t1", "joint", "speed", "direction", "label"])
            for s in self.segments:
                w.writerow([s.kind, f"{s.t0:.17g}", f"{s.t1:.17g}", s.joint or "", s.speed, s.direction,
                            s.label])
        return traj, seg_path


def _model(robot: Robot | Model) -> Model:
    return robot if isinstance(robot, Model) else compile_model(robot)


def _vector(v: float | Sequence[float] | None, default: np.ndarray, name: str) -> np.ndarray:
    if v is None:
        return default
    arr = np.asarray(v, dtype=float)
    if arr.ndim == 0:
        arr = np.full(default.shape, float(arr))
    if arr.shape != default.shape or not np.all(np.isfinite(arr)) or np.any(arr <= 0):
        raise InputError(f"{name} must be positive: a scalar or a {default.shape} array, got {v!r}")
    return arr


#: Slowest speed fraction of a test program (a stroke at 1e-6 of the limit takes days of samples).
MIN_SPEED = 1e-3
#: Most ISO 9283 cycles (the standard's repeatability test uses 30).
MAX_CYCLES = 10_000


def _speeds(speeds: Sequence[float]) -> tuple[float, ...]:
    out = tuple(float(s) for s in speeds)
    if not out or any(not (MIN_SPEED <= s <= 1.0) for s in out):
        raise InputError(f"speeds must be fractions in [{MIN_SPEED:g}, 1] of the velocity limit, "
                         f"got {speeds!r}")
    return out


def jointwise(robot: Robot | Model, *, speeds: Sequence[float] = (0.5, 1.0), stroke: float = np.pi,
              home: Sequence[float] | None = None, joints: Sequence[str] | None = None,
              velocity: float | Sequence[float] | None = None,
              acceleration: float | Sequence[float] | None = None, dwell: float = 0.5,
              dt: float = 1e-3) -> TestProgram:
    """One joint at a time: out-and-back trapezoidal strokes at each speed fraction.

    For each joint (in chain order, or the order of ``joints``): move it from home to the start
    of its stroke, then for each speed fraction ``s`` a move of ``+stroke`` and one of
    ``-stroke`` (both directions) at cruise speed ``s * velocity`` with acceleration
    ``acceleration``, each followed by ``dwell`` s at rest; finally back home.

    Parameters
    ----------
    robot : Robot or Model
    speeds : sequence of float
        Fractions of the speed limit, in (0, 1] (thesis: 50 % and 100 %).
    stroke : float
        Move length, rad (m), default pi (180 deg); shortened to the joint's range within its
        limits where that is smaller.
    home : (n,) array_like, optional
        Joint values held by the joints not moving (default: the middle of each joint's range,
        0 for a joint without limits).
    joints : sequence of str, optional
        Joints to test (default all).
    velocity, acceleration : float or (n,) array_like, optional
        Speed limit (default the description's ``velocity_limit``, else
        :data:`~robodyn.studies.excitation.DEFAULT_VELOCITY`) and acceleration (default
        :data:`~robodyn.studies.excitation.DEFAULT_ACCELERATION`).
    dwell : float
        Rest after each move, s (>= 0).
    dt : float
        Sampling step, s.

    Returns
    -------
    TestProgram
    """
    model = _model(robot)
    rob = model.robot
    n = model.dof
    lim = excitation_limits(rob, margin=0.0)
    vel = _vector(velocity, lim.velocity, "velocity")
    acc = _vector(acceleration, lim.acceleration, "acceleration")
    fracs = _speeds(speeds)
    _check_dt(dt, "jointwise")
    if not np.isfinite(stroke) or stroke <= 0:
        raise InputError(f"jointwise: stroke must be a positive angle (rad), got {stroke!r}")
    if dwell < 0:
        raise InputError(f"jointwise: dwell must be >= 0 s, got {dwell!r}")
    has = np.array([j.lower is not None and j.upper is not None for j in rob.joints])
    q_home = np.where(has, 0.5 * (lim.lower + lim.upper), 0.0) if home is None else np.asarray(home, float)
    if q_home.shape != (n,) or np.any(q_home < lim.lower) or np.any(q_home > lim.upper):
        raise InputError(f"jointwise: home must be a ({n},) array within the joint limits, got {home!r}")
    names = rob.joint_names
    order = list(range(n)) if joints is None else [_joint_index(names, j) for j in joints]
    parts: list[JointTrajectory] = []
    segments: list[Segment] = []
    clock = [0.0]

    def add(part: JointTrajectory, seg: Segment) -> None:
        parts.append(part)
        segments.append(Segment(seg.kind, clock[0], clock[0] + part.duration, seg.joint, seg.speed,
                                seg.direction, seg.label))
        clock[0] += part.duration

    def rest(q: np.ndarray) -> None:
        if dwell > 0:
            add(trapezoidal(q, q, vel, acc, duration=dwell, dt=_PLAN),
                Segment("dwell", 0, 0, None, 0.0, 0, "rest"))

    q = q_home.copy()
    for i in order:
        span = lim.upper[i] - lim.lower[i]
        length = min(stroke, span)
        # start so the stroke is centred on home where the limits allow
        start = float(np.clip(q_home[i] - length / 2, lim.lower[i], lim.upper[i] - length))
        a = q.copy()
        a[i] = start
        if abs(start - q[i]) > 0:
            add(trapezoidal(q, a, vel, acc, dt=_PLAN), Segment("approach", 0, 0, names[i], 1.0, 0,
                                                            f"{names[i]} to start"))
            rest(a)
        b = a.copy()
        b[i] = start + length
        for s in fracs:
            for direction, (p0, p1) in ((1, (a, b)), (-1, (b, a))):
                sign = "+" if direction > 0 else "-"
                label = f"{names[i]} {sign}{np.degrees(length):.1f} deg at {100 * s:g} %"
                add(trapezoidal(p0, p1, s * vel, acc, dt=_PLAN),
                    Segment("move", 0, 0, names[i], s, direction, label))
                rest(p1)
        add(trapezoidal(a, q_home, vel, acc, dt=_PLAN) if abs(start - q_home[i]) > 0
            else trapezoidal(a, a, vel, acc, duration=dt, dt=_PLAN),
            Segment("approach", 0, 0, names[i], 1.0, 0, f"{names[i]} home"))
        q = q_home.copy()
    traj = _sampled(parts, dt, "jointwise", n)
    return TestProgram("jointwise", traj, tuple(segments), names)


def default_cube_center(model: Model, *, samples: int = 1024, seed: int = 0) -> np.ndarray:
    """A cube centre in the middle of the workspace, in front of the robot, (3,) m.

    From the tool positions of ``samples`` random joint values within the limits: the median
    horizontal distance from the base z axis (placed on +x) and the median height.
    """
    rng = np.random.default_rng(seed)
    lim = excitation_limits(model.robot, margin=0.0)
    p = model.forward_kinematics(rng.uniform(lim.lower, lim.upper, (samples, model.dof)))[:, :3, 3]
    return np.array([np.median(np.hypot(p[:, 0], p[:, 1])), 0.0, np.median(p[:, 2])])


def iso_cube(robot: Robot | Model, *, size: float = 0.5, center: Sequence[float] | None = None,
             rotation: np.ndarray | None = None, fraction: float = 0.1, cycles: int = 1,
             speed: float = 0.5, home: Sequence[float] | None = None,
             velocity: float | Sequence[float] | None = None,
             acceleration: float | Sequence[float] | None = None, dwell: float = 1.0,
             dt: float = 1e-3) -> TestProgram:
    """ISO 9283 cube poses P1..P5, visited ``cycles`` times (P1 P2 P3 P4 P5, then back to P1).

    Parameters
    ----------
    robot : Robot or Model
    size : float
        Cube edge, m (the thesis used 0.5 m).
    center : (3,) array_like, optional
        Cube centre in the base frame, m (default :func:`default_cube_center`).
    rotation : (3, 3) array_like, optional
        Cube orientation.
    fraction : float
        Distance of P2..P5 from the corners along the diagonals (ISO 9283: 0.10 +- 0.02).
    cycles : int
        Number of P1..P5 cycles (ISO 9283 pose repeatability uses 30).
    speed : float
        Fraction of the speed limit, in (0, 1].
    home : (n,) array_like, optional
        Start and end of the program, and the IK guess for P1 (default mid-range).
    velocity, acceleration : float or (n,) array_like, optional
        As for :func:`jointwise`.
    dwell : float
        Rest at each pose, s (where a tracker measures it).
    dt : float
        Sampling step, s.

    Returns
    -------
    TestProgram
        With ``points`` (5, 3) and ``poses`` (5, n).

    Raises
    ------
    UnreachableError
        When a test point cannot be reached within the joint limits (names the point).
    """
    model = _model(robot)
    rob = model.robot
    n = model.dof
    lim = excitation_limits(rob, margin=0.0)
    vel = _vector(velocity, lim.velocity, "velocity")
    acc = _vector(acceleration, lim.acceleration, "acceleration")
    (s,) = _speeds([speed])
    _check_dt(dt, "iso_cube")
    if isinstance(cycles, bool) or not isinstance(cycles, int) or not 1 <= cycles <= MAX_CYCLES:
        raise InputError(f"iso_cube: cycles must be an integer in [1, {MAX_CYCLES}] (ISO 9283 "
                         f"uses 30), got {cycles!r}")
    if dwell < 0:
        raise InputError(f"iso_cube: dwell must be >= 0 s, got {dwell!r}")
    has = np.array([j.lower is not None and j.upper is not None for j in rob.joints])
    q_home = np.where(has, 0.5 * (lim.lower + lim.upper), 0.0) if home is None else np.asarray(home, float)
    if q_home.shape != (n,):
        raise InputError(f"iso_cube: home must have shape ({n},), got {q_home.shape}")
    c = default_cube_center(model) if center is None else np.asarray(center, dtype=float)
    points = cube_points(c, size, fraction=fraction, rotation=rotation)
    poses = np.empty((5, n))
    guess = q_home
    for k, p in enumerate(points):
        res = inverse_kinematics(model, p, guess, tol=1e-9, raise_on_failure=False)
        if not res.success:
            raise UnreachableError(f"iso_cube: test point P{k + 1} {np.round(p, 4).tolist()} m of a "
                                   f"{size:g} m cube is out of reach of {rob.name!r}: {res.message}")
        poses[k] = guess = res.q
    parts: list[JointTrajectory] = []
    segments: list[Segment] = []
    clock = 0.0
    # pose indices (-1: home); a move or dwell repeated every cycle is planned once
    visits = [-1] + [k for _ in range(cycles) for k in range(5)] + [0, -1]
    pose = {-1: q_home, **{k: poses[k] for k in range(5)}}
    planned: dict[tuple[int, int], JointTrajectory] = {}
    for i, j in zip(visits[:-1], visits[1:], strict=True):
        a, b = pose[i], pose[j]
        label = "home" if j < 0 else f"P{j + 1}"
        if (i, j) not in planned:
            planned[i, j] = (trapezoidal(a, b, s * vel, acc, dt=_PLAN) if np.any(a != b)
                             else trapezoidal(a, a, vel, acc, duration=dt, dt=_PLAN))
        move = planned[i, j]
        parts.append(move)
        segments.append(Segment("move", clock, clock + move.duration, None, s, 0, f"to {label}"))
        clock += move.duration
        if dwell > 0 and label != "home":
            if (j, j) not in planned:
                planned[j, j] = trapezoidal(b, b, vel, acc, duration=dwell, dt=_PLAN)
            parts.append(planned[j, j])
            segments.append(Segment("dwell", clock, clock + dwell, None, 0.0, 0, label))
            clock += dwell
    traj = _sampled(parts, dt, f"iso_cube (cycles {cycles})", n)
    return TestProgram("iso-cube", traj, tuple(segments), rob.joint_names, _frozen(points), _frozen(poses))


#: Sampling step of the planned parts of a program, s: each is a piecewise polynomial with a few
#: samples, and :func:`_sampled` samples the whole program once at the user's ``dt``.
_PLAN = 1e9


def _check_dt(dt: float, where: str) -> None:
    if isinstance(dt, bool) or not isinstance(dt, int | float) or not np.isfinite(dt) or dt <= 0:
        raise InputError(f"{where}: dt must be a positive number of seconds, got {dt!r}")


def _sampled(parts: list[JointTrajectory], dt: float, where: str, n: int) -> JointTrajectory:
    """The parts one after the other, sampled every ``dt``, after checking the program's sample
    count (t, q, qd, qdd of ``n`` joints are evaluated and written: :func:`time_grid_steps`)."""
    time_grid_steps(sum(p.duration for p in parts), dt, where, duration_name="program",
                    values_per_sample=1 + 3 * n)
    return concatenate(*parts, dt=dt)


def _joint_index(names: tuple[str, ...], name: str) -> int:
    if name not in names:
        raise InputError(f"unknown joint {name!r}; the robot's joints are {', '.join(names)}")
    return names.index(name)


def _frozen(a: np.ndarray) -> np.ndarray:
    a = np.array(a, dtype=float)
    a.flags.writeable = False
    return a
