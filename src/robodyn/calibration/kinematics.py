"""Vectorised forward kinematics of a chain of elementary transforms, with analytic Jacobians.

Every calibration error model (:mod:`robodyn.calibration.models`) is a fixed sequence of
elementary transforms ("ops"): a rotation about, or a translation along, one axis of the current
frame, or a constant 4x4 transform. The value of an elementary op is::

    value = sign * p[param] + q[:, joint]          (either term may be absent)

so a revolute DH joint is ``rz(theta + q)``, a link length ``tx(a)`` and a POE twist frame
``tx(u) ... rz(q) ... tx(-u)``. The end of the chain is the measured target frame.

Jacobians are geometric: an op turning the frame about its local axis ``k`` moves the target point
``p`` by ``z x (p - o)`` per radian, where ``z`` is that axis in the world and ``o`` the frame
origin; a translation moves it by ``z`` per metre (Hayati & Mirmirani 1985; the "standard
geometric approach"). Orientation rows are ``z`` for rotations and zero for translations.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

__all__ = ["ChainEval", "Op", "evaluate", "hom", "inv", "rot", "trans"]

_AXIS = {"rx": 0, "ry": 1, "rz": 2, "tx": 0, "ty": 1, "tz": 2}


@dataclass(frozen=True, eq=False)
class Op:
    """One elementary transform of a chain.

    Attributes
    ----------
    kind : {"rx", "ry", "rz", "tx", "ty", "tz", "fixed"}
        Rotation about (rad) or translation along (m) a local axis, or a constant transform.
    param : int
        Index of the parameter that enters the value, or -1.
    sign : float
        Multiplier of the parameter (POE twist frames use +1 and -1).
    joint : int
        Index of the joint whose reading is added to the value, or -1.
    matrix : numpy.ndarray or None, shape (4, 4)
        The constant transform of a ``"fixed"`` op.
    """

    kind: str
    param: int = -1
    sign: float = 1.0
    joint: int = -1
    matrix: np.ndarray | None = None


@dataclass(frozen=True, eq=False)
class ChainEval:
    """Target frame and derivatives for a batch of joint readings.

    Attributes
    ----------
    position : numpy.ndarray, shape (N, 3)
        Target position, m.
    rotation : numpy.ndarray, shape (N, 3, 3)
        Target orientation.
    jac_param : numpy.ndarray or None, shape (N, 6, P)
        ``d[position; rotation vector] / d params``: rows 0-2 in m per unit, rows 3-5 the
        angular (small rotation, world frame) rows in rad per unit.
    jac_joint : numpy.ndarray or None, shape (N, 6, n)
        The same with respect to the joint readings.
    """

    position: np.ndarray
    rotation: np.ndarray
    jac_param: np.ndarray | None
    jac_joint: np.ndarray | None


def rot(axis: str, angle: float) -> np.ndarray:
    """Homogeneous rotation about ``"x"``, ``"y"`` or ``"z"`` by ``angle`` (rad), shape (4, 4)."""
    k = "xyz".index(axis)
    i, j = (k + 1) % 3, (k + 2) % 3
    c, s = np.cos(angle), np.sin(angle)
    m = np.eye(4)
    # R = [.. c -s ..; .. s c ..] in the (i, j) plane
    m[i, i], m[i, j], m[j, i], m[j, j] = c, -s, s, c
    return m


def trans(x: float = 0.0, y: float = 0.0, z: float = 0.0) -> np.ndarray:
    """Homogeneous translation, shape (4, 4)."""
    m = np.eye(4)
    m[:3, 3] = (x, y, z)
    return m


def hom(rotation: np.ndarray | None = None, translation: Sequence[float] | None = None) -> np.ndarray:
    """Homogeneous transform from a (3, 3) rotation and a 3-vector, shape (4, 4)."""
    m = np.eye(4)
    if rotation is not None:
        m[:3, :3] = rotation
    if translation is not None:
        m[:3, 3] = translation
    return m


def inv(t: np.ndarray) -> np.ndarray:
    """Inverse of homogeneous transforms, shape (..., 4, 4)."""
    r = np.swapaxes(t[..., :3, :3], -1, -2)
    out = np.zeros_like(t)
    out[..., :3, :3] = r
    # p' = -R^T p
    out[..., :3, 3] = -np.einsum("...ij,...j->...i", r, t[..., :3, 3])
    out[..., 3, 3] = 1.0
    return out


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise cross product of (N, 3) arrays."""
    return np.stack(
        (a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1],
         a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2],
         a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]),
        axis=1,
    )


