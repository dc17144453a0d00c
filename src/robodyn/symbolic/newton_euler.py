"""Recursive Newton-Euler inverse dynamics as a customised symbolic model.

Outward recursion of angular velocity, angular acceleration and frame-origin acceleration in each
link frame; inward recursion of forces and moments; gravity enters as a base acceleration. Every
non-trivial component becomes an intermediate variable (:class:`~robodyn.symbolic.program.Recorder`),
zeros and ones fold, products are never expanded: the cost grows linearly with the joint count.

Link dynamics use the barycentric parameters (mass ``m``, first moment ``MS = m c`` and inertia
``J`` about the link frame origin), in which the equations are linear; see
:mod:`robodyn.symbolic.regressor`.

Notation for joint ``i`` (all vectors in link frame ``i`` unless noted)::

    R_i   rotation of frame i in frame i-1           = R_pre R_axis(q_i) R_post
    z_i   joint axis                                 = R_post^T axis
    p_i   origin of the motion frame in frame i-1    = translation(pre)
    s_i   motion-frame origin -> frame i origin       = R_post^T t_post (+ q_i z_i if prismatic)
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import sympy as sp

from robodyn import spatial as S
from robodyn.robot.model import Robot
from robodyn.symbolic.program import Recorder

Vec = sp.ImmutableMatrix
ZERO3 = sp.ImmutableMatrix([0, 0, 0])


@dataclass(frozen=True)
class LinkInertial:
    """Barycentric inertial parameters of one link, in its frame.

    Attributes
    ----------
    mass : Expr
        kg.
    first_moment : (3, 1) matrix
        ``m c``, kg m.
    inertia : (3, 3) matrix
        Inertia about the link frame origin, kg m^2.
    """

    mass: sp.Expr
    first_moment: sp.ImmutableMatrix
    inertia: sp.ImmutableMatrix


def description_inertials(robot: Robot) -> list[LinkInertial]:
    """Barycentric parameters from the robot description (expressions in its parameters)."""
    return [LinkInertial(lk.mass, lk.first_moment, lk.inertia_at_origin) for lk in robot.links]


@dataclass(frozen=True)
class ChainGeometry:
    """Constant and joint-dependent geometry of the chain for the recursions (see module doc)."""

    rot: tuple[sp.ImmutableMatrix, ...]
    z: tuple[sp.ImmutableMatrix, ...]
    p: tuple[sp.ImmutableMatrix, ...]
    s: tuple[sp.ImmutableMatrix, ...]
    prismatic: tuple[bool, ...]


def chain_geometry(robot: Robot, q: Sequence[sp.Expr], rec: Recorder) -> ChainGeometry:
    """Rotations ``R_i(q_i)``, axes ``z_i``, offsets ``p_i`` and ``s_i`` for every joint."""
    rots, zs, ps, ss, pris = [], [], [], [], []
    for i, (joint, qi) in enumerate(zip(robot.joints, q, strict=True)):
        k = i + 1
        r_post = S.rotation(joint.post)
        if joint.type == "revolute":
            # c_k = cos(q_k), s_k = sin(q_k)
            c = rec.scalar(sp.cos(qi), f"c{k}")
            s = rec.scalar(sp.sin(qi), f"s{k}")
            r_q = S.axis_angle(joint.axis, qi).xreplace({sp.cos(qi): c, sp.sin(qi): s})
        else:
            r_q = sp.eye(3)
        # R_i = R_pre R_axis(q) R_post
        rot = rec.matrix(S.rotation(joint.pre) * r_q * r_post, f"R{k}")
        z = sp.ImmutableMatrix(r_post.T * joint.axis)
        # s_i = R_post^T t_post (+ q z for prismatic)
        s_vec = sp.ImmutableMatrix(r_post.T * S.translation(joint.post))
        if joint.type == "prismatic":
            s_vec = sp.ImmutableMatrix(s_vec + qi * z)
        rots.append(rot)
        zs.append(z)
        ps.append(S.translation(joint.pre))
        ss.append(s_vec)
        pris.append(joint.type == "prismatic")
    return ChainGeometry(tuple(rots), tuple(zs), tuple(ps), tuple(ss), tuple(pris))


@dataclass(frozen=True)
class Motion:
    """Outward recursion results per link, link-frame components.

    ``u[i]`` is ``[wd]x + [w]x [w]x``: the acceleration of a point fixed in link i at offset r
    from the frame origin is ``a + u r`` (its entries are recorded lazily: unused ones are pruned).
    """

    w: tuple[sp.ImmutableMatrix, ...]
    wd: tuple[sp.ImmutableMatrix, ...]
    a: tuple[sp.ImmutableMatrix, ...]
    u: tuple[sp.ImmutableMatrix, ...]


def _u_matrix(w: Vec, wd: Vec, rec: Recorder, k: int) -> sp.ImmutableMatrix:
    """``U = [wd]x + [w]x^2`` with the products of ``w`` as shared intermediates."""
    wx, wy, wz = w
    sq = [rec.scalar(wx * wx, f"wxx{k}"), rec.scalar(wy * wy, f"wyy{k}"),
          rec.scalar(wz * wz, f"wzz{k}")]
    xy, xz, yz = (rec.scalar(wx * wy, f"wxy{k}"), rec.scalar(wx * wz, f"wxz{k}"),
                  rec.scalar(wy * wz, f"wyz{k}"))
    # [w]x^2 = w w^T - |w|^2 I
    ww = sp.Matrix([[-sq[1] - sq[2], xy, xz], [xy, -sq[0] - sq[2], yz], [xz, yz, -sq[0] - sq[1]]])
    return rec.matrix(S.skew(wd) + ww, f"U{k}")


def base_acceleration(robot: Robot, with_gravity: bool) -> sp.ImmutableMatrix:
    """Fictitious base acceleration ``-g`` in the chain base frame (zero without gravity)."""
    if not with_gravity:
        return ZERO3
    return sp.ImmutableMatrix(-(S.rotation(robot.base).T * robot.gravity))


def outward(geo: ChainGeometry, qd: Sequence[sp.Expr], qdd: Sequence[sp.Expr],
            a0: sp.ImmutableMatrix, rec: Recorder) -> Motion:
    """Outward recursion of angular velocity/acceleration and frame-origin acceleration."""
    w_prev, wd_prev, a_prev = ZERO3, ZERO3, a0
    u_prev = sp.ImmutableMatrix(sp.zeros(3, 3))
    ws, wds, accs, us = [], [], [], []
    for i in range(len(geo.rot)):
        k = i + 1
        rt, z, p, s = geo.rot[i].T, geo.z[i], geo.p[i], geo.s[i]
        # acceleration of the motion-frame origin, fixed in link i-1:
        # aJ = a_{i-1} + wd_{i-1} x p + w_{i-1} x (w_{i-1} x p) = a_{i-1} + U_{i-1} p
        a_j = a_prev + u_prev * p
        # wp = R^T w_{i-1}
        wp = rec.vector(rt * w_prev, f"wp{k}")
        if geo.prismatic[i]:
            w, wd = wp, rec.vector(rt * wd_prev, f"wd{k}")
        else:
            # w_i = R^T w_{i-1} + z qd_i
            w = rec.vector(wp + z * qd[i], f"w{k}")
            # wd_i = R^T wd_{i-1} + (R^T w_{i-1}) x z qd_i + z qdd_i
            wd = rec.vector(rt * wd_prev + S.cross(wp, z * qd[i]) + z * qdd[i], f"wd{k}")
        u = _u_matrix(w, wd, rec, k)
        # a_i = R^T aJ + wd_i x s + w_i x (w_i x s) = R^T aJ + U_i s
        acc = rt * rec.vector(a_j, f"aj{k}") + u * s
        if geo.prismatic[i]:
            # + 2 w_i x z qd_i + z qdd_i
            acc = acc + 2 * S.cross(w, z * qd[i]) + z * qdd[i]
        a = rec.vector(acc, f"a{k}")
        ws.append(w)
        wds.append(wd)
        accs.append(a)
        us.append(u)
        w_prev, wd_prev, a_prev, u_prev = w, wd, a, u
    return Motion(tuple(ws), tuple(wds), tuple(accs), tuple(us))


def link_wrench(p: LinkInertial, w: Vec, wd: Vec, a: Vec, u: sp.ImmutableMatrix,
                rec: Recorder, k: int) -> tuple[sp.ImmutableMatrix, sp.ImmutableMatrix]:
    """Inertial force and moment about the link frame origin, link-frame components.

    Barycentric form (linear in the parameters)::

        F = m a + U MS,   N = J wd + w x (J w) + MS x a

    or, when the inertia about the centre of mass is sparser (numeric links), the equivalent
    centre-of-mass form ``F = m (a + U c)``, ``N = I_c wd + w x (I_c w) + c x F``.
    """
    ms, j = p.first_moment, p.inertia
    m = p.mass
    if _com_form_is_cheaper(p):
        c = ms / m
        i_c = j - m * ((c.T * c)[0, 0] * sp.eye(3) - c * c.T)
        i_c = i_c.applyfunc(_clean)
        # F = m (a + U c)
        f = rec.vector(m * rec.vector(a + u * c, f"ac{k}"), f"F{k}")
        jw = rec.vector(i_c * w, f"Jw{k}")
        # N = I_c wd + w x (I_c w) + c x F
        n = rec.vector(i_c * wd + S.cross(w, jw) + S.cross(c, f), f"N{k}")
        return f, n
    # F = m a + U MS
    f = rec.vector(m * a + u * ms, f"F{k}")
    jw = rec.vector(j * w, f"Jw{k}")
    # N = J wd + w x (J w) + MS x a
    n = rec.vector(j * wd + S.cross(w, jw) + S.cross(ms, a), f"N{k}")
    return f, n


def _clean(e: sp.Expr) -> sp.Expr:
    """Round off float noise (e.g. 0.13 - 1e-17) in numeric inertia entries."""
    if e.is_Float:
        v = float(e)
        return sp.Integer(0) if abs(v) < 1e-15 else sp.Float(round(v, 14))
    return e


def _com_form_is_cheaper(p: LinkInertial) -> bool:
    """True when the link is numeric and its COM inertia has fewer non-zeros than ``J``."""
    if p.mass.free_symbols or p.inertia.free_symbols or p.first_moment.free_symbols:
        return False
    if p.mass == 0 or all(v == 0 for v in p.first_moment):
        return False
    c = p.first_moment / p.mass
    i_c = (p.inertia - p.mass * ((c.T * c)[0, 0] * sp.eye(3) - c * c.T)).applyfunc(_clean)
    return sum(v != 0 for v in i_c) < sum(v != 0 for v in p.inertia)


def inward(geo: ChainGeometry, wrenches: Sequence[tuple[Vec, Vec] | None], rec: Recorder,
           prefix: str = "") -> list[sp.Expr]:
    """Inward recursion of forces and moments; returns the joint torques/forces.

    ``wrenches[i]`` is link i's own (F, N) about its frame origin, or None for no contribution.
    """
    n = len(geo.rot)
    taus: list[sp.Expr] = [sp.Integer(0)] * n
    f_next: Vec | None = None
    n_next: Vec | None = None
    for i in reversed(range(n)):
        k = i + 1
        f, m = ZERO3, ZERO3
        s = geo.s[i]
        if wrenches[i] is not None:
            big_f, big_n = wrenches[i]
            # own wrench about the motion-frame origin: N + s x F
            f, m = big_f, big_n + S.cross(s, big_f)
        if f_next is not None:
            rf = geo.rot[i + 1] * f_next
            # f_i = F_i + R_{i+1} f_{i+1};  n_i += R_{i+1} n_{i+1} + (s_i + p_{i+1}) x (R_{i+1} f_{i+1})
            rf = rec.vector(rf, f"{prefix}fc{k}")
            f = f + rf
            m = m + geo.rot[i + 1] * n_next + S.cross(s + geo.p[i + 1], rf)
        if f == ZERO3 and m == ZERO3 and f_next is None:
            continue
        f_next = rec.vector(f, f"{prefix}f{k}")
        n_next = rec.vector(m, f"{prefix}n{k}")
        # tau_i = z_i . n_i (revolute) or z_i . f_i (prismatic)
        taus[i] = (geo.z[i].T * (f_next if geo.prismatic[i] else n_next))[0, 0]
    return taus


def inverse_dynamics(robot: Robot, q: Sequence[sp.Expr], qd: Sequence[sp.Expr],
                     qdd: Sequence[sp.Expr], rec: Recorder, *, with_gravity: bool = True,
                     inertials: Sequence[LinkInertial] | None = None) -> sp.ImmutableMatrix:
    """Rigid-body inverse dynamics ``tau = M qdd + C qd + g``, shape (n, 1).

    Parameters
    ----------
    q, qd, qdd : sequences of length n
        Joint positions (rad or m), velocities and accelerations (symbols or numbers).
    rec : Recorder
        Receives the intermediate variables (pass ``Recorder(record=False)`` for nested
        expressions).
    inertials : sequence of LinkInertial, optional
        Defaults to the description's values.
    """
    inertials = list(inertials) if inertials is not None else description_inertials(robot)
    geo = chain_geometry(robot, q, rec)
    mot = outward(geo, qd, qdd, base_acceleration(robot, with_gravity), rec)
    wrenches = [link_wrench(p, mot.w[i], mot.wd[i], mot.a[i], mot.u[i], rec, i + 1)
                for i, p in enumerate(inertials)]
    taus = inward(geo, wrenches, rec)
    return sp.ImmutableMatrix([rec.scalar(t, f"tau{i + 1}") for i, t in enumerate(taus)])


def gravity_torque(robot: Robot, q: Sequence[sp.Expr], rec: Recorder,
                   inertials: Sequence[LinkInertial] | None = None) -> sp.ImmutableMatrix:
    """Gravity load ``g(q)``: torques that hold the arm still, shape (n, 1)."""
    n = robot.dof
    prefix = rec.prefix
    rec.prefix = f"{prefix}g_"
    out = inverse_dynamics(robot, q, [0] * n, [0] * n, rec, inertials=inertials)
    rec.prefix = prefix
    return out


def symbolic_inertials(n: int) -> list[LinkInertial]:
    """Barycentric parameters as symbols ``XXj .. ZZj, MXj, MYj, MZj, Mj`` (regressor names)."""
    out = []
    for j in range(1, n + 1):
        xx, xy, xz, yy, yz, zz, mx, my, mz, m = sp.symbols(
            f"XX{j} XY{j} XZ{j} YY{j} YZ{j} ZZ{j} MX{j} MY{j} MZ{j} M{j}", real=True)
        out.append(LinkInertial(m, sp.ImmutableMatrix([mx, my, mz]),
                                sp.ImmutableMatrix([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])))
    return out
