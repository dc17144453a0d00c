"""Rotations, homogeneous transforms and cross products for floats and SymPy alike.

Every function takes plain numbers or SymPy expressions and returns a SymPy ``ImmutableMatrix``;
exact arguments (``pi/2``, ``0``, ``1``) fold to exact zeros and ones, which keeps generated
equations short. Convert to NumPy with ``numpy.array(m, dtype=float)`` when numbers are wanted.
"""

from __future__ import annotations

from collections.abc import Sequence

import sympy as sp

Scalar = float | int | sp.Expr
Mat = sp.ImmutableMatrix


def _trig(angle: Scalar) -> tuple[sp.Expr, sp.Expr]:
    """cos and sin of an angle, exact where possible."""
    a = sp.sympify(angle)
    return sp.cos(a), sp.sin(a)


def rotx(angle: Scalar) -> Mat:
    """Rotation about x by ``angle`` (rad), shape (3, 3)."""
    c, s = _trig(angle)
    return Mat([[1, 0, 0], [0, c, -s], [0, s, c]])


def roty(angle: Scalar) -> Mat:
    """Rotation about y by ``angle`` (rad), shape (3, 3)."""
    c, s = _trig(angle)
    return Mat([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def rotz(angle: Scalar) -> Mat:
    """Rotation about z by ``angle`` (rad), shape (3, 3)."""
    c, s = _trig(angle)
    return Mat([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def rpy_to_matrix(roll: Scalar, pitch: Scalar, yaw: Scalar) -> Mat:
    """URDF fixed-axis roll-pitch-yaw: ``Rz(yaw) @ Ry(pitch) @ Rx(roll)``, shape (3, 3)."""
    return Mat(rotz(yaw) * roty(pitch) * rotx(roll))


def skew(v: Sequence[Scalar] | Mat) -> Mat:
    """Cross-product matrix ``[v]x`` with ``skew(v) @ w == cross(v, w)``, shape (3, 3)."""
    x, y, z = (sp.sympify(e) for e in v)
    return Mat([[0, -z, y], [z, 0, -x], [-y, x, 0]])


def cross(a: Sequence[Scalar] | Mat, b: Sequence[Scalar] | Mat) -> Mat:
    """Cross product of two 3-vectors, shape (3, 1)."""
    a0, a1, a2 = (sp.sympify(e) for e in a)
    b0, b1, b2 = (sp.sympify(e) for e in b)
    return Mat([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0])


def axis_angle(axis: Sequence[Scalar] | Mat, angle: Scalar) -> Mat:
    """Rotation by ``angle`` about the unit vector ``axis`` (Rodrigues), shape (3, 3).

    Coordinate axes give exactly :func:`rotx`, :func:`roty`, :func:`rotz`.
    """
    u = [sp.sympify(e) for e in axis]
    if u == [1, 0, 0]:
        return rotx(angle)
    if u == [0, 1, 0]:
        return roty(angle)
    if u == [0, 0, 1]:
        return rotz(angle)
    c, s = _trig(angle)
    k = skew(u)
    uu = Mat(u) * Mat(u).T
    # R = c I + s [u]x + (1 - c) u u^T
    return Mat(c * sp.eye(3) + s * k + (1 - c) * uu)


def transform(rotation: Mat | None = None, translation: Sequence[Scalar] | Mat | None = None) -> Mat:
    """Homogeneous transform from a (3, 3) rotation and a 3-vector translation, shape (4, 4)."""
    t = sp.eye(4)
    if rotation is not None:
        t[:3, :3] = rotation
    if translation is not None:
        t[:3, 3] = Mat([sp.sympify(e) for e in translation])
    return Mat(t)


def trans(x: Scalar = 0, y: Scalar = 0, z: Scalar = 0) -> Mat:
    """Pure translation, shape (4, 4)."""
    return transform(None, (x, y, z))


def rot_h(rotation: Mat) -> Mat:
    """Pure rotation as a homogeneous transform, shape (4, 4)."""
    return transform(rotation, None)


def inverse(t: Mat) -> Mat:
    """Inverse of a homogeneous transform, shape (4, 4), without a general matrix inverse."""
    r = t[:3, :3]
    p = t[:3, 3]
    return transform(r.T, -r.T * p)


def rotation(t: Mat) -> Mat:
    """Rotation block of a homogeneous transform, shape (3, 3)."""
    return Mat(t[:3, :3])


def translation(t: Mat) -> Mat:
    """Translation block of a homogeneous transform, shape (3, 1)."""
    return Mat(t[:3, 3])


def dh_standard(a: Scalar, alpha: Scalar, d: Scalar, theta: Scalar) -> Mat:
    """Standard (distal) DH link transform ``Rz(theta) Tz(d) Tx(a) Rx(alpha)``, shape (4, 4)."""
    return Mat(rot_h(rotz(theta)) * trans(0, 0, d) * trans(a, 0, 0) * rot_h(rotx(alpha)))


def dh_modified(a: Scalar, alpha: Scalar, d: Scalar, theta: Scalar) -> Mat:
    """Modified (proximal, Craig/Khalil) DH transform ``Rx(alpha) Tx(a) Rz(theta) Tz(d)``, (4, 4)."""
    return Mat(rot_h(rotx(alpha)) * trans(a, 0, 0) * rot_h(rotz(theta)) * trans(0, 0, d))
