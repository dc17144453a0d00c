"""The prior of an identification: the description, completed joint by joint from the data.

Descriptions usually give masses and inertias (a CAD model, a manufacturer's URDF) but neither
friction nor reflected rotor inertia, and motor currents come without the drive gains. So the
prior toward which :mod:`robodyn.identification.estimate` regularises is built in one cheap step, one
joint at a time, from the same identification samples::

    y_j = a_j tau_nom,j + Ia_j qdd_j + Fv_j qd_j + Fcp_j H(qd_j) - Fcn_j H(-qd_j) + Fo_j

with ``tau_nom = Y(q, qd, qdd) p_nom`` the description's rigid-body torque (its own rotor inertia
and friction left out). For ``target="tau"``, ``a_j = 1`` is fixed. For ``target="current"``:

* gains from the description (``"description"``, or ``"auto"`` when any joint's
  ``gear_ratio x torque_constant`` differs from 1, the default drive): ``a_j = 1 / K_j`` fixed;
* otherwise (``"absorbed"``) ``a_j`` is fitted and ``K_j = 1 / a_j``: the gain that scales the
  description's rigid-body torque onto the measured current (where that fails, ``a_j <= 0`` on a
  joint whose nominal torque is too small to see, the geometric mean of the other joints' gains
  is used, with an :class:`IdentificationWarning`). It thereby also absorbs a uniform
  error of the nominal load on that joint (an unmodelled tool); what is then identified are
  parameters in the torque units of the description's model, and currents ``i_j = tau_j / K_j``.

The prior's standard vector is the description's inertial parameters with ``(Ia, Fv, Fcp, Fcn,
Fo)`` of each joint replaced by the fitted ones, in torque units (multiplied by ``K_j``); Coulomb
levels and rotor inertia are clipped at zero.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence

import numpy as np
import sympy as sp

from robodyn.identification.preprocess import Samples
from robodyn.robot.errors import IdentificationError
from robodyn.robot.model import Robot
from robodyn.symbolic.regressor import joint_columns

__all__ = ["GAIN_MODES", "REVERSED_CORRELATION", "IdentificationWarning", "current_directions",
           "description_gains", "joint_prior"]

#: A joint's current whose correlation with the nominal torque is below minus this runs reversed.
REVERSED_CORRELATION = 0.5

GAIN_MODES = ("auto", "description", "absorbed")


class IdentificationWarning(UserWarning):
    """An identification went ahead with a fallback the user should know about."""


def description_gains(robot: Robot) -> np.ndarray:
    """``|gear_ratio x torque_constant|`` of each joint (n,), N m / A."""
    subs = robot.defaults()
    return np.array([abs(float(sp.sympify(j.drive.gear_ratio * j.drive.torque_constant).xreplace(subs)))
                     for j in robot.joints])


def _joint_columns(y: np.ndarray, j: int) -> np.ndarray:
    """Joint ``j``'s own regressor columns (Ia, Fv, Fcp, Fcn, Fo) of its row, (N, 5)."""
    # Ia qdd + Fv qd + Fcp H(qd) - Fcn H(-qd) + Fo
    return y[:, j, joint_columns(j)]


