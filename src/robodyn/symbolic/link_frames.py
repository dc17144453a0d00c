"""Link-frame geometry and chain-rule derivatives for the Lagrange and Kane formulations.

Both formulations are written as straight-line programs (:class:`~robodyn.symbolic.program.Recorder`):
every non-trivial quantity becomes a named intermediate, and derivatives (partial velocities,
time derivatives, ``dV/dq``, ``-dF*/dqdd``) are taken through the intermediates by the chain rule
instead of by differentiating expanded expressions, whose size grows exponentially with the
number of joints. Newton-Euler keeps its own geometry (:mod:`robodyn.symbolic.newton_euler`), so
that the formulations stay independent.

Notation for joint ``k`` (all vectors in link frame ``k`` unless noted)::

    R_k   rotation of frame k in frame k-1         = R_pre R_axis(q_k) R_post
    z_k   joint axis                               = R_post^T axis
    p_k   origin of the motion frame in frame k-1  = translation(pre)
    s_k   motion-frame origin -> frame k origin     = R_post^T t_post (+ q_k z_k if prismatic)
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import sympy as sp

from robodyn import spatial as S
from robodyn.robot.model import Robot
from robodyn.symbolic.kinematics import motion
from robodyn.symbolic.program import Recorder


@dataclass(frozen=True)
class JointFrames:
    """Joint-dependent and constant geometry of every joint (see the module notation).

    Attributes
    ----------
    rot, axis, pre, offset : tuples of matrices
        ``R_k`` (3, 3), ``z_k``, ``p_k`` and ``s_k`` (3, 1) per joint.
    prismatic : tuple of bool
    trig : dict
        ``cos(q_k) -> c_k`` and ``sin(q_k) -> s_k``: the recorded names of the joint functions.
    """

    rot: tuple[sp.ImmutableMatrix, ...]
    axis: tuple[sp.ImmutableMatrix, ...]
    pre: tuple[sp.ImmutableMatrix, ...]
    offset: tuple[sp.ImmutableMatrix, ...]
    prismatic: tuple[bool, ...]
    trig: dict[sp.Expr, sp.Expr]


def chain_program(robot: Robot, q: Sequence[sp.Symbol], qd: Sequence[sp.Symbol],
                  qdd: Sequence[sp.Symbol]) -> tuple[Recorder, JointFrames]:
    """Start a formulation's straight-line program: a recorder and the joint frames in it.

    Parameters
    ----------
    robot : Robot
        The serial chain; its parameter names are reserved too.
    q, qd, qdd : sequence of Symbol
        The n joint variables: positions (rad or m), their rates and second rates. Only ``q``
        enters the frames; all three names are reserved.

    Returns
    -------
    rec : Recorder
        Reserves the names of the joint variables and of the robot's parameters.
    geo : JointFrames
        :func:`joint_frames` of ``q``, its entries recorded in ``rec``.
    """
    rec = Recorder({s.name for s in (*q, *qd, *qdd)} | set(robot.parameters))
    return rec, joint_frames(robot, q, rec)


def joint_frames(robot: Robot, q: Sequence[sp.Expr], rec: Recorder) -> JointFrames:
    """Rotations ``R_k(q_k)`` (entries recorded), axes, offsets of every joint."""
    rots, axes, pres, offsets, pris = [], [], [], [], []
    trig: dict[sp.Expr, sp.Expr] = {}
    for k, (joint, qk) in enumerate(zip(robot.joints, q, strict=True), start=1):
        cos_q = sin_q = None
        if joint.type == "revolute":
            # c_k = cos(q_k), s_k = sin(q_k)
            cos_q, sin_q = rec.scalar(sp.cos(qk), f"c{k}"), rec.scalar(sp.sin(qk), f"s{k}")
            trig[sp.cos(qk)], trig[sp.sin(qk)] = cos_q, sin_q
        r_post = S.rotation(joint.post)
        # R_k = R_pre R_axis(q_k) R_post
        rot = S.rotation(joint.pre * motion(joint, qk, cos_q, sin_q) * joint.post)
        rots.append(rec.matrix(rot, f"R{k}"))
        z = sp.ImmutableMatrix(r_post.T * joint.axis)
        # s_k = R_post^T t_post (+ q_k z_k for prismatic)
        s_vec = r_post.T * S.translation(joint.post)
        if joint.type == "prismatic":
            s_vec = s_vec + qk * z
        axes.append(z)
        pres.append(S.translation(joint.pre))
        offsets.append(sp.ImmutableMatrix(s_vec))
        pris.append(joint.type == "prismatic")
    return JointFrames(tuple(rots), tuple(axes), tuple(pres), tuple(offsets), tuple(pris), trig)


def tangent(expr: sp.Expr, dvals: Mapping[sp.Symbol, sp.Expr],
            trig: Mapping[sp.Expr, sp.Expr]) -> sp.Expr:
    """Chain rule ``de = sum_a (de/da) da`` over the symbols ``a`` of ``expr`` with a tangent."""
    terms = [expr.diff(a) * dvals[a] for a in expr.free_symbols if a in dvals]
    # cos(q_k), sin(q_k) from differentiating c_k, s_k: back to the recorded names
    return sp.Add(*terms).xreplace(trig) if terms else sp.Integer(0)


def tangents(assignments: Sequence[tuple[sp.Symbol, sp.Expr]], seeds: Mapping[sp.Symbol, sp.Expr],
             rec: Recorder, suffix: str, trig: Mapping[sp.Expr, sp.Expr]) -> dict[sp.Symbol, sp.Expr]:
    """Forward-mode derivative of a straight-line program along the tangent ``seeds``.

    Parameters
    ----------
    assignments : sequence of (Symbol, Expr)
        The program, in evaluation order.
    seeds : mapping
        Tangent of each independent variable (e.g. ``{qd_r: 1}`` for ``d/dqd_r``, or
        ``{q_k: qd_k, qd_k: qdd_k}`` for the time derivative along a motion).
    rec : Recorder
        Receives the non-trivial tangents as ``<symbol>_<suffix>``.
    trig : mapping
        ``cos(q_k) -> c_k``, ``sin(q_k) -> s_k`` (see :class:`JointFrames`).

    Returns
    -------
    dict
        The seeds and the non-zero tangent of every assignment that depends on them.
    """
    dvals: dict[sp.Symbol, sp.Expr] = dict(seeds)
    for sym, expr in assignments:
        # ds = sum_a (de/da) da
        d = tangent(expr, dvals, trig)
        if d != 0:
            dvals[sym] = rec.scalar(d, f"{sym.name}_{suffix}")
    return dvals


def tangent_matrix(mat: sp.MatrixBase, dvals: Mapping[sp.Symbol, sp.Expr],
                   trig: Mapping[sp.Expr, sp.Expr]) -> sp.ImmutableMatrix:
    """:func:`tangent` of every entry of a matrix."""
    return sp.ImmutableMatrix(mat.applyfunc(lambda e: tangent(e, dvals, trig)))
