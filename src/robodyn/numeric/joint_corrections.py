"""Link angles from joint readings: the corrections a calibrated description carries.

Evaluates :class:`robodyn.robot.corrections.JointCorrections` (the equations are in that module's
docstring): the transmission terms, then the joints' deflection under the holding torque of point
masses on the stored reference geometry, linear (torque at the readings) or exact (torque at the
deflected pose, Newton's method, :mod:`robodyn.numeric.deflection`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from robodyn.numeric.deflection import exact_deflection
from robodyn.robot.corrections import HoldingTorque, JointCorrections
from robodyn.robot.numbers import RobotNumbers, robot_numbers

if TYPE_CHECKING:
    from robodyn.robot.model import Robot

__all__ = ["holding_torque", "holding_torque_jacobian", "link_positions"]


def _rotation(direction: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Rotations (N, 3, 3) by ``angle`` (N,) about the unit ``direction`` (3,) (Rodrigues)."""
    k = np.array([[0.0, -direction[2], direction[1]], [direction[2], 0.0, -direction[0]],
                  [-direction[1], direction[0], 0.0]])
    s, c = np.sin(angle)[:, None, None], np.cos(angle)[:, None, None]
    return np.eye(3) + s * k + (1.0 - c) * (k @ k)


def holding_torque(holding: HoldingTorque, q: np.ndarray) -> np.ndarray:
    """Static holding torques of the point masses, shape (N, n), N m (N), for angles (N, n).

    Product of exponentials on the reference geometry: joint ``j`` moves everything beyond it
    by a rotation about (or a translation along) its axis as it is after joints ``1 .. j-1``.
    """
    q = np.atleast_2d(np.asarray(q, dtype=float))
    big_n, n = q.shape
    pts, dirs = np.array(holding.axis_points), np.array(holding.axis_directions)
    masses = np.array(holding.masses)
    moments = np.array(holding.moments).reshape(-1, 3)
    moved = np.array(holding.moved_by, dtype=int)
    gravity = np.array(holding.gravity)
    rot = np.broadcast_to(np.eye(3), (big_n, 3, 3)).copy()  # G_j = prod exp(S_k q_k), k < j
    trans = np.zeros((big_n, 3))
    axis_p, axis_u = np.zeros((big_n, n, 3)), np.zeros((big_n, n, 3))
    first = np.zeros((big_n, n + 1, 3))  # first moments m p of the masses moved by exactly j joints
    mass = np.zeros(n + 1)
    for j in range(n):
        axis_p[:, j] = rot @ pts[j] + trans
        axis_u[:, j] = rot @ dirs[j]
        if holding.joint_types[j] == "revolute":
            r = _rotation(dirs[j], q[:, j])
            t = pts[j] - r @ pts[j]  # rotation about the line through p_j
        else:
            r = np.broadcast_to(np.eye(3), (big_n, 3, 3))
            t = q[:, j, None] * dirs[j]
        trans = np.einsum("nij,nj->ni", rot, t) + trans
        rot = rot @ r
        on = moved == j + 1
        if np.any(on):
            h = moments[on].sum(axis=0)
            m = masses[on].sum()
            first[:, j + 1] = rot @ h + m * trans  # m p(q) = R h + m t
            mass[j + 1] = m
    # S_j, M_j: moments and masses moved by joint j (those moved by j + 1 .. n joints)
    s_beyond = np.cumsum(first[:, ::-1], axis=1)[:, ::-1]
    m_beyond = np.cumsum(mass[::-1])[::-1]
    out = np.zeros((big_n, n))
    for j in range(n):
        s, m = s_beyond[:, j + 1], m_beyond[j + 1]
        if holding.joint_types[j] == "revolute":
            # tau_j = -g . (u_j x (S_j - M_j p_j))
            out[:, j] = -np.cross(axis_u[:, j], s - m * axis_p[:, j]) @ gravity
        else:
            out[:, j] = -m * axis_u[:, j] @ gravity  # tau_j = -M_j g . u_j
    return out