def joint_prior(robot: Robot, samples: Sequence[Samples], y_full: Sequence[np.ndarray],
                nominal: np.ndarray, target: str, mode: str,
                known: Sequence[np.ndarray] | None = None,
                observed: Sequence[np.ndarray] | None = None
                ) -> tuple[np.ndarray, str, np.ndarray]:
    """Drive gains, their source and the prior standard vector (module docstring).

    Parameters
    ----------
    robot : Robot
    samples : sequence of Samples
        Processed, decimated samples with targets ``y`` (N_k, n).
    y_full : sequence of numpy.ndarray, shape (N_k, n, 15 n)
        Full regressor at those samples (filtered like the target).
    nominal : numpy.ndarray, shape (15 n,)
    target : {"tau", "current"}
    mode : {"auto", "description", "absorbed"}
    known : sequence of numpy.ndarray, shape (N_k, n), optional
        Known torque in each recording's target, N m (a payload's, the fluid's): added to the nominal
        rigid-body torque, so that the per-joint fit does not take it for friction.
    observed : sequence of numpy.ndarray of bool, shape (n,), optional
        The joints with target data in each recording (default: all): a joint is fitted on the
        recordings where it has data, and keeps the description's terms (and drive gain, or 1)
        where none has (:mod:`robodyn.identification.unobserved`).

    Returns
    -------
    gains : numpy.ndarray, shape (n,)
        ``K_j`` (ones for torque targets); negative for a joint whose current runs against its
        torque (:func:`current_directions`).
    source : {"none", "description", "absorbed"}
        With " (current reversed: ...)" naming such joints.
    prior : numpy.ndarray, shape (15 n,)
    """
    n = robot.dof
    rigid = nominal.copy()
    for j in range(n):
        rigid[joint_columns(j)] = 0.0
    desc = description_gains(robot)
    if target == "tau":
        fixed, source = np.ones(n), "none"
    elif mode == "description" or (mode == "auto" and np.any(np.abs(desc - 1.0) > 1e-12)):
        if np.any(desc <= 0):
            j = int(np.argmin(desc))
            raise IdentificationError(f"{robot.source}: joints[{j}].drive: gear_ratio x "
                                      f"torque_constant is {desc[j]:g}; a current target needs a "
                                      f"positive drive gain (or gains='absorbed')")
        fixed, source = desc, "description"
    else:
        fixed, source = None, "absorbed"
    gains = np.ones(n) if fixed is None else fixed.copy()
    prior = rigid.copy()
    failed = []
    extra = [np.zeros((len(s.y), n)) for s in samples] if known is None else known
    seen = [np.ones(n, bool)] * len(samples) if observed is None else list(observed)
    flip = current_directions(samples, y_full, nominal, extra, seen) if target == "current" \
        else np.ones(n)

    def fit(j: int, gain: float | None) -> bool:
        use = [k for k in range(len(samples)) if seen[k][j]]
        if not use:  # no data on this joint: the description's own terms
            prior[joint_columns(j)] = nominal[joint_columns(j)]
            return True
        # the torque the description and the known loads explain: Y p_rigid + tau_known
        tau_nom = np.concatenate([y_full[k][:, j, :] @ rigid + extra[k][:, j] for k in use])
        cols = np.vstack([_joint_columns(y_full[k], j) for k in use])
        b = np.concatenate([samples[k].y[:, j] for k in use]) * flip[j]  # current in the torque's sense
        a = np.column_stack([tau_nom, cols]) if gain is None else cols
        if gain is not None:
            b = b - tau_nom / gain
        used = np.linalg.norm(a, axis=0) > 1e-12 * max(1.0, float(np.abs(a).max()))
        coef = np.zeros(a.shape[1])
        coef[used] = np.linalg.lstsq(a[:, used], b, rcond=None)[0]
        if gain is None:
            if not used[0] or coef[0] <= 0:
                return False
            gains[j] = 1.0 / coef[0]
            coef = coef[1:]
        ia, fv, fcp, fcn, fo = coef * gains[j]
        prior[joint_columns(j)] = (
            max(ia, 0.0), fv, max(fcp, 0.0), max(fcn, 0.0), fo)
        return True

    for j in range(n):
        if not fit(j, None if fixed is None else float(fixed[j])):
            failed.append(j)
    if failed:
        # the joints whose gain was absorbed from data (not those without data: gain 1)
        ok = [j for j in range(n) if j not in failed and any(obs[j] for obs in seen)]
        if not ok:
            raise IdentificationError(
                "recordings: no joint's drive gain can be absorbed (the description's torque "
                "does not explain the current on any joint); give the gains in the description's "
                "drives (gear_ratio x torque_constant)")
        names = ", ".join(repr(robot.joint_names[j]) for j in failed)
        warnings.warn(IdentificationWarning(
            f"drive gain of joint(s) {names} cannot be absorbed (the description's torque does "
            f"not explain their current): the geometric mean of the other joints' gains is used"),
            stacklevel=3)
        for j in failed:
            gains[j] = float(np.exp(np.mean(np.log(gains[ok]))))
            fit(j, gains[j])
        source = "absorbed (" + ", ".join(robot.joint_names[j] for j in failed) + ": mean of the others)"
    if np.any(flip < 0):
        reversed_ = ", ".join(robot.joint_names[j] for j in np.flatnonzero(flip < 0))
        source += f" (current reversed: {reversed_})"
    return gains * flip, source, prior


def current_directions(samples: Sequence[Samples], y_full: Sequence[np.ndarray], nominal: np.ndarray,
                       known: Sequence[np.ndarray],
                       observed: Sequence[np.ndarray] | None = None) -> np.ndarray:
    """Sense (n,) of each joint's current relative to its torque: -1 where the current is
    strongly anti-correlated with the description's joint torque ``Y p_nominal`` (rigid body,
    rotor inertia and friction; correlation below
    ``-REVERSED_CORRELATION``: a motor-side current sensor on a drive turning against the
    joint, or a log's sign convention), else +1. A weak correlation (a joint whose torque the
    description barely explains) keeps +1. ``known`` (N_k, n), N m: torque the description does
    not hold (a payload's, the fluid's), added to it. ``observed`` (n,) bool per recording: the
    joints with data there (default: all); a joint is judged on those recordings (+1 without)."""
    n = samples[0].q.shape[1]
    out = np.ones(n)
    for j in range(n):
        use = [k for k in range(len(samples)) if observed is None or observed[k][j]]
        if not use:
            continue
        tau = np.concatenate([y_full[k][:, j, :] @ nominal + known[k][:, j] for k in use])
        cur = np.concatenate([samples[k].y[:, j] for k in use])
        if np.std(tau) > 0 and np.std(cur) > 0 and np.corrcoef(tau, cur)[0, 1] < -REVERSED_CORRELATION:
            out[j] = -1.0
    return out
