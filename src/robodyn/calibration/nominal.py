"""Nominal geometry of a robot and the convention-specific frames built from its joint axes.

A :class:`~robodyn.robot.model.Robot` places joint ``i`` by ``pre_i @ motion(axis_i, q_i) @ post_i``
(SymPy, with named parameters at their defaults). Calibration works with numbers and with the
joint *axes* (lines in space at ``q = 0``): every error model is a different parametrisation of
the same chain of lines and the same target point. This module

* evaluates a robot at ``q = 0`` (:func:`robot_geometry`): link frames, joint frames, axis lines,
  tool frame, in the robot's world frame;
* builds frames with their z axis along the joint axes in a chosen convention
  (:func:`axis_frames`): standard Denavit-Hartenberg (Denavit & Hartenberg 1955) or, for
  (nearly) parallel consecutive axes, Hayati & Mirmirani (1985), returning each link's parameters.

Frame ``i`` (``i = 0..n``) has its z axis along joint ``i + 1``'s axis, pointing the way positive
joint motion turns (or slides); frame ``n`` has no next axis and is frame ``n - 1`` turned by the
last joint (all its parameters zero). Where a convention leaves a choice (the sign of ``x`` for
intersecting axes, ``x`` for coincident axes) the choice closest to a reference frame is taken,
so the frames follow the robot's own frames where those already obey the convention (the PUMA 560
description gives back its own DH table).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from robodyn.calibration.kinematics import hom, rot, trans
from robodyn.robot.errors import InputError
from robodyn.robot.numbers import RobotNumbers, robot_numbers

if TYPE_CHECKING:
    import sympy as sp

    from robodyn.robot.model import Robot

__all__ = [
    "LinkParams",
    "RobotGeometry",
    "axis_frames",
    "default_frame0",
    "dh_link",
    "frame_on_line",
    "hayati_link",
    "numeric",
    "parallel_links",
    "robot_geometry",
]

#: Below this sine of the angle between two axes they are treated as exactly parallel.
EXACT_PARALLEL = 1e-9


def numeric(matrix: sp.MatrixBase, subs: dict) -> np.ndarray:
    """A SymPy matrix with parameters at ``subs`` as a float array."""
    import sympy as sp  # only where a description's expressions are evaluated

    m = sp.Matrix(matrix).xreplace(subs)
    return np.array(m.evalf(), dtype=float)


@dataclass(frozen=True, eq=False)
class RobotGeometry:
    """A robot's kinematics at ``q = 0`` in numbers, world frame, metres.

    Attributes
    ----------
    joint_names, joint_types : tuple of str, length n
    base : numpy.ndarray, shape (4, 4)
        Chain base frame ``L_0`` (``robot.base``).
    joint_frames : numpy.ndarray, shape (n, 4, 4)
        Frame after ``pre_i`` (``W_i``); the joint moves about / along ``axes_local[i]`` in it.
    axes_local : numpy.ndarray, shape (n, 3)
        Unit joint axes in their joint frames.
    posts : numpy.ndarray, shape (n, 4, 4)
        ``post_i`` transforms.
    link_frames : numpy.ndarray, shape (n, 4, 4)
        Link frames ``L_i = W_i post_i``.
    tool : numpy.ndarray, shape (4, 4)
        ``robot.tool`` (tool frame in the last link frame).
    points, directions : numpy.ndarray, shape (n, 3)
        A point on each joint axis (the joint frame origin) and its unit direction, world frame.
    """

    joint_names: tuple[str, ...]
    joint_types: tuple[str, ...]
    base: np.ndarray
    joint_frames: np.ndarray
    axes_local: np.ndarray
    posts: np.ndarray
    link_frames: np.ndarray
    tool: np.ndarray
    points: np.ndarray
    directions: np.ndarray

    @property
    def dof(self) -> int:
        """Number of joints."""
        return len(self.joint_names)

    @property
    def target(self) -> np.ndarray:
        """Tool frame in the world at ``q = 0``, shape (4, 4)."""
        return self.link_frames[-1] @ self.tool


def robot_geometry(robot: Robot | RobotNumbers) -> RobotGeometry:
    """Evaluate ``robot`` at ``q = 0`` with its parameters at their defaults."""
    num = robot_numbers(robot)
    frame = num.base
    joint_frames, axes, links = [], [], []
    for name, pre, axis, post in zip(num.joint_names, num.pres, num.axes, num.posts, strict=True):
        w = frame @ pre
        norm = np.linalg.norm(axis)
        if not norm > 0:
            raise InputError(f"{num.source}: joint {name!r} has a zero axis")
        frame = w @ post
        joint_frames.append(w)
        axes.append(axis / norm)
        links.append(frame)
    jf = np.array(joint_frames)
    ax = np.array(axes)
    return RobotGeometry(
        joint_names=num.joint_names,
        joint_types=num.joint_types,
        base=np.array(num.base),
        joint_frames=jf,
        axes_local=ax,
        posts=np.array(num.posts),
        link_frames=np.array(links),
        tool=np.array(num.tool),
        points=jf[:, :3, 3].copy(),
        directions=np.einsum("nij,nj->ni", jf[:, :3, :3], ax),
    )


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def _perpendicular(hint: np.ndarray, z: np.ndarray, fallback: np.ndarray | None = None) -> np.ndarray:
    """``hint`` projected onto the plane normal to unit ``z`` and normalised (never zero)."""
    for cand in (hint, fallback, np.eye(3)[0], np.eye(3)[1], np.eye(3)[2]):
        if cand is None:
            continue
        v = cand - (cand @ z) * z
        if np.linalg.norm(v) > 1e-6:
            return _unit(v)
    raise AssertionError("unreachable: some basis vector is not parallel to z")


def frame_on_line(point: np.ndarray, direction: np.ndarray, origin_hint: np.ndarray,
                  x_hint: np.ndarray) -> np.ndarray:
    """Frame with z along a line, origin at the foot of ``origin_hint``, x nearest ``x_hint``.

    Parameters
    ----------
    point, direction : numpy.ndarray, shape (3,)
        The line (``direction`` need not be unit).
    origin_hint, x_hint : numpy.ndarray, shape (3,)

    Returns
    -------
    numpy.ndarray, shape (4, 4)
    """
    z = _unit(direction)
    origin = point + ((origin_hint - point) @ z) * z  # foot of the perpendicular
    x = _perpendicular(x_hint, z)
    return hom(np.column_stack((x, np.cross(z, x), z)), origin)


@dataclass(frozen=True)
class LinkParams:
    """Parameters of one link transform ``F_{i-1}^{-1} F_i`` (m, rad).

    ``kind`` is ``"dh"``: ``Rz(theta) Tz(d) Tx(a) Rx(alpha)``; or ``"hayati"``:
    ``Rz(theta) Tx(a) Rx(alpha) Ry(beta)`` (``d`` is then zero by construction).
    """

    kind: str
    theta: float
    d: float
    a: float
    alpha: float
    beta: float = 0.0

    def matrix(self) -> np.ndarray:
        """The link transform, shape (4, 4)."""
        if self.kind == "dh":
            return rot("z", self.theta) @ trans(z=self.d) @ trans(x=self.a) @ rot("x", self.alpha)
        return (rot("z", self.theta) @ trans(z=self.d) @ trans(x=self.a) @ rot("x", self.alpha)
                @ rot("y", self.beta))


def _angle_about(u: np.ndarray, v: np.ndarray, axis: np.ndarray) -> float:
    """Signed angle turning ``u`` into ``v`` about ``axis`` (both perpendicular to it)."""
    return float(np.arctan2(np.cross(u, v) @ axis, u @ v))


def dh_link(prev: np.ndarray, point: np.ndarray, u: np.ndarray, x_ref: np.ndarray) -> LinkParams:
    """Standard DH link from frame ``prev`` (z along axis i) to the line ``(point, u)``."""
    o, x0, z0 = prev[:3, 3], prev[:3, 0], prev[:3, 2]
    s = np.cross(z0, u)
    if np.linalg.norm(s) > EXACT_PARALLEL:
        # closest points o + t1 z0 and point + t2 u (common normal), s = z0 x u, w = point - o:
        # t1 = (w x u) . s / |s|^2, t2 = (w x z0) . s / |s|^2 (no cancellation near parallel)
        w = point - o
        den = s @ s
        t1 = np.cross(w, u) @ s / den
        t2 = np.cross(w, z0) @ s / den
        p1, p2 = o + t1 * z0, point + t2 * u
        x = _unit(s)  # the common normal's direction, exactly perpendicular to both axes
        if x @ x_ref < 0:
            x = -x
        d = float(t1)
    else:
        # parallel: the common normal through o (d = 0)
        foot = point + ((o - point) @ u) * u
        p2 = foot
        normal = foot - o
        x = _unit(normal) if np.linalg.norm(normal) > 1e-12 else _perpendicular(x_ref, z0, x0)
        if x @ x_ref < 0:
            x = -x
        d = 0.0
        p1 = o
    theta = _angle_about(x0, x, z0)
    a = float((p2 - p1) @ x)
    alpha = _angle_about(z0, u, x)
    return LinkParams("dh", theta, d, a, alpha)


def hayati_link(prev: np.ndarray, point: np.ndarray, u: np.ndarray, x_ref: np.ndarray,
                 where: str) -> LinkParams:
    """Hayati link from ``prev`` to a (nearly) parallel line: origin in the plane through ``o``."""
    o, x0, z0 = prev[:3, 3], prev[:3, 0], prev[:3, 2]
    den = u @ z0
    if abs(den) < 0.5:
        raise InputError(f"{where}: Hayati's parametrisation needs (nearly) parallel axes; these are "
                         f"{np.degrees(np.arccos(np.clip(abs(den), 0, 1))):.1f} degrees apart")
    # the axis meets the plane through o normal to z0 at o_i
    o_i = point + ((o - point) @ z0 / den) * u
    normal = o_i - o
    x = _unit(normal) if np.linalg.norm(normal) > 1e-12 else _perpendicular(x_ref, z0, x0)
    if x @ x_ref < 0:
        x = -x
    theta = _angle_about(x0, x, z0)
    a = float(normal @ x)
    y = np.cross(z0, x)
    w = np.array([u @ x, u @ y, u @ z0])
    # Rx(alpha) Ry(beta) e_z = (sin b, -sin a cos b, cos a cos b)
    beta = float(np.arcsin(np.clip(w[0], -1.0, 1.0)))
    alpha = float(np.arctan2(-w[1], w[2]))
    return LinkParams("hayati", theta, 0.0, a, alpha, beta)


def axis_frames(
    points: np.ndarray,
    directions: np.ndarray,
    frame0: np.ndarray,
    references: np.ndarray,
    kinds: Sequence[str],
    *,
    where: str = "robot",
) -> tuple[np.ndarray, list[LinkParams]]:
    """Frames along the joint axes in the DH (or Hayati) convention, and their parameters.

    Parameters
    ----------
    points, directions : numpy.ndarray, shape (n, 3)
        The joint axes at ``q = 0``: a point on each and its direction (positive motion).
    frame0 : numpy.ndarray, shape (4, 4)
        Frame 0; its z axis must lie along axis 1 (see :func:`frame_on_line`).
    references : numpy.ndarray, shape (n + 1, 4, 4)
        Frames whose x axes decide the free choices (signs, coincident axes).
    kinds : sequence of str, length n
        ``"dh"`` or ``"hayati"`` for the link transform ``i = 1..n`` (the last one is ignored:
        link ``n`` has all parameters zero).
    where : str
        Names the robot in error messages.

    Returns
    -------
    frames : numpy.ndarray, shape (n + 1, 4, 4)
        ``F_0 .. F_n`` at ``q = 0``; ``F_i = F_{i-1} @ params[i-1].matrix()``.
    params : list of LinkParams, length n
    """
    n = len(points)
    frames = [np.asarray(frame0, dtype=float)]
    params: list[LinkParams] = []
    for i in range(1, n):
        prev = frames[-1]
        u = _unit(directions[i])
        x_ref = references[i][:3, 0]
        if kinds[i - 1] == "hayati":
            link = hayati_link(prev, points[i], u, x_ref, f"{where}: link {i}")
        else:
            link = dh_link(prev, points[i], u, x_ref)
        params.append(link)
        frames.append(prev @ link.matrix())
    params.append(LinkParams("dh", 0.0, 0.0, 0.0, 0.0))
    frames.append(frames[-1].copy())
    return np.array(frames), params


def parallel_links(directions: np.ndarray, tolerance: float) -> tuple[bool, ...]:
    """Whether joint axes ``i`` and ``i + 1`` are within ``tolerance`` rad of (anti)parallel.

    Returns a tuple of length n (the last entry is False: there is no axis after the last).
    """
    out = []
    for i in range(len(directions) - 1):
        c = abs(_unit(directions[i]) @ _unit(directions[i + 1]))
        out.append(bool(np.arccos(np.clip(c, -1.0, 1.0)) < tolerance))
    return (*out, False)


def default_frame0(geometry: RobotGeometry) -> np.ndarray:
    """Frame 0 on joint 1's axis nearest the chain base frame, x nearest the base's x."""
    b = geometry.base
    return frame_on_line(geometry.points[0], geometry.directions[0], b[:3, 3], b[:3, 0])
