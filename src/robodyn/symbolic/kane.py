"""Kane's method: partial velocities, generalised active and inertia forces.

Generalised speeds are the joint velocities ``u = qd``. For each link ``i`` the angular velocity
``w_i`` and the centre-of-mass velocity ``v_i`` are written in link-frame components (so the link's
inertia is constant); their derivatives with respect to ``qd_r`` are the partial angular
velocities and partial velocities. Accelerations are the time derivatives seen from the link frame
plus the transport term (``alpha = dw/dt``, ``a = dv/dt + w x v``). Kane's equations
``F_r + F*_r = 0`` with

    F_r  = tau_r + sum_i m_i g_i . v_i^r                         (generalised active forces)
    F*_r = -sum_i (m_i a_i . v_i^r + (I_i alpha_i + w_i x I_i w_i) . w_i^r)   (inertia forces)

give the rigid-body inverse dynamics ``tau_r = -F*_r - sum_i m_i g_i . v_i^r``.

The velocities are linear in ``qd``, so ``qdd_s`` enters ``F*`` only through ``alpha_i`` and
``a_i``, with coefficients ``w_i^s`` and ``v_i^s``: the mass matrix is

    M_rs = -dF*_r/dqdd_s = sum_i m_i v_i^r . v_i^s + w_i^r . I_i w_i^s

Everything is a straight-line program (:mod:`robodyn.symbolic.link_frames`): velocities are named
intermediates, and the partial velocities and time derivatives are taken through them by the
chain rule, so the cost grows polynomially (not exponentially) with the number of joints.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import sympy as sp

from robodyn import spatial as S
from robodyn.robot.model import Robot
from robodyn.symbolic.link_frames import chain_program, tangent_matrix, tangents
from robodyn.symbolic.program import Program


@dataclass(frozen=True)
class KaneTerms:
    """Kane's equations split into their parts, as straight-line programs.

    Attributes
    ----------
    forces : Program
        Generalised inertia forces ``F*`` (functions of q, qd, qdd) and generalised active forces
        of gravity ``F``, as the two columns of its (n, 2) output.
    mass_matrix : Program
        ``-dF*/dqdd`` from the partial velocities, shape (n, n).
    """

    forces: Program
    mass_matrix: Program

    def _column(self, col: sp.MatrixBase) -> Program:
        return Program(self.forces.assignments, sp.ImmutableMatrix(col)).pruned()

    @property
    def inertia_forces(self) -> Program:
        """Generalised inertia forces ``F*``, shape (n, 1)."""
        return self._column(self.forces.outputs[:, 0])

    @property
    def gravity_forces(self) -> Program:
        """Generalised active forces of gravity ``F``, shape (n, 1)."""
        return self._column(self.forces.outputs[:, 1])

    @property
    def tau(self) -> sp.ImmutableMatrix:
        """Rigid-body joint torques ``-(F* + F)`` as expressions, shape (n, 1)."""
        out = self.forces.outputs
        return Program(self.forces.assignments, sp.ImmutableMatrix(-(out[:, 0] + out[:, 1]))).expand()

    @property
    def gravity(self) -> Program:
        """Gravity load ``g(q) = -F``, shape (n, 1)."""
        return self._column(-self.forces.outputs[:, 1])


def kane(robot: Robot, q: Sequence[sp.Symbol], qd: Sequence[sp.Symbol],
         qdd: Sequence[sp.Symbol]) -> KaneTerms:
    """Generalised active and inertia forces of a serial chain.

    Parameters
    ----------
    robot : Robot
    q, qd, qdd : sequences of Symbol, length n
        Joint positions (rad or m), velocities and accelerations.

    Returns
    -------
    KaneTerms
    """
    n = robot.dof
    rec, geo = chain_program(robot, q, qd, qdd)
    w = sp.zeros(3, 1)  # angular velocity of the previous link, its frame
    v = sp.zeros(3, 1)  # velocity of the previous link frame origin, its frame
    g = S.rotation(robot.base).T * robot.gravity  # gravity in the previous link frame
    ws, vcs, gs = [], [], []
    for i in range(n):
        k = i + 1
        rt, z, s_vec = geo.rot[i].T, geo.axis[i], geo.offset[i]
        # velocity of the motion-frame origin (fixed in link i-1): v + w x p
        v_j = v + S.cross(w, geo.pre[i])
        w_new = rt * w
        if not geo.prismatic[i]:
            # w_i = R^T w_{i-1} + z qd_i
            w_new = w_new + z * qd[i]
        w = rec.vector(w_new, f"kw{k}")
        # v_i = R^T v_J + w_i x s (+ z qd prismatic)
        v_new = rt * v_j + S.cross(w, s_vec)
        if geo.prismatic[i]:
            v_new = v_new + z * qd[i]
        v = rec.vector(v_new, f"kv{k}")
        # centre of mass velocity v_c = v + w x c
        vcs.append(rec.vector(v + S.cross(w, robot.links[i].com), f"kvc{k}"))
        ws.append(w)
        # gravity in link frame i: R^T g
        g = rec.vector(rt * g, f"kg{k}")
        gs.append(g)
    velocity_program = list(rec.assignments)

    # partial angular velocities and partial velocities: d/dqd_r of w_i and v_i
    w_r, v_r = [], []
    for r in range(n):
        d = tangents(velocity_program, {qd[r]: sp.Integer(1)}, rec, f"u{r + 1}", geo.trig)
        w_r.append([tangent_matrix(wi, d, geo.trig) for wi in ws])
        v_r.append([tangent_matrix(vi, d, geo.trig) for vi in vcs])

    # time derivatives along the motion: dq/dt = qd, dqd/dt = qdd
    seeds = {**dict(zip(q, qd, strict=True)), **dict(zip(qd, qdd, strict=True))}
    dt = tangents(velocity_program, seeds, rec, "t", geo.trig)
    f_star = [sp.Integer(0)] * n
    f_grav = [sp.Integer(0)] * n
    mass = sp.zeros(n, n)
    for i, link in enumerate(robot.links):
        k = i + 1
        wi, vi = ws[i], vcs[i]
        # alpha_i = dw_i/dt, a_i = dv_i/dt + w_i x v_i
        alpha = rec.vector(tangent_matrix(wi, dt, geo.trig), f"kal{k}")
        acc = rec.vector(tangent_matrix(vi, dt, geo.trig) + S.cross(wi, vi), f"ka{k}")
        inertia = link.inertia
        # inertia torque and force: T* = -(I alpha + w x I w), R* = -m a
        iw = rec.vector(inertia * wi, f"kIw{k}")
        t_star = rec.vector(-(inertia * alpha + S.cross(wi, iw)), f"kT{k}")
        r_star = rec.vector(-link.mass * acc, f"kF{k}")
        weight = link.mass * gs[i]
        # I w_i^s, for the mass matrix
        iw_s = [rec.vector(inertia * w_r[s][i], f"kIw{k}_u{s + 1}") for s in range(i + 1)]
        for r in range(i + 1):
            # F*_r += v_r . R* + w_r . T*;  F_r (gravity) += v_r . m g
            f_star[r] += (v_r[r][i].T * r_star + w_r[r][i].T * t_star)[0, 0]
            f_grav[r] += (v_r[r][i].T * weight)[0, 0]
            for s in range(r, i + 1):
                # -dF*_r/dqdd_s += m v_r . v_s + w_r . I w_s  (dalpha/dqdd_s = w_s, da/dqdd_s = v_s)
                mass[r, s] += link.mass * (v_r[r][i].T * v_r[s][i])[0, 0] + (w_r[r][i].T * iw_s[s])[0, 0]
    f_star_v = sp.ImmutableMatrix([rec.scalar(f, f"kFs{r + 1}") for r, f in enumerate(f_star)])
    f_grav_v = sp.ImmutableMatrix([rec.scalar(f, f"kFg{r + 1}") for r, f in enumerate(f_grav)])
    for r in range(n):
        for s in range(r, n):
            mass[r, s] = mass[s, r] = rec.scalar(mass[r, s], f"kM{r + 1}_{s + 1}")
    everything = tuple(rec.assignments)
    return KaneTerms(Program(everything, sp.ImmutableMatrix.hstack(f_star_v, f_grav_v)).pruned(),
                     Program(everything, sp.ImmutableMatrix(mass)).pruned())
