"""Linear parameterisation ``tau = Y(q, qd, qdd) @ p`` of the full inverse dynamics.

Per joint ``j`` (base outwards) the parameter vector holds 15 entries::

    XXj XYj XZj YYj YZj ZZj   inertia about the link frame origin, link axes (kg m^2)
    MXj MYj MZj               first moment m c (kg m)
    Mj                        mass (kg)
    Iaj                       rotor inertia reflected to the joint, G^2 J_m (kg m^2)
    Fvj Fcpj Fcnj Foj         viscous, Coulomb (+), Coulomb (-) and offset friction, joint side

The inertial columns come from the Newton-Euler recursion (the kinematics does not depend on the
parameters). The inward recursion is linear in the wrenches, so the torque of joint ``i`` under a
wrench ``(F, N)`` on link ``j >= i`` (about link ``j``'s frame origin) is the power pairing
``tau_i = omega_ij . N + v_ij . F`` with joint ``i``'s unit motion ``(omega_ij, v_ij)`` expressed in
link frame ``j`` at its origin. The ``n (n + 1) / 2`` unit motions are carried outward once, one
spatial transform per pair, instead of one inward pass per parameter column (``10 n`` of them).
"""

from __future__ import annotations

from collections.abc import Sequence

import sympy as sp

from robodyn import spatial as S
from robodyn.robot.model import Robot
from robodyn.symbolic.newton_euler import (
    ZERO3,
    ChainGeometry,
    base_acceleration,
    chain_geometry,
    outward,
)
from robodyn.symbolic.program import Recorder

INERTIAL_NAMES = ("XX", "XY", "XZ", "YY", "YZ", "ZZ", "MX", "MY", "MZ", "M")
JOINT_NAMES = ("Ia", "Fv", "Fcp", "Fcn", "Fo")
PER_JOINT = len(INERTIAL_NAMES) + len(JOINT_NAMES)

_INERTIA_INDEX = {"XX": (0, 0), "XY": (0, 1), "XZ": (0, 2), "YY": (1, 1), "YZ": (1, 2), "ZZ": (2, 2)}


def joint_columns(j: int, first: str = "Ia", last: str = "Fo") -> slice:
    """Columns (of the 15 n) of joint ``j``'s drive parameters ``first`` to ``last`` (both
    included, in :data:`JOINT_NAMES` order: Ia, Fv, Fcp, Fcn, Fo)."""
    start = PER_JOINT * j + len(INERTIAL_NAMES)
    return slice(start + JOINT_NAMES.index(first), start + JOINT_NAMES.index(last) + 1)


def parameter_names(n: int) -> tuple[str, ...]:
    """Names of the 15 n parameters, in regressor column order."""
    return tuple(f"{name}{j + 1}" for j in range(n) for name in INERTIAL_NAMES + JOINT_NAMES)


def reflected_rotor_inertia(robot: Robot, j: int) -> sp.Expr:
    """``G^2 J_m`` of joint ``j`` (kg m^2 or kg)."""
    d = robot.joints[j].drive
    return d.gear_ratio**2 * d.rotor_inertia


def parameter_values(robot: Robot) -> sp.ImmutableMatrix:
    """The robot's parameter vector (expressions in its named parameters), shape (15 n, 1)."""
    vals: list[sp.Expr] = []
    for j, (joint, link) in enumerate(zip(robot.joints, robot.links, strict=True)):
        jo = link.inertia_at_origin
        ms = link.first_moment
        vals += [jo[_INERTIA_INDEX[k]] for k in INERTIAL_NAMES[:6]]
        vals += [ms[0], ms[1], ms[2], link.mass]
        fr = joint.friction
        vals += [reflected_rotor_inertia(robot, j), fr.viscous, fr.coulomb_positive,
                 fr.coulomb_negative, fr.offset]
    return sp.ImmutableMatrix(vals)


def friction_columns(qd: sp.Expr) -> list[sp.Expr]:
    """Regressor entries of (Fv, Fcp, Fcn, Fo) for joint velocity ``qd``."""
    # tau_f = Fv qd + Fcp H(qd) - Fcn H(-qd) + Fo
    return [qd, sp.Heaviside(qd, 0), -sp.Heaviside(-qd, 0), sp.Integer(1)]