def evaluate(
    ops: Sequence[Op],
    params: np.ndarray,
    q: np.ndarray,
    n_params: int | None = None,
    *,
    derivatives: bool = True,
    frames_after: Sequence[int] = (),
) -> tuple[ChainEval, list[np.ndarray]]:
    """Run the chain for every row of ``q``.

    Parameters
    ----------
    ops : sequence of Op
    params : numpy.ndarray, shape (P,)
        Parameter values (m, rad).
    q : numpy.ndarray, shape (N, n)
        Joint readings (rad, m).
    n_params : int, optional
        Width of the parameter Jacobian (default ``len(params)``).
    derivatives : bool
        Compute ``jac_param`` and ``jac_joint``.
    frames_after : sequence of int
        Op indices after which the running frame is recorded.

    Returns
    -------
    ChainEval
    list of numpy.ndarray, each shape (N, 4, 4)
        The recorded frames, in the order of ``frames_after``.
    """
    q = np.asarray(q, dtype=float)
    params = np.asarray(params, dtype=float)
    big_n, n = q.shape
    n_params = len(params) if n_params is None else n_params
    r = np.broadcast_to(np.eye(3), (big_n, 3, 3)).copy()
    t = np.zeros((big_n, 3))
    records: list[tuple[Op, bool, np.ndarray, np.ndarray | None]] = []
    wanted = {k: None for k in frames_after}
    for index, op in enumerate(ops):
        if op.kind == "fixed":
            m = op.matrix
            t = t + r @ m[:3, 3]  # p' = p + R m_p
            r = r @ m[:3, :3]  # R' = R m_R
        else:
            value = op.sign * params[op.param] if op.param >= 0 else 0.0
            if op.joint >= 0:
                value = value + q[:, op.joint]
            k = _AXIS[op.kind]
            axis = r[:, :, k].copy()
            if op.kind[0] == "r":
                if derivatives and (op.param >= 0 or op.joint >= 0):
                    records.append((op, True, axis, t))
                i, j = (k + 1) % 3, (k + 2) % 3
                c, s = np.cos(value), np.sin(value)
                if np.ndim(value):
                    c, s = c[:, None], s[:, None]
                ci, cj = r[:, :, i].copy(), r[:, :, j]
                # columns i, j of R Rk(value): c_i' = c c_i + s c_j, c_j' = c c_j - s c_i
                r[:, :, i] = c * ci + s * cj
                r[:, :, j] = c * cj - s * ci
            else:
                if derivatives and (op.param >= 0 or op.joint >= 0):
                    records.append((op, False, axis, None))
                v = value[:, None] if np.ndim(value) else value
                t = t + v * axis  # p' = p + value z
        if index in wanted:
            frame = np.zeros((big_n, 4, 4))
            frame[:, :3, :3], frame[:, :3, 3], frame[:, 3, 3] = r, t, 1.0
            wanted[index] = frame
    jp = jq = None
    if derivatives:
        jp = np.zeros((big_n, 6, n_params))
        jq = np.zeros((big_n, 6, n))
        for op, is_rot, axis, origin in records:
            if is_rot:
                lin = _cross(axis, t - origin)  # dp = z x (p - o)
                ang = axis  # dw = z
            else:
                lin, ang = axis, None  # dp = z
            if op.param >= 0:
                jp[:, :3, op.param] += op.sign * lin
                if ang is not None:
                    jp[:, 3:, op.param] += op.sign * ang
            if op.joint >= 0:
                jq[:, :3, op.joint] += lin
                if ang is not None:
                    jq[:, 3:, op.joint] += ang
    return ChainEval(t, r, jp, jq), [wanted[k] for k in frames_after]
