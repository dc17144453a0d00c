"""Circle-point analysis (Stone 1987): joint axes from measurements moving one joint at a time.

For each joint ``j`` the robot moves only that joint while the target is measured. A revolute
joint carries the target around a circle: a plane fitted to the points (SVD) gives the axis
direction, a circle fitted in that plane (algebraic fit refined by Gauss-Newton) gives a point on
the axis (the centre); the direction's sign follows the way the readings turn. A prismatic joint
carries the target along a line (principal direction of the points). Sets are processed base
outwards: the axis of joint ``j`` measured with joints ``k < j`` at readings ``q_k`` is carried back
to all-zero readings through the already known axes, ``line_j(0) = (prod_k exp(S_k q_k))^-1
line_j(q)``. The axes at zero readings and the target position are a product-of-exponentials
model of the arm; Stone's S-model puts frame ``i`` on axis ``i + 1`` at its circle centre.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from robodyn.calibration.kinematics import hom, inv
from robodyn.calibration.nominal import (
    LinkParams,
    RobotGeometry,
    axis_frames,
    default_frame0,
    dh_link,
    frame_on_line,
    hayati_link,
    parallel_links,
)
from robodyn.robot.errors import InputError

__all__ = [
    "CircleFit",
    "CirclePointResult",
    "JointAxis",
    "arc_angles",
    "circle_point",
    "fit_circle",
    "fit_line",
    "fit_plane",
    "joint_axis",
    "register_lines",
]


def fit_plane(points: np.ndarray) -> tuple[np.ndarray, np.ndarray, float, np.ndarray]:
    """Least-squares plane through points of shape (M, 3).

    Returns
    -------
    centroid : numpy.ndarray, shape (3,)
    normal : numpy.ndarray, shape (3,)
        Unit normal (the direction of least spread).
    rms : float
        RMS distance of the points from the plane, m.
    spread : numpy.ndarray, shape (3,)
        Singular values of the centred points.
    """
    c = points.mean(axis=0)
    _, s, vt = np.linalg.svd(points - c, full_matrices=False)
    s = np.pad(s, (0, 3 - len(s)))
    return c, vt[-1] if vt.shape[0] == 3 else np.cross(vt[0], vt[1]), float(s[2] / np.sqrt(len(points))), s


@dataclass(frozen=True)
class CircleFit:
    """A circle in space.

    Attributes
    ----------
    center : numpy.ndarray, shape (3,)
    normal : numpy.ndarray, shape (3,)
        Unit normal of its plane.
    radius : float
        m.
    rms : float
        RMS distance of the points from the circle (in-plane and out-of-plane), m.
    """

    center: np.ndarray
    normal: np.ndarray
    radius: float
    rms: float


def fit_circle(points: np.ndarray) -> CircleFit:
    """Plane fit, then a circle in that plane (Kasa's algebraic fit refined by Gauss-Newton).

    Parameters
    ----------
    points : numpy.ndarray, shape (M, 3), M >= 3

    Returns
    -------
    CircleFit
    """
    c0, normal, _, _ = fit_plane(points)
    e1 = np.linalg.svd(points - c0, full_matrices=False)[2][0]
    e2 = np.cross(normal, e1)
    xy = np.column_stack(((points - c0) @ e1, (points - c0) @ e2))
    # x^2 + y^2 + D x + E y + F = 0, linear in D, E, F
    a = np.column_stack((xy, np.ones(len(xy))))
    sol, *_ = np.linalg.lstsq(a, -(xy**2).sum(axis=1), rcond=None)
    centre = -0.5 * sol[:2]
    radius = np.sqrt(max(centre @ centre - sol[2], 0.0))
    for _ in range(20):
        d = xy - centre
        dist = np.linalg.norm(d, axis=1)
        res = dist - radius  # geometric residual
        jac = np.column_stack((-d / dist[:, None], -np.ones(len(xy))))
        step, *_ = np.linalg.lstsq(jac, -res, rcond=None)
        centre, radius = centre + step[:2], radius + step[2]
        if np.linalg.norm(step) < 1e-15 * max(radius, 1.0):
            break
    d = xy - centre
    in_plane = np.linalg.norm(d, axis=1) - radius
    out = (points - c0) @ normal
    rms = float(np.sqrt(np.mean(in_plane**2 + out**2)))
    return CircleFit(c0 + centre[0] * e1 + centre[1] * e2, normal, float(abs(radius)), rms)


def fit_line(points: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """Least-squares line through points of shape (M, 3): centroid, unit direction, RMS distance."""
    c = points.mean(axis=0)
    _, s, vt = np.linalg.svd(points - c, full_matrices=False)
    rest = np.sqrt(np.sum(s[1:] ** 2) / len(points))
    return c, vt[0], float(rest)


@dataclass(frozen=True)
class JointAxis:
    """One joint axis as measured (at the readings of the other joints in its data set).

    Attributes
    ----------
    joint : str
    joint_type : str
    point : numpy.ndarray, shape (3,)
        Circle centre (revolute) or centroid of the points (prismatic), instrument frame, m.
    direction : numpy.ndarray, shape (3,)
        Unit axis, pointing the way increasing readings turn (slide).
    radius : float
        Circle radius, m (0 for prismatic joints).
    rms : float
        RMS distance of the points from the fitted circle (line), m.
    scale : float
        Fitted rotation (travel) per unit of reading: 1 for a correct joint scale.
    count : int
        Number of points.
    """

    joint: str
    joint_type: str
    point: np.ndarray
    direction: np.ndarray
    radius: float
    rms: float
    scale: float
    count: int


def joint_axis(q: np.ndarray, points: np.ndarray, joint_type: str, name: str = "joint") -> JointAxis:
    """Axis of one joint from its readings (M,) and the target positions (M, 3) it produced.

    Raises
    ------
    ValueError
        If the joint did not move, the points do not determine an axis (too few, collinear for a
        revolute joint, the target on the axis) or do not follow the readings.
    """
    q = np.asarray(q, dtype=float)
    points = np.asarray(points, dtype=float)
    need = 3 if joint_type == "revolute" else 2
    if len(points) < need:
        raise InputError(f"{name}: {len(points)} points; circle-point analysis of a {joint_type} joint "
                         f"needs at least {need}")
    if not np.ptp(q) > 1e-6:
        raise InputError(f"{name}: the joint never moved in its circle-point data set "
                         f"(readings span {np.ptp(q):.3g}); its axis cannot be recovered")
    order = np.argsort(q)
    q, points = q[order], points[order]
    if joint_type == "prismatic":
        c, u, rms = fit_line(points)
        s = (points - c) @ u
        slope = np.polyfit(q, s, 1)[0]
        if slope < 0:
            u, slope = -u, -slope
        _check_scale(name, slope, "m per m of reading")
        return JointAxis(name, joint_type, c, u, 0.0, rms, float(slope), len(points))
    _, _, _, spread = fit_plane(points)
    if not spread[1] > 1e-6 * spread[0] or not spread[0] > 0:
        raise InputError(f"{name}: the measured points are (nearly) collinear, so they fix no circle "
                         "(the target is on the joint axis, or the arc is too short)")
    circle = fit_circle(points)
    n = circle.normal
    e1 = np.linalg.svd(points - circle.center, full_matrices=False)[2][0]
    e1 = e1 - (e1 @ n) * n
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n, e1)
    d = points - circle.center
    phi = arc_angles(q, np.arctan2(d @ e2, d @ e1))
    slope = np.polyfit(q, phi, 1)[0]
    if slope < 0:
        n, slope = -n, -slope
    gap = float(np.max(np.diff(q)))
    _check_scale(name, slope, "rad of arc per rad of reading",
                 "" if gap < np.pi else
                 f"; its readings are up to {np.degrees(gap):.0f} deg apart, so the arc between two "
                 "of them is ambiguous: measure the sweep in steps under 180 deg (readings as "
                 "given, multi-turn values are fine), or check that the readings are in the "
                 "declared angle unit")
    return JointAxis(name, joint_type, circle.center, n, circle.radius, circle.rms, float(slope),
                     len(points))


def arc_angles(q: np.ndarray, phi: np.ndarray, tol: float = 0.5) -> np.ndarray:
    """Continuous arc angles (M,) of a target circling a revolute joint, from readings (M,) sorted.

    ``phi`` (M,) are the measured angles wrapped to (-pi, pi]. Multi-turn sweeps (beyond
    +-180 deg) and sparse sweeps (steps over 180 deg) are unwrapped with the readings as given:
    the arc angle is ``+-q + c`` up to calibration errors, so ``phi`` minus that line is wrapped
    and added back. When neither sense fits within ``tol`` rad RMS (readings of another scale),
    neighbouring samples are unwrapped instead (:func:`numpy.unwrap`), which needs steps under
    180 deg, and the scale check that follows says what is wrong.
    """
    best, best_rms = None, tol
    for sense in (1.0, -1.0):
        off = np.angle(np.exp(1j * (phi - sense * q)))  # wrapped phi - sense q
        c = np.angle(np.mean(np.exp(1j * off)))  # circular mean
        dev = np.angle(np.exp(1j * (off - c)))
        rms = float(np.sqrt(np.mean(dev**2)))
        if rms < best_rms:
            best, best_rms = sense * q + c + dev, rms
    return best if best is not None else np.unwrap(phi)


def _check_scale(name: str, scale: float, unit: str, hint: str = "") -> None:
    if not 0.8 < scale < 1.25:
        raise InputError(
            f"{name}: the target moved {scale:.3g} {unit}, not about 1: the data set does not move "
            "this joint alone, the readings have the wrong scale, or the target is too close to "
            f"the axis for its circle to be measured{hint}"
        )


def _exp(point: np.ndarray, direction: np.ndarray, joint_type: str, value: float) -> np.ndarray:
    """Rigid motion of a twist about / along a line by ``value``, shape (4, 4)."""
    if joint_type == "prismatic":
        return hom(None, direction * value)
    k = np.array([[0, -direction[2], direction[1]], [direction[2], 0, -direction[0]],
                  [-direction[1], direction[0], 0]])
    r = np.eye(3) + np.sin(value) * k + (1 - np.cos(value)) * k @ k  # Rodrigues
    return hom(r, point - r @ point)


def _motion(points: np.ndarray, dirs: np.ndarray, types: Sequence[str], q: np.ndarray) -> np.ndarray:
    """``prod_k exp(S_k q_k)`` over the given axes, shape (4, 4)."""
    t = np.eye(4)
    for p, u, jt, v in zip(points, dirs, types, q, strict=False):
        t = t @ _exp(p, u, jt, v)
    return t


def register_lines(nominal_points: np.ndarray, nominal_dirs: np.ndarray, points: np.ndarray,
                   dirs: np.ndarray, nominal_target: np.ndarray, target: np.ndarray) -> np.ndarray:
    """Rigid transform (4, 4) placing nominal joint axes on measured ones (least squares).

    Rotation from the axis directions and the common normals of consecutive axes (Kabsch), with
    the direction to the target as a weak tie-breaker; translation from the common-normal feet
    and the distances to the measured lines.
    """
    pairs_a, pairs_b, weights = list(nominal_dirs), list(dirs), [1.0] * len(dirs)
    feet_a, feet_b = [], []
    for i in range(len(dirs) - 1):
        fa = _feet(nominal_points[i], nominal_dirs[i], nominal_points[i + 1], nominal_dirs[i + 1])
        fb = _feet(points[i], dirs[i], points[i + 1], dirs[i + 1])
        if fa is not None and fb is not None:
            feet_a += list(fa)
            feet_b += list(fb)
            va, vb = fa[1] - fa[0], fb[1] - fb[0]
            if np.linalg.norm(va) > 1e-6 and np.linalg.norm(vb) > 1e-6:
                pairs_a.append(va / np.linalg.norm(va))
                pairs_b.append(vb / np.linalg.norm(vb))
                weights.append(1.0)
    ta = nominal_target - nominal_points[0]
    tb = target - points[0]
    pairs_a.append(ta - (ta @ nominal_dirs[0]) * nominal_dirs[0])
    pairs_b.append(tb - (tb @ dirs[0]) * dirs[0])
    weights.append(1e-3)
    h = sum(w * np.outer(a, b) for w, a, b in zip(weights, pairs_a, pairs_b, strict=True))
    u, _, vt = np.linalg.svd(h)
    dfix = np.diag([1.0, 1.0, np.sign(np.linalg.det(vt.T @ u.T))])
    r = vt.T @ dfix @ u.T
    # translation: sum |R a + t - b|^2 over feet + sum |P_i (R c_i + t - c'_i)|^2 + weak target term
    lhs = np.zeros((3, 3))
    rhs = np.zeros(3)
    for a, b in zip(feet_a, feet_b, strict=True):
        lhs += np.eye(3)
        rhs += b - r @ a
    for c, cb, u_b in zip(nominal_points, points, dirs, strict=True):
        p = np.eye(3) - np.outer(u_b, u_b)
        lhs += p
        rhs += p @ (cb - r @ c)
    lhs += 1e-3 * np.eye(3)
    rhs += 1e-3 * (target - r @ nominal_target)
    return hom(r, np.linalg.solve(lhs, rhs))


def _feet(p1, u1, p2, u2):
    """Closest points of two non-parallel lines, or None."""
    s = np.cross(u1, u2)
    if np.linalg.norm(s) < 1e-6:
        return None
    w0 = p1 - p2
    b, d, e = u1 @ u2, u1 @ w0, u2 @ w0
    den = 1 - b * b
    t1, t2 = (b * e - d) / den, (e - b * d) / den
    return p1 + t1 * u1, p2 + t2 * u2


@dataclass(frozen=True, eq=False)
class CirclePointResult:
    """Joint axes and target from circle-point analysis, and Stone's S-model of them.

    Attributes
    ----------
    axes : tuple of JointAxis
        Per joint, as fitted in its own data set.
    points, directions : numpy.ndarray, shape (n, 3)
        The axes at zero readings, instrument frame.
    centres : numpy.ndarray, shape (n, 3)
        The circle centres (prismatic: centroids) carried to zero readings.
    target : numpy.ndarray, shape (3,)
        Target position at zero readings (mean over all points), m.
    registration : numpy.ndarray, shape (4, 4)
        The robot's world frame in the instrument frame, from the nominal axes fitted onto the
        measured ones.
    s_model : dict of str to float
        Stone's S-model parameters (``joint.theta``, ``.d``, ``.a``, ``.alpha`` (``.beta_y`` at
        parallel axes), ``.b``, ``.beta``): frame ``i`` on axis ``i + 1`` at its circle centre.
    s_frames : numpy.ndarray, shape (n + 1, 4, 4)
        The S-model frames at zero readings.
    """

    axes: tuple[JointAxis, ...]
    points: np.ndarray
    directions: np.ndarray
    centres: np.ndarray
    target: np.ndarray
    registration: np.ndarray
    s_model: dict[str, float]
    s_frames: np.ndarray


def circle_point(
    geometry: RobotGeometry,
    sets: Sequence[tuple[np.ndarray, np.ndarray]],
    *,
    parallel_tol: float = np.radians(1.0),
    still: float = 1e-6,
) -> CirclePointResult:
    """Circle-point analysis of one data set per joint.

    Parameters
    ----------
    geometry : RobotGeometry
        The nominal robot (for joint types, names and the free choices of the S-model frames).
    sets : sequence of (q, points), length n
        ``sets[j]``: joint readings (M_j, n) in which only joint ``j`` moves, and the measured
        target positions (M_j, 3), instrument frame, m.
    parallel_tol : float
        Nominal axes closer than this to parallel (rad) use Hayati's link in the S-model.
    still : float
        Largest spread of a joint that is meant to stay still in a set (rad or m).

    Returns
    -------
    CirclePointResult
    """
    n = geometry.dof
    names, types = geometry.joint_names, geometry.joint_types
    if len(sets) != n:
        raise InputError(f"circle-point analysis needs one data set per joint ({n}), got {len(sets)}")
    checked = []
    for j, item in enumerate(sets):
        if len(item) != 2:
            raise InputError(f"circle-point set {j} ({names[j]}): expected (q, points)")
        q, pts = (np.asarray(a, dtype=float) for a in item)
        if q.ndim != 2 or q.shape[1] != n or pts.ndim != 2 or pts.shape[1] != 3 or len(q) != len(pts):
            raise InputError(f"circle-point set {j} ({names[j]}): q must be (M, {n}) and points (M, 3) "
                             f"with the same M; got {q.shape} and {pts.shape}")
        if not (np.all(np.isfinite(q)) and np.all(np.isfinite(pts))):
            raise InputError(f"circle-point set {j} ({names[j]}): NaN or infinite values")
        others = [k for k in range(n) if k != j and np.ptp(q[:, k]) > still]
        if others:
            raise InputError(f"circle-point set {j} ({names[j]}) also moves "
                             f"{', '.join(names[k] for k in others)}; each set must move one joint")
        checked.append((q, pts))
    axes, points, dirs, centres = [], np.zeros((n, 3)), np.zeros((n, 3)), np.zeros((n, 3))
    for j, (q, pts) in enumerate(checked):
        ax = joint_axis(q[:, j], pts, types[j], f"circle-point set {j} ({names[j]})")
        axes.append(ax)
        back = inv(_motion(points[:j], dirs[:j], types[:j], q[0, :j]))  # to zero readings
        points[j] = back[:3, :3] @ ax.point + back[:3, 3]
        dirs[j] = back[:3, :3] @ ax.direction
        centres[j] = points[j]
    targets = []
    for q, pts in checked:
        for qk, y in zip(q, pts, strict=True):
            t = inv(_motion(points, dirs, types, qk))
            targets.append(t[:3, :3] @ y + t[:3, 3])
    target = np.mean(targets, axis=0)
    reg = register_lines(geometry.points, geometry.directions, points, dirs,
                         geometry.target[:3, 3], target)
    s_model, s_frames = _s_model(geometry, reg, points, dirs, centres, parallel_tol)
    return CirclePointResult(tuple(axes), points, dirs, centres, target, reg, s_model, s_frames)


def _s_model(geometry: RobotGeometry, reg: np.ndarray, points: np.ndarray, dirs: np.ndarray,
             centres: np.ndarray, parallel_tol: float) -> tuple[dict[str, float], np.ndarray]:
    """Stone's S-model frames (origins at the circle centres) and parameters."""
    n = geometry.dof
    par = parallel_links(geometry.directions, parallel_tol)
    kinds = ["hayati" if p else "dh" for p in par]
    refs_nom = np.concatenate((geometry.base[None], geometry.link_frames))
    nominal, _ = axis_frames(geometry.points, geometry.directions, default_frame0(geometry), refs_nom,
                             kinds)
    refs = reg @ nominal
    frames = [frame_on_line(points[0], dirs[0], centres[0], refs[0][:3, 0])]
    values: dict[str, float] = {}
    for i in range(n):
        name = geometry.joint_names[i]
        prev = frames[-1]
        if i < n - 1:
            u = dirs[i + 1] / np.linalg.norm(dirs[i + 1])
            x_ref = refs[i + 1][:3, 0]
            if kinds[i] == "hayati":
                link = hayati_link(prev, points[i + 1], u, x_ref, f"S-model link {i + 1}")
            else:
                link = dh_link(prev, points[i + 1], u, x_ref)
            dh = prev @ link.matrix()
            s_frame = frame_on_line(points[i + 1], u, centres[i + 1], dh[:3, 0])
            screw = inv(dh) @ s_frame  # Tz(b) Rz(beta)
            b, beta = float(screw[2, 3]), float(np.arctan2(screw[1, 0], screw[0, 0]))
        else:
            link = LinkParams("dh", 0.0, 0.0, 0.0, 0.0)
            s_frame, b, beta = prev.copy(), 0.0, 0.0
        values[f"{name}.theta"] = link.theta
        if link.kind == "dh":
            values[f"{name}.d"] = link.d
        values[f"{name}.a"] = link.a
        values[f"{name}.alpha"] = link.alpha
        if link.kind == "hayati":
            values[f"{name}.beta_y"] = link.beta
        values[f"{name}.b"] = b
        values[f"{name}.beta"] = beta
        frames.append(s_frame)
    return values, np.array(frames)