def _unit_wrench(name: str, w: sp.ImmutableMatrix, wd: sp.ImmutableMatrix, u: sp.ImmutableMatrix,
                 a: sp.ImmutableMatrix) -> tuple[sp.ImmutableMatrix, sp.ImmutableMatrix]:
    """Force and moment about the link origin per unit of one inertial parameter."""
    if name == "M":
        # F = a, N = 0
        return a, ZERO3
    if name.startswith("M"):
        e = sp.ImmutableMatrix([1 if name[1] == ax else 0 for ax in "XYZ"])
        # F = wd x e + w x (w x e), N = e x a
        return (sp.ImmutableMatrix(u * e),
                sp.ImmutableMatrix(S.cross(e, a)))
    r, c = _INERTIA_INDEX[name]
    basis = sp.zeros(3, 3)
    basis[r, c] = 1
    basis[c, r] = 1
    # N = J wd + w x (J w)
    return ZERO3, sp.ImmutableMatrix(basis * wd + S.cross(w, basis * w))


Motion = tuple[sp.ImmutableMatrix, sp.ImmutableMatrix]


def joint_motions(geo: ChainGeometry, rec: Recorder) -> list[list[Motion]]:
    """Unit motion of every joint seen from every link outboard of it.

    Returns
    -------
    list of list of (omega, v)
        ``[j][i]`` for ``i <= j``: angular velocity ``omega`` (3, 1) and velocity ``v`` (3, 1) of
        link ``j``'s frame origin, link-frame-``j`` components, per unit rate of joint ``i`` alone
        (rad/s or m/s).
    """
    n = len(geo.rot)
    out: list[list[Motion]] = [[] for _ in range(n)]
    for i in range(n):
        z, s = geo.z[i], geo.s[i]
        if geo.prismatic[i]:
            # omega = 0, v = z_i
            om, v = ZERO3, z
        else:
            # omega = z_i, v = z_i x s_i (frame i origin turning about the joint axis)
            om, v = z, sp.ImmutableMatrix(S.cross(z, s))
        out[i].append((om, v))
        for k in range(i + 1, n):
            rt = geo.rot[k].T
            # omega_k = R_k^T omega;  v_k = R_k^T (v + omega x p_k) + omega_k x s_k
            om_k = rec.vector(rt * om, f"S{i + 1}_{k + 1}w")
            v_k = rec.vector(rt * (v + S.cross(om, geo.p[k])) + S.cross(om_k, geo.s[k]),
                             f"S{i + 1}_{k + 1}v")
            out[k].append((om_k, v_k))
            om, v = om_k, v_k
    return out


def regressor(robot: Robot, q: Sequence[sp.Symbol], qd: Sequence[sp.Symbol],
              qdd: Sequence[sp.Symbol], rec: Recorder) -> sp.ImmutableMatrix:
    """Full inverse-dynamics regressor ``Y``, shape (n, 15 n), in intermediate-variable form."""
    n = robot.dof
    geo = chain_geometry(robot, q, rec)
    mot = outward(geo, qd, qdd, base_acceleration(robot, True), rec)
    motions = joint_motions(geo, rec)
    y = sp.zeros(n, PER_JOINT * n)
    for j in range(n):
        for k, name in enumerate(INERTIAL_NAMES):
            f, m = _unit_wrench(name, mot.w[j], mot.wd[j], mot.u[j], mot.a[j])
            if f == ZERO3 and m == ZERO3:
                continue
            f = rec.vector(f, f"y{name}{j + 1}_F")
            m = rec.vector(m, f"y{name}{j + 1}_N")
            for i in range(j + 1):
                om, v = motions[j][i]
                # tau_i = omega_ij . N + v_ij . F
                y[i, PER_JOINT * j + k] = (om.T * m)[0, 0] + (v.T * f)[0, 0]
        base = PER_JOINT * j + len(INERTIAL_NAMES)
        y[j, base] = qdd[j]
        for k, col in enumerate(friction_columns(qd[j])):
            y[j, base + 1 + k] = col
    return sp.ImmutableMatrix(y)