def holding_torque_jacobian(holding: HoldingTorque, q: np.ndarray, step: float = 1e-6) -> np.ndarray:
    """``d tau / d q`` (N, n, n), ``[i, j, k] = d tau_j / d q_k``, by central differences (step in
    rad or m; truncation error of order ``step**2`` times the third derivative)."""
    q = np.atleast_2d(np.asarray(q, dtype=float))
    out = np.zeros(q.shape + (q.shape[1],))
    for k in range(q.shape[1]):
        e = np.zeros(q.shape[1])
        e[k] = step
        out[:, :, k] = (holding_torque(holding, q + e) - holding_torque(holding, q - e)) / (2 * step)
    return out


def _transmission(table: np.ndarray, gear: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``u - q`` (N, n) of the transmission terms and ``du/dq`` diagonal (N, n)."""
    k, a, b, am, bm = (table[:, i] for i in range(5))
    g = np.where(np.isfinite(gear), gear, 0.0)
    has_motor = np.isfinite(gear)
    sq, cq, sg, cg = np.sin(q), np.cos(q), np.sin(g * q), np.cos(g * q)
    # du = k q + a cos q + b sin q + a' cos(G q) + b' sin(G q)
    du = k * q + a * cq + b * sq + np.where(has_motor, am * cg + bm * sg, 0.0)
    diag = 1.0 + k - a * sq + b * cq + np.where(has_motor, g * (bm * cg - am * sg), 0.0)
    return du, diag


def link_positions(robot: Robot | RobotNumbers, q: np.ndarray, *, derivative: bool = False,
                   ) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """Link angles (N, n) for joint readings ``q`` (n,) or (N, n), rad (m).

    ``robot.corrections`` is applied (module docstring); without corrections the readings are
    returned unchanged (a copy). The gear ratios of the motor harmonics are the joints' drive
    ratios at the description's default parameter values.

    Parameters
    ----------
    robot : Robot or RobotNumbers
    q : numpy.ndarray, shape (n,) or (N, n)
    derivative : bool
        Also return ``d x / d q`` (N, n, n): the transmission terms exactly, the compliance's
        torque derivative by central differences.

    Returns
    -------
    x : numpy.ndarray, shape of ``q``
    dx_dq : numpy.ndarray, shape (N, n, n) or (n, n)
        Only with ``derivative``.
    """
    q_in = np.asarray(q, dtype=float)
    q2 = np.atleast_2d(q_in)
    n = q2.shape[1]
    corr: JointCorrections | None = robot.corrections
    if corr is None:
        x, jac = q2.copy(), np.broadcast_to(np.eye(n), (len(q2), n, n)).copy()
    else:
        gear = np.array(robot_numbers(robot).gear_ratios)
        gear[gear == 1.0] = np.nan  # a direct drive has no separate motor harmonic
        table = corr.array
        du, diag = _transmission(table, gear, q2)
        u = q2 + du
        c = table[:, 5]
        if not np.any(c):
            x, jac = u, diag[:, :, None] * np.eye(n)
        elif corr.deflection == "linear":
            x = u - c * holding_torque(corr.holding, q2)  # x = u - C tau(q)
            jac = diag[:, :, None] * np.eye(n)
            if derivative:
                jac = jac - c[None, :, None] * holding_torque_jacobian(corr.holding, q2)
        else:
            d = exact_deflection(u, c, lambda v: holding_torque(corr.holding, v),
                                 lambda v: holding_torque_jacobian(corr.holding, v))
            x = d.q_link  # x = u - C tau(x)
            jac = d.sensitivity * diag[:, None, :]  # dx/dq = (I + C G)^-1 du/dq
    x = x.reshape(q_in.shape)
    if not derivative:
        return x
    return x, (jac[0] if q_in.ndim == 1 else jac)
