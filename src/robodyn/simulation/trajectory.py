"""Planned joint trajectories: quintic and trapezoidal moves, via-point splines, Cartesian lines.

Every planner returns a :class:`JointTrajectory`: piecewise polynomials in time (a SciPy
``PPoly``), sampled on a uniform grid ``t`` into frozen arrays ``q``, ``qd``, ``qdd``, and
evaluable at any time with :meth:`JointTrajectory.at` (what :class:`~robodyn.simulation.controllers.
ComputedTorque` and the PD references use). Positions in rad (revolute) or m (prismatic).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import BSpline, PPoly, make_interp_spline
from scipy.spatial.transform import Rotation

from robodyn.numeric.model import Model
from robodyn.robot.errors import InputError
from robodyn.robot.sizes import time_grid_steps
from robodyn.simulation.ik import UnreachableError, inverse_kinematics


@dataclass(frozen=True, eq=False)
class JointTrajectory:
    """A planned joint motion.

    Attributes
    ----------
    t : (N,) ndarray
        Sample times, s, from 0 to ``duration``.
    q, qd, qdd : (N, n) ndarray
        Positions, velocities and accelerations at ``t`` (read-only).
    duration : float
        s.
    kind : str
        Which planner made it ("quintic", "trapezoidal", "cubic spline", ...).
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    duration: float
    kind: str
    _pp: PPoly = field(repr=False)

    @property
    def dof(self) -> int:
        """Number of joints n."""
        return self.q.shape[1]

    def at(self, t: float | np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(q, qd, qdd)`` at time(s) ``t``: (n,) each for a scalar, (K, n) for a (K,) array.

        Before 0 and after ``duration`` the motion is held at rest at its first / last position.
        """
        tt = np.asarray(t, dtype=float)
        scalar = tt.ndim == 0
        tt = np.atleast_1d(tt)
        inside = (tt >= 0.0) & (tt <= self.duration)
        tc = np.clip(tt, 0.0, self.duration)
        q = self._pp(tc)
        qd = np.where(inside[:, None], self._pp(tc, 1), 0.0)
        qdd = np.where(inside[:, None], self._pp(tc, 2), 0.0)
        if scalar:
            return q[0], qd[0], qdd[0]
        return q, qd, qdd

    def resampled(self, dt: float) -> JointTrajectory:
        """The same motion sampled every ``dt`` s."""
        return _from_ppoly(self._pp, self.duration, dt, self.kind)


def quintic(q0: Sequence[float], q1: Sequence[float], duration: float, *, dt: float = 1e-3,
            qd0: Sequence[float] | None = None, qd1: Sequence[float] | None = None,
            qdd0: Sequence[float] | None = None, qdd1: Sequence[float] | None = None) -> JointTrajectory:
    """Quintic polynomial move with given end positions, velocities and accelerations.

    Parameters
    ----------
    q0, q1 : (n,) array_like
        Start and end positions.
    duration : float
        Move time T, s (> 0).
    dt : float
        Sampling step of the returned arrays, s.
    qd0, qd1, qdd0, qdd1 : (n,) array_like, optional
        End velocities and accelerations (default zero: a rest-to-rest move).

    Returns
    -------
    JointTrajectory
        ``q(t) = a0 + a1 t + ... + a5 t^5`` per joint, exact at both ends.
    """
    a, b = _vectors(q0, q1)
    n = a.size
    v0, v1, c0, c1 = (np.zeros(n) if v is None else finite_vector(v, n, name)
                      for v, name in ((qd0, "qd0"), (qd1, "qd1"), (qdd0, "qdd0"), (qdd1, "qdd1")))
    T = _positive(duration, "duration")
    h = b - a
    # a3..a5 from q(T) = q1, qd(T) = qd1, qdd(T) = qdd1 (closed form)
    a3 = (20 * h - (8 * v1 + 12 * v0) * T - (3 * c0 - c1) * T**2) / (2 * T**3)
    a4 = (-30 * h + (14 * v1 + 16 * v0) * T + (3 * c0 - 2 * c1) * T**2) / (2 * T**4)
    a5 = (12 * h - 6 * (v1 + v0) * T + (c1 - c0) * T**2) / (2 * T**5)
    coeffs = np.stack([a5, a4, a3, 0.5 * c0, v0, a])[:, None, :]
    return _from_ppoly(PPoly(coeffs, [0.0, T]), T, dt, "quintic")


def trapezoidal(q0: Sequence[float], q1: Sequence[float], vmax: float | Sequence[float],
                amax: float | Sequence[float], *, duration: float | None = None,
                dt: float = 1e-3) -> JointTrajectory:
    """Straight line in joint space with a trapezoidal velocity profile, all joints synchronised.

    The joints share one time scaling ``q(t) = q0 + (q1 - q0) s(t)``, ``s`` from 0 to 1 with
    constant acceleration, cruise and deceleration phases (triangular when the cruise would have
    negative length). ``s`` accelerates at ``A = min_i amax_i / |dq_i|`` and cruises at
    ``V = min_i vmax_i / |dq_i|``, so no joint exceeds its limits and the slowest joint sets the
    pace: the time-optimal move along the joint-space line.

    Parameters
    ----------
    q0, q1 : (n,) array_like
    vmax, amax : float or (n,) array_like
        Velocity (rad/s, m/s) and acceleration (rad/s^2, m/s^2) limits, positive.
    duration : float, optional
        Stretch the move to this time (s) by lowering the cruise speed; must not be shorter than
        the minimum time.
    dt : float
        Sampling step, s.

    Returns
    -------
    JointTrajectory
    """
    a, b = _vectors(q0, q1)
    n = a.size
    vmax_v = _limit_vector(vmax, n, "vmax")
    amax_v = _limit_vector(amax, n, "amax")
    dq = b - a
    moving = np.abs(dq) > 0
    if not moving.any():
        T = 0.0 if duration is None else _positive(duration, "duration")
        coeffs = np.zeros((3, 1, n))
        coeffs[2, 0] = a
        return _from_ppoly(PPoly(coeffs, [0.0, max(T, 1e-12)]), T, dt, "trapezoidal")
    A = float(np.min(amax_v[moving] / np.abs(dq[moving])))
    V = float(np.min(vmax_v[moving] / np.abs(dq[moving])))
    # triangular profile when the cruise speed is never reached: V^2 / A > 1
    V = min(V, np.sqrt(A))
    t_min = 1.0 / V + V / A
    if duration is not None:
        T = _positive(duration, "duration")
        if T < t_min * (1 - 1e-12):
            raise InputError(f"trapezoidal: duration {T:g} s is shorter than the minimum {t_min:g} s "
                             f"the velocity and acceleration limits allow")
        # T = 1/V + V/A  ->  V^2 - A T V + A = 0, the smaller root
        V = 0.5 * (A * T - np.sqrt(max(A * A * T * T - 4 * A, 0.0)))
    ta = V / A
    T = 1.0 / V + V / A
    # s on [0, ta]: A x^2/2;  cruise: s(ta) + V x;  deceleration: s(T-ta) + V x - A x^2/2
    pieces = [(0.0, (A / 2, 0.0, 0.0))]
    s_ta = A * ta**2 / 2
    if T - 2 * ta > 1e-12 * T:
        pieces.append((ta, (0.0, V, s_ta)))
    pieces.append((T - ta, (-A / 2, V, 1.0 - s_ta)))
    breaks = np.array([p[0] for p in pieces] + [T])
    coeffs = np.zeros((3, len(pieces), n))
    for i, (_, (c2, c1, c0)) in enumerate(pieces):
        coeffs[0, i] = c2 * dq
        coeffs[1, i] = c1 * dq
        coeffs[2, i] = a + c0 * dq
    return _from_ppoly(PPoly(coeffs, breaks), T, dt, "trapezoidal")


def via_points(points: Sequence[Sequence[float]], times: Sequence[float], *, kind: str = "quintic",
               dt: float = 1e-3) -> JointTrajectory:
    """Smooth path through via points, at rest at both ends.

    Parameters
    ----------
    points : (K, n) array_like
        Joint positions to pass through, K >= 2.
    times : (K,) array_like
        When to pass each point, s; strictly increasing, starting at 0.
    kind : {"quintic", "cubic"}
        "quintic": a quintic spline (C^4) with zero velocity and acceleration at both ends;
        "cubic": a cubic spline (C^2) with zero velocity at both ends.
    dt : float
        Sampling step, s.

    Returns
    -------
    JointTrajectory
    """
    pts = np.asarray(points, dtype=float)
    tk = np.asarray(times, dtype=float)
    if pts.ndim != 2 or pts.shape[0] < 2:
        raise InputError(f"via_points: points must be (K, n) with K >= 2, got shape {pts.shape}")
    if tk.shape != (pts.shape[0],):
        raise InputError(f"via_points: times must have shape ({pts.shape[0]},), got {tk.shape}")
    if not (np.all(np.isfinite(pts)) and np.all(np.isfinite(tk))):
        raise InputError("via_points: points and times must be finite")
    if tk[0] != 0.0 or np.any(np.diff(tk) <= 0):
        raise InputError("via_points: times must start at 0 and be strictly increasing")
    n = pts.shape[1]
    if kind == "quintic":
        ends = [(1, np.zeros(n)), (2, np.zeros(n))]
        spline = make_interp_spline(tk, pts, k=5, bc_type=(ends, ends))
    elif kind == "cubic":
        ends = [(1, np.zeros(n))]
        spline = make_interp_spline(tk, pts, k=3, bc_type=(ends, ends))
    else:
        raise InputError(f"via_points: unknown kind {kind!r}; choose 'quintic' or 'cubic'")
    return _from_ppoly(_spline_ppoly(spline), float(tk[-1]), dt, f"{kind} spline")


def cartesian_line(model: Model, q_start: Sequence[float], target: np.ndarray, duration: float, *,
                   dt: float = 1e-3, knots: int | None = None, tol: float = 1e-10) -> JointTrajectory:
    """Straight tool line from the pose at ``q_start`` to ``target``, through inverse kinematics.

    The tool point moves along the segment with a rest-to-rest quintic time scaling
    ``s(t) = 10 tau^3 - 15 tau^4 + 6 tau^5``, ``tau = t / T``. A (3,) target is a position (the
    orientation is left free, position-only IK); a (4, 4) target is a pose, and the orientation
    turns about a fixed axis (``R(s) = exp(s log(R_target R0^T)) R0``). Inverse kinematics is
    solved at each knot, warm-started from the previous one (so the arm stays on the branch of
    ``q_start``), and a quintic spline in time with zero end velocity and acceleration is fitted
    through the solutions: the joint curves that the seed thesis' path planner produced from its
    inverse kinematic results.

    Parameters
    ----------
    model : Model
    q_start : (n,) array_like
        Joint values at the start (the line starts at their tool pose).
    target : (3,) or (4, 4) array_like
        End position (m) or pose, base frame.
    duration : float
        s.
    dt : float
        Sampling step of the result, s.
    knots : int, optional
        Number of IK solutions along the line, evenly spaced in time (default: one every 10 ms,
        at least 11). Between knots the spline leaves the line by far less than the IK
        tolerance for smooth paths (about 1e-11 m on the AA300); ``knots = steps + 1`` puts
        every sample on the line.
    tol : float
        IK tolerance, m and rad.

    Returns
    -------
    JointTrajectory

    Raises
    ------
    UnreachableError
        When a point of the line cannot be reached within the joint limits (the message gives
        the fraction of the line reached).
    """
    q0 = np.asarray(q_start, dtype=float)
    if q0.shape != (model.dof,):
        raise InputError(f"cartesian_line: q_start must have shape ({model.dof},), got {q0.shape}")
    target = np.asarray(target, dtype=float)
    if target.shape not in ((3,), (4, 4)):
        raise InputError(f"cartesian_line: target must be (3,) or (4, 4), got {target.shape}")
    T = _positive(duration, "duration")
    start = model.forward_kinematics(q0)
    p0 = start[:3, 3]
    p1 = target if target.shape == (3,) else target[:3, 3]
    rotvec = (None if target.shape == (3,)
              else Rotation.from_matrix(target[:3, :3] @ start[:3, :3].T).as_rotvec())
    _steps(T, dt)
    count = max(11, int(np.ceil(T / 0.01)) + 1) if knots is None else int(knots)
    if count < 2:
        raise InputError("cartesian_line: knots must be >= 2")
    tk = np.linspace(0.0, T, count)
    tau = tk / T
    s = 10 * tau**3 - 15 * tau**4 + 6 * tau**5
    qs = np.empty((count, model.dof))
    q = q0
    for k, sk in enumerate(s):
        # p(s) = p0 + s (p1 - p0)
        p = p0 + sk * (p1 - p0)
        if rotvec is None:
            goal = p
        else:
            goal = np.eye(4)
            goal[:3, :3] = Rotation.from_rotvec(sk * rotvec).as_matrix() @ start[:3, :3]
            goal[:3, 3] = p
        res = inverse_kinematics(model, goal, q, tol=tol, restarts=0, raise_on_failure=False)
        if not res.success:
            raise UnreachableError(f"cartesian_line: the line leaves the reachable workspace at "
                                   f"{100 * sk:.1f} % of its length: {res.message}")
        q = res.q
        qs[k] = q
    ends = [(1, np.zeros(model.dof)), (2, np.zeros(model.dof))]
    spline = make_interp_spline(tk, qs, k=5, bc_type=(ends, ends))
    return _from_ppoly(_spline_ppoly(spline), T, dt, "cartesian line")


def concatenate(*parts: JointTrajectory, dt: float | None = None) -> JointTrajectory:
    """One trajectory running ``parts`` one after the other (each must start where the last ended).

    Parameters
    ----------
    *parts : JointTrajectory
    dt : float, optional
        Sampling step (default: the first part's).
    """
    if not parts:
        raise InputError("concatenate: give at least one trajectory")
    for prev, nxt in zip(parts, parts[1:], strict=False):
        gap = np.max(np.abs(prev.at(prev.duration)[0] - nxt.at(0.0)[0]))
        if gap > 1e-9:
            raise InputError(f"concatenate: a {nxt.kind} part starts {gap:.3g} away from where the "
                             f"previous {prev.kind} part ends")
    order = max(p._pp.c.shape[0] for p in parts)
    breaks, coeffs, offset = [0.0], [], 0.0
    for p in parts:
        c = p._pp.c
        c = np.concatenate([np.zeros((order - c.shape[0],) + c.shape[1:]), c])
        x = p._pp.x
        keep = (x[1:] > 0.0) & (x[:-1] < p.duration)
        breaks += list(offset + np.minimum(x[1:][keep], p.duration))
        coeffs.append(c[:, keep])
        offset += p.duration
    pp = PPoly(np.concatenate(coeffs, axis=1), np.array(breaks))
    step = parts[0].t[1] - parts[0].t[0] if dt is None and parts[0].t.size > 1 else (dt or 1e-3)
    return _from_ppoly(pp, offset, step, "+".join(dict.fromkeys(p.kind for p in parts)))


# --- helpers -----------------------------------------------------------------------------------
def _spline_ppoly(spline: BSpline) -> PPoly:
    """A vector-valued B-spline as one PPoly (SciPy converts one component at a time)."""
    parts = [PPoly.from_spline(BSpline(spline.t, spline.c[:, j], spline.k)) for j in range(spline.c.shape[1])]
    return PPoly(np.stack([pp.c for pp in parts], axis=-1), parts[0].x)


def _from_ppoly(pp: PPoly, duration: float, dt: float, kind: str) -> JointTrajectory:
    steps = _steps(duration, dt) if duration > 0 else 0
    t = np.minimum(dt * np.arange(steps + 1), duration)
    arrays = [t, pp(t), pp(t, 1), pp(t, 2)]
    for arr in arrays:
        arr.flags.writeable = False
    return JointTrajectory(*arrays, duration=float(duration), kind=kind, _pp=pp)


def _steps(duration: float, dt: float) -> int:
    dt = _positive(dt, "dt")
    time_grid_steps(duration, dt, "trajectory")  # the sample count bounded before allocating
    return int(np.ceil(duration / dt - 1e-9))


def _positive(value: float, name: str) -> float:
    v = float(value)
    if not np.isfinite(v) or v <= 0:
        raise InputError(f"{name} must be a positive finite number, got {value!r}")
    return v


def finite_vector(v: Sequence[float], n: int, name: str) -> np.ndarray:
    """``v`` as a finite (n,) float array, or an :class:`InputError` naming ``name``."""
    arr = np.asarray(v, dtype=float)
    if arr.shape != (n,) or not np.all(np.isfinite(arr)):
        raise InputError(f"{name} must be a finite ({n},) array, got shape {arr.shape}")
    return arr


def _vectors(q0: Sequence[float], q1: Sequence[float]) -> tuple[np.ndarray, np.ndarray]:
    a = np.asarray(q0, dtype=float)
    if a.ndim != 1 or a.size == 0:
        raise InputError(f"q0 must be a 1-D array of joint values, got shape {a.shape}")
    return finite_vector(a, a.size, "q0"), finite_vector(q1, a.size, "q1")


def _limit_vector(v: float | Sequence[float], n: int, name: str) -> np.ndarray:
    arr = np.broadcast_to(np.asarray(v, dtype=float), (n,)) if np.ndim(v) == 0 else np.asarray(v, float)
    if arr.shape != (n,) or not np.all(np.isfinite(arr)) or np.any(arr <= 0):
        raise InputError(f"{name} must be positive: a scalar or a ({n},) array, got {v!r}")
    return arr


__all__ = ["JointTrajectory", "cartesian_line", "concatenate", "finite_vector", "quintic", "trapezoidal",
           "via_points"]
