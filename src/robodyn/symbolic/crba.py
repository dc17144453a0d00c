"""Composite-rigid-body algorithm: the joint-space inertia matrix as a recursive program.

Instead of ``n`` Newton-Euler passes (one per column of ``M``), the inertia of the sub-chain
``i..n`` is accumulated inward once and each joint's motion subspace is pushed through it
(Featherstone's CRBA, written with 3-vectors and the barycentric parameters of
:mod:`robodyn.symbolic.newton_euler`). Everything about joint ``i`` is expressed in link frame
``i`` about the joint point ``O_i``: the origin of the joint's motion frame, which lies on its
axis, so the motion subspace is simply ``[z_i; 0]`` (revolute) or ``[0; z_i]`` (prismatic).

Composite body ``i`` (links ``i..n``) about ``O_i``: mass ``m``, first moment ``h`` (kg m) and
inertia ``J`` (kg m^2). Moving a body by rotation ``R`` and offset ``p``::

    h' = R h + m p
    J' = R J R^T - [p]x [R h]x - [R h]x [p]x - m [p]x^2
"""

from __future__ import annotations

from collections.abc import Sequence

import sympy as sp

from robodyn import spatial as S
from robodyn.robot.model import Robot
from robodyn.symbolic.newton_euler import LinkInertial, chain_geometry, description_inertials
from robodyn.symbolic.program import Recorder


def _symmetric(mat: sp.MatrixBase, rec: Recorder, name: str) -> sp.ImmutableMatrix:
    """Record the 6 distinct entries of a symmetric (3, 3) matrix."""
    entries = {}
    for r in range(3):
        for c in range(r, 3):
            entries[r, c] = entries[c, r] = rec.scalar(mat[r, c], f"{name}_{r + 1}{c + 1}")
    return sp.ImmutableMatrix(3, 3, [entries[r, c] for r in range(3) for c in range(3)])


def _shift(m: sp.Expr, h: sp.ImmutableMatrix, j: sp.ImmutableMatrix, rot: sp.MatrixBase | None,
           p: sp.ImmutableMatrix) -> tuple[sp.ImmutableMatrix, sp.MatrixBase]:
    """First moment and inertia of a body rotated by ``rot`` (None: identity) and moved by ``p``."""
    rh = h if rot is None else rot * h
    rj = j if rot is None else rot * j * rot.T
    if all(v == 0 for v in p):
        return sp.ImmutableMatrix(rh), rj
    px, rhx = S.skew(p), S.skew(rh)
    # h' = R h + m p
    h_new = sp.ImmutableMatrix(rh + m * p)
    # J' = R J R^T - [p]x [Rh]x - [Rh]x [p]x - m [p]x^2
    j_new = rj - px * rhx - rhx * px - m * px * px
    return h_new, j_new


def mass_matrix(robot: Robot, q: Sequence[sp.Expr], rec: Recorder,
                inertials: Sequence[LinkInertial] | None = None) -> sp.ImmutableMatrix:
    """Rigid-body joint-space inertia matrix ``M(q)`` by the composite-rigid-body algorithm.

    Parameters
    ----------
    robot : Robot
    q : sequence of length n
        Joint positions (rad or m), symbols or numbers.
    rec : Recorder
        Receives the intermediate variables (``c1``, ``R2_11``, ``Jc3_12``, ...).
    inertials : sequence of LinkInertial, optional
        Barycentric parameters per link; defaults to the description's values.

    Returns
    -------
    ImmutableMatrix, shape (n, n)
        Symmetric, rotor inertia not included (kg m^2, kg m or kg per entry).
    """
    inertials = list(inertials) if inertials is not None else description_inertials(robot)
    n = robot.dof
    prefix = rec.prefix
    rec.prefix = f"{prefix}M_"
    geo = chain_geometry(robot, q, rec)
    out = sp.zeros(n, n)
    m_c: sp.Expr = sp.Integer(0)
    h_c = sp.ImmutableMatrix([0, 0, 0])
    j_c: sp.MatrixBase = sp.zeros(3, 3)
    for i in reversed(range(n)):
        k = i + 1
        link = inertials[i]
        # own link about the joint point O_i (frame origin is at s_i from O_i)
        h_own, j_own = _shift(link.mass, link.first_moment, link.inertia, None, geo.s[i])
        if i < n - 1:
            # composite i+1 moved into frame i about O_i: R = R_{i+1}, p = s_i + p_{i+1}
            h_in, j_in = _shift(m_c, h_c, j_c, geo.rot[i + 1], geo.s[i] + geo.p[i + 1])
        else:
            h_in, j_in = sp.ImmutableMatrix([0, 0, 0]), sp.zeros(3, 3)
        # composite_i = own_i + composite_{i+1}
        m_c = rec.scalar(link.mass + m_c, f"mc{k}")
        h_c = rec.vector(h_own + h_in, f"hc{k}")
        j_c = _symmetric(j_own + j_in, rec, f"Jc{k}")
        z = geo.z[i]
        if geo.prismatic[i]:
            # F = I_c [0; z]:  f = m z,  n = h x z
            f, nm = m_c * z, S.cross(h_c, z)
        else:
            # F = I_c [z; 0]:  f = z x h,  n = J z
            f, nm = S.cross(z, h_c), j_c * z
        f = rec.vector(f, f"fM{k}_{k}")
        nm = rec.vector(nm, f"nM{k}_{k}")
        for r in range(i, -1, -1):
            if r < i:
                # carry the force column to the parent: f' = R f, n' = R n + (s + p) x f'
                rot = geo.rot[r + 1]
                f = rec.vector(rot * f, f"fM{k}_{r + 1}")
                nm = rec.vector(rot * nm + S.cross(geo.s[r] + geo.p[r + 1], f), f"nM{k}_{r + 1}")
            # M_rk = S_r . F
            val = (geo.z[r].T * (f if geo.prismatic[r] else nm))[0, 0]
            out[r, i] = out[i, r] = rec.scalar(val, f"M{r + 1}{k}" if n < 10 else f"M{r + 1}_{k}")
    rec.prefix = prefix
    return sp.ImmutableMatrix(out)
