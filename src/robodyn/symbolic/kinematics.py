"""Forward kinematics of every frame and geometric Jacobians, symbolic or numeric.

Functions take a :class:`~robodyn.robot.model.Robot` and a sequence of joint values (SymPy symbols
or numbers) and return SymPy matrices.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import sympy as sp

from robodyn import spatial as S
from robodyn.robot.model import Joint, Robot
from robodyn.symbolic.program import Recorder


def joint_symbols(n: int) -> tuple[tuple[sp.Symbol, ...], tuple[sp.Symbol, ...], tuple[sp.Symbol, ...]]:
    """Joint positions ``q1..qn``, velocities ``qd1..qdn`` and accelerations ``qdd1..qddn``."""
    q = tuple(sp.Symbol(f"q{i + 1}", real=True) for i in range(n))
    qd = tuple(sp.Symbol(f"qd{i + 1}", real=True) for i in range(n))
    qdd = tuple(sp.Symbol(f"qdd{i + 1}", real=True) for i in range(n))
    return q, qd, qdd


def motion(joint: Joint, q: sp.Expr, cos_q: sp.Expr | None = None,
           sin_q: sp.Expr | None = None) -> sp.ImmutableMatrix:
    """The joint's motion transform: rotation about / translation along its axis, shape (4, 4).

    ``cos_q`` and ``sin_q`` may be passed to use named variables instead of ``cos(q)``.
    """
    if joint.type == "prismatic":
        return S.trans(*(joint.axis * q))
    rot = S.axis_angle(joint.axis, q)
    if cos_q is not None:
        rot = rot.xreplace({sp.cos(q): cos_q, sp.sin(q): sin_q})
    return S.rot_h(rot)


def link_transform(joint: Joint, q: sp.Expr) -> sp.ImmutableMatrix:
    """Pose of the joint's link frame in its parent link frame: ``pre @ motion(q) @ post``."""
    return sp.ImmutableMatrix(joint.pre * motion(joint, q) * joint.post)


@dataclass(frozen=True)
class Kinematics:
    """Poses along the chain, all in the world frame.

    Attributes
    ----------
    links : tuple of (4, 4) matrices
        Pose of each link frame.
    joint_frames : tuple of (4, 4) matrices
        Pose of each joint's motion frame (after ``pre``, before the motion).
    end_effector : (4, 4) matrix
        Pose of the tool frame.
    """

    links: tuple[sp.ImmutableMatrix, ...]
    joint_frames: tuple[sp.ImmutableMatrix, ...]
    end_effector: sp.ImmutableMatrix


def forward_kinematics(robot: Robot, q: Sequence[sp.Expr], rec: Recorder | None = None) -> Kinematics:
    """Poses of every link frame, joint frame and the tool in the world frame.

    With a :class:`~robodyn.symbolic.program.Recorder` every pose entry becomes an intermediate
    variable (``T3_14``: link 3, row 1, column 4), which keeps the cost linear in the joint count.
    """
    def keep(mat: sp.MatrixBase, name: str) -> sp.ImmutableMatrix:
        return sp.ImmutableMatrix(mat) if rec is None else rec.matrix(mat, name)

    t = sp.ImmutableMatrix(robot.base)
    links, joints = [], []
    for k, (joint, qi) in enumerate(zip(robot.joints, q, strict=True), start=1):
        # T_joint = T_{i-1} pre_i
        jf = keep(t * joint.pre, f"Tj{k}")
        joints.append(jf)
        cos_q = sin_q = None
        if rec is not None and joint.type == "revolute":
            cos_q, sin_q = rec.scalar(sp.cos(qi), f"c{k}"), rec.scalar(sp.sin(qi), f"s{k}")
        # T_i = T_joint motion(q_i) post_i
        t = keep(jf * motion(joint, qi, cos_q, sin_q) * joint.post, f"T{k}")
        links.append(t)
    return Kinematics(tuple(links), tuple(joints), keep(t * robot.tool, "Ttool"))


def joint_axes_world(robot: Robot, kin: Kinematics) -> list[sp.ImmutableMatrix]:
    """Unit joint axes in the world frame, each shape (3, 1)."""
    return [sp.ImmutableMatrix(S.rotation(jf) * j.axis) for j, jf in zip(robot.joints, kin.joint_frames,
                                                                           strict=True)]


def point_jacobian(robot: Robot, kin: Kinematics, point: sp.MatrixBase, upto: int) -> sp.ImmutableMatrix:
    """Geometric Jacobian ``[v; omega] = J qd`` of a point moving with link ``upto - 1``.

    Parameters
    ----------
    point : (3, 1) matrix
        The point in the world frame (a function of q).
    upto : int
        Number of joints that move the point (joints ``upto..n-1`` give zero columns).

    Returns
    -------
    (6, n) matrix: linear velocity rows first, then angular velocity, world frame.
    """
    n = robot.dof
    jac = sp.zeros(6, n)
    axes = joint_axes_world(robot, kin)
    for i in range(upto):
        z = axes[i]
        if robot.joints[i].type == "prismatic":
            jac[:3, i] = z
        else:
            origin = S.translation(kin.joint_frames[i])
            # v = z x (p - o_i), omega = z
            jac[:3, i] = S.cross(z, point - origin)
            jac[3:, i] = z
    return sp.ImmutableMatrix(jac)


def end_effector_jacobian(robot: Robot, kin: Kinematics) -> sp.ImmutableMatrix:
    """Geometric Jacobian of the tool frame origin, shape (6, n), world frame, ``[v; omega]``."""
    return point_jacobian(robot, kin, S.translation(kin.end_effector), robot.dof)
