"""Joint placements: DH, modified DH and general origin + axis, as ``(pre, axis, post)``.

See :mod:`robodyn.robot.model` for the convention ``T(q) = pre @ motion(axis, q) @ post``.
"""

from __future__ import annotations

from collections.abc import Sequence

import sympy as sp

from robodyn import spatial as S

Placement = tuple[sp.ImmutableMatrix, sp.ImmutableMatrix, sp.ImmutableMatrix]
_Z = sp.ImmutableMatrix([0, 0, 1])


def from_dh(joint_type: str, a: S.Scalar, alpha: S.Scalar, d: S.Scalar, theta: S.Scalar) -> Placement:
    """Standard DH: link frame i = ``Rz(theta + q) Tz(d) Tx(a) Rx(alpha)`` (revolute).

    For a prismatic joint ``d`` becomes ``d + q``. ``theta`` and ``d`` are the joint's offsets.
    """
    if joint_type == "revolute":
        post = S.dh_standard(a, alpha, d, theta)
        return sp.ImmutableMatrix(sp.eye(4)), _Z, post
    # prismatic: Rz(theta) Tz(d) | Tz(q) | Tx(a) Rx(alpha)
    pre = sp.ImmutableMatrix(S.rot_h(S.rotz(theta)) * S.trans(0, 0, d))
    post = sp.ImmutableMatrix(S.trans(a, 0, 0) * S.rot_h(S.rotx(alpha)))
    return pre, _Z, post


def from_mdh(joint_type: str, a: S.Scalar, alpha: S.Scalar, d: S.Scalar, theta: S.Scalar) -> Placement:
    """Modified DH (Craig/Khalil): link frame i = ``Rx(alpha) Tx(a) Rz(theta + q) Tz(d)``."""
    pre = S.dh_modified(a, alpha, d, theta)
    return pre, _Z, sp.ImmutableMatrix(sp.eye(4))


def from_origin(xyz: Sequence[S.Scalar], rpy: Sequence[S.Scalar], axis: Sequence[S.Scalar]) -> Placement:
    """URDF-style: link frame i = ``origin(xyz, rpy) @ motion(axis, q)``; ``axis`` is normalised."""
    pre = S.transform(S.rpy_to_matrix(*rpy), xyz)
    u = sp.Matrix([sp.sympify(e) for e in axis])
    norm2 = sp.simplify((u.T * u)[0, 0])
    if norm2 != 1:
        u = u / sp.sqrt(norm2)
    return pre, sp.ImmutableMatrix(u), sp.ImmutableMatrix(sp.eye(4))
