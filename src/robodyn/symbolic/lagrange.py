"""Lagrange-Euler equations from kinetic and potential energy.

The kinetic energy ``T = qd^T M qd / 2`` gives ``M(q) = sum_k m_k Jv_k^T Jv_k + Jw_k^T I_k Jw_k``
from the centre-of-mass Jacobians of the links; ``C`` comes from the Christoffel symbols of ``M``
(:mod:`robodyn.symbolic.coriolis`) and ``g = dV/dq`` from the potential energy
``V = -sum_k m_k g . p_ck``.

The Jacobians are written in link-frame components (the energy does not depend on the frame):
column ``i`` of link ``k`` is ``[z_i x (c_k - o_i); z_i]`` for a revolute joint with axis ``z_i``
through the point ``o_i``, and ``[z_i; 0]`` for a prismatic joint, with ``z_i`` and ``o_i`` carried
outward from frame ``i`` to frame ``k``. The inertia ``I_k`` about the centre of mass ``c_k`` is then
constant, and ``M_ij`` depends on ``q_{min(i,j)+1} .. q_n`` only.

:func:`lagrange` keeps every quantity as a named intermediate (a straight-line program, see
:mod:`robodyn.symbolic.link_frames`) and differentiates through them by the chain rule: ``dV/dq``
and the Christoffel symbols then cost a multiple of the program, where expanded expressions grow
exponentially with the number of joints.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import sympy as sp

from robodyn import spatial as S
from robodyn.robot.model import Robot
from robodyn.symbolic.coriolis import christoffel_program
from robodyn.symbolic.link_frames import JointFrames, chain_program, tangent, tangents
from robodyn.symbolic.program import Program, Recorder


@dataclass(frozen=True)
class LagrangeTerms:
    """Lagrange's equations split into their parts.

    Attributes
    ----------
    mass_matrix : Program
        ``M(q)`` from the kinetic energy, shape (n, n).
    potential : Program
        ``V(q)``, shape (1, 1).
    gravity : Program
        ``g(q) = dV/dq``, shape (n, 1).
    coriolis : ImmutableMatrix
        ``C(q, qd)`` from the Christoffel symbols of ``M``, as expressions, shape (n, n).
    tau : ImmutableMatrix
        Rigid-body inverse dynamics ``M qdd + C qd + g`` as expressions, shape (n, 1).
    """

    mass_matrix: Program
    potential: Program
    gravity: Program
    coriolis: sp.ImmutableMatrix
    tau: sp.ImmutableMatrix


def _jacobian_columns(robot: Robot, geo: JointFrames, rec: Recorder
                      ) -> list[list[tuple[sp.ImmutableMatrix, sp.ImmutableMatrix | None]]]:
    """``cols[k][i] = (Jv, Jw)``: column ``i`` of link ``k``'s centre-of-mass Jacobian, frame ``k``.

    ``Jw`` is None for a prismatic joint.
    """
    n = robot.dof
    cols: list[list[tuple[sp.ImmutableMatrix, sp.ImmutableMatrix | None]]] = [[] for _ in range(n)]
    for i in range(n):
        # joint i's axis and a point on it (the motion-frame origin), in frame i
        z, o = geo.axis[i], -geo.offset[i]
        for k in range(i, n):
            if k > i:
                rt = geo.rot[k].T
                # carried to frame k: z <- R_k^T z
                z = rec.vector(rt * z, f"lz{i + 1}_{k + 1}")
                if not geo.prismatic[i]:
                    # o <- R_k^T (o - p_k) - s_k
                    o = rec.vector(rt * (o - geo.pre[k]) - geo.offset[k], f"lo{i + 1}_{k + 1}")
            if geo.prismatic[i]:
                # Jv = z, Jw = 0
                cols[k].append((z, None))
            else:
                # Jv = z x (c_k - o), Jw = z
                jv = rec.vector(S.cross(z, robot.links[k].com - o), f"lJ{i + 1}_{k + 1}")
                cols[k].append((jv, z))
    return cols


def _mass_matrix(robot: Robot, geo: JointFrames, rec: Recorder) -> sp.ImmutableMatrix:
    """``M = sum_k m_k Jv_k^T Jv_k + Jw_k^T I_k Jw_k``, entries recorded as ``lM_ij``."""
    n = robot.dof
    cols = _jacobian_columns(robot, geo, rec)
    entries = [[sp.Integer(0)] * n for _ in range(n)]
    for k, link in enumerate(robot.links):
        # I_k Jw_kj, shared by the row
        iw = [None if jw is None else rec.vector(link.inertia * jw, f"lIw{j + 1}_{k + 1}")
              for j, (_, jw) in enumerate(cols[k])]
        for i in range(k + 1):
            jv_i, jw_i = cols[k][i]
            for j in range(i, k + 1):
                jv_j = cols[k][j][0]
                # M_ij += m_k Jv_ki . Jv_kj + Jw_ki . I_k Jw_kj
                entries[i][j] += link.mass * (jv_i.T * jv_j)[0, 0]
                if jw_i is not None and iw[j] is not None:
                    entries[i][j] += (jw_i.T * iw[j])[0, 0]
    m = sp.zeros(n, n)
    for i in range(n):
        for j in range(i, n):
            m[i, j] = m[j, i] = rec.scalar(entries[i][j], f"lM{i + 1}_{j + 1}")
    return sp.ImmutableMatrix(m)


def _potential(robot: Robot, geo: JointFrames, rec: Recorder) -> sp.Expr:
    """``V = -sum_k m_k g . p_ck`` with the positions chained frame by frame."""
    rot_base = S.rotation(robot.base)
    # gravity in the chain base frame, and g . (origin of the base frame)
    gvec = rot_base.T * robot.gravity
    height = (robot.gravity.T * S.translation(robot.base))[0, 0]
    potential = sp.Integer(0)
    for k, link in enumerate(robot.links):
        # g . o_k = g . o_{k-1} + g_{k-1} . p_k + g_k . s_k   (o_k = o_{k-1} + R (p_k + R_k s_k))
        g_prev = gvec
        gvec = rec.vector(geo.rot[k].T * gvec, f"lg{k + 1}")
        height = rec.scalar(height + (g_prev.T * geo.pre[k])[0, 0]
                            + (gvec.T * geo.offset[k])[0, 0], f"lh{k + 1}")
        # V -= m_k g . p_ck = m_k (g . o_k + g_k . c_k)
        potential -= link.mass * (height + (gvec.T * link.com)[0, 0])
    return rec.scalar(potential, "lV")


def lagrange(robot: Robot, q: Sequence[sp.Symbol], qd: Sequence[sp.Symbol],
             qdd: Sequence[sp.Symbol]) -> LagrangeTerms:
    """Lagrange-Euler equations of a serial chain as straight-line programs.

    Parameters
    ----------
    robot : Robot
    q, qd, qdd : sequences of Symbol, length n
        Joint positions (rad or m), velocities and accelerations.

    Returns
    -------
    LagrangeTerms
    """
    n = robot.dof
    rec, geo = chain_program(robot, q, qd, qdd)
    m = _mass_matrix(robot, geo, rec)
    potential = _potential(robot, geo, rec)
    v_prog = Program(tuple(rec.assignments), sp.ImmutableMatrix([[potential]])).pruned()
    grav = []
    for k in range(n):
        # g_k = dV/dq_k through the program of V
        d = tangents(v_prog.assignments, {q[k]: sp.Integer(1)}, rec, f"q{k + 1}", geo.trig)
        grav.append(tangent(potential, d, geo.trig))
    everything = tuple(rec.assignments)
    m_prog = Program(everything, m).pruned()
    g_prog = Program(everything, sp.ImmutableMatrix(grav)).pruned()
    # C_ij = sum_k (dM_ij/dq_k + dM_ik/dq_j - dM_jk/dq_i) qd_k / 2
    c = christoffel_program(m_prog, q, qd).expand()
    m_x, g_x = m_prog.expand(), g_prog.expand()
    # tau = M qdd + C qd + g
    tau = sp.ImmutableMatrix(m_x * sp.Matrix(qdd) + c * sp.Matrix(qd) + g_x)
    return LagrangeTerms(m_prog, v_prog, g_prog, c, tau)
