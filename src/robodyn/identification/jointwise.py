"""Per-joint identification (the thesis's method): one joint moves, the others are held.

With every other joint held still, the row of the moving revolute joint ``j`` reduces to::

    y_j = J qdd_j + Gs sin(q_j) + Gc cos(q_j) + Fv qd_j + Fcp H(qd_j) - Fcn H(-qd_j) + Fo

``J`` is the effective inertia about the joint axis (links outboard in their held pose, plus the
reflected rotor), ``Gs sin + Gc cos`` the gravity torque of the outboard links (their potential
energy is a first harmonic of ``q_j`` when nothing else moves), and the Coriolis terms vanish
(``M_jj`` does not depend on ``q_j``). For a prismatic joint the gravity term is a constant,
which merges with the offset. Everything is in the target's units (N m, or A for currents: then
``J`` is in A s^2/rad, and so on), so no drive gain is needed. The recording is processed by the
same rule as :func:`robodyn.identification` (:mod:`robodyn.identification.preprocess`). Ordinary least
squares; standard deviations from the residual variance.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from robodyn.identification.estimate import truncated_lstsq
from robodyn.identification.preprocess import (
    MOVING_RAD,
    Preprocess,
    preprocess,
    resolve_preprocess,
)
from robodyn.measure.angles import unwrap_turns
from robodyn.robot.errors import IdentificationError
from robodyn.robot.model import Robot

__all__ = ["JOINT_PARAMETERS", "JointIdentification", "identify_joint", "moving_joint"]

JOINT_PARAMETERS = ("J", "Gs", "Gc", "Fv", "Fcp", "Fcn", "Fo")


def moving_joint(rec: Any) -> int | None:
    """The one joint whose position spans at least 1 mrad while the others do not (else None)."""
    span = np.ptp(unwrap_turns(rec.q), axis=0)
    moving = np.flatnonzero(span >= MOVING_RAD)
    return int(moving[0]) if moving.size == 1 else None


def _columns(q: np.ndarray, qd: np.ndarray, qdd: np.ndarray, revolute: bool) -> np.ndarray:
    grav = [np.sin(q), np.cos(q)] if revolute else [np.zeros_like(q), np.zeros_like(q)]
    # y = J qdd + Gs sin q + Gc cos q + Fv qd + Fcp H(qd) - Fcn H(-qd) + Fo
    return np.column_stack([qdd, *grav, qd, (qd > 0).astype(float), -(qd < 0).astype(float),
                            np.ones_like(q)])


@dataclass(frozen=True, eq=False)
class JointIdentification:
    """Result of :func:`identify_joint`.

    Attributes
    ----------
    joint : int
        0-based index of the moving joint.
    joint_name : str
    names : tuple of str
        ``JOINT_PARAMETERS``.
    values, std : numpy.ndarray, shape (7,)
        Estimates and standard deviations (inf: not excited by the recording, value 0).
    identifiable : numpy.ndarray of bool, shape (7,)
    target : {"tau", "current"}
    preprocess : Preprocess
    revolute : bool
    residual_std : float
    """

    joint: int
    joint_name: str
    names: tuple[str, ...]
    values: np.ndarray
    std: np.ndarray
    identifiable: np.ndarray
    target: str
    preprocess: Preprocess
    revolute: bool
    residual_std: float

    @property
    def relative_std(self) -> np.ndarray:
        """``100 std / |value|`` (%), shape (7,)."""
        with np.errstate(divide="ignore", invalid="ignore"):
            rel = 100.0 * self.std / np.abs(self.values)
        return np.where(np.isfinite(rel), rel, np.inf)

    def predict(self, recording: Any) -> np.ndarray:
        """Predicted target of the moving joint (N,) at the recording's own samples (processed
        as the fit's data were)."""
        s = preprocess(recording, self.preprocess, None)
        j = self.joint
        return _columns(s.q[:, j], s.qd[:, j], s.qdd[:, j], self.revolute) @ self.values


def identify_joint(robot: Robot, recording: Any, joint: int | str | None = None, target: str = "current",
                   *, cutoff: float | str | None = "auto", decimate: int | str = "auto"
                   ) -> JointIdentification:
    """Effective inertia, gravity and friction of one joint from a one-joint-moving recording.

    Parameters
    ----------
    robot : Robot
        For the joint names and types.
    recording : Recording
        ``t`` (N,), ``q`` (N, n) and the target (N, n); one joint moves, the others are held.
    joint : int or str, optional
        The joint to identify (index or name); default the one that moves.
    target : {"tau", "current"}
    cutoff, decimate
        As in :func:`robodyn.identification`.

    Returns
    -------
    JointIdentification

    Raises
    ------
    IdentificationError
        The requested joint never moves in the recording (its parameters are unidentifiable
        from it), no single joint moves, or the recording does not fit the robot.
    """
    from robodyn.identification.inputs import check_recording

    check_recording(robot, recording, 0, target, unobserved=True)  # other joints' sensors may be absent
    src = str(getattr(recording, "source", "") or "recording")
    span = np.ptp(unwrap_turns(recording.q), axis=0)
    if joint is None:
        j = moving_joint(recording)
        if j is None:
            moving = [robot.joint_names[k] for k in np.flatnonzero(span >= MOVING_RAD)]
            raise IdentificationError(f"{src}: q: per-joint identification needs exactly one moving "
                                      f"joint, found {moving or 'none'}; pass joint=")
    else:
        j = robot.joint_names.index(joint) if isinstance(joint, str) else int(joint)
    name = robot.joint_names[j]
    if span[j] < MOVING_RAD:
        raise IdentificationError(
            f"{src}: q: joint {name!r} never moves (position span {span[j]:.3g} < {MOVING_RAD:g}): "
            f"its inertia, gravity and friction are unidentifiable from this recording")
    if not np.isfinite(np.asarray(getattr(recording, target), float)[:, j]).any():
        raise IdentificationError(f"{src}: {target}: joint {name!r} has no data (an all-NaN column): "
                                  f"nothing to identify it from")
    settings = resolve_preprocess([recording], cutoff, decimate)
    s = preprocess(recording, settings, target)
    d = settings.decimate
    revolute = robot.joints[j].type == "revolute"
    a = _columns(s.q[::d, j], s.qd[::d, j], s.qdd[::d, j], revolute)
    y = s.y[::d, j]
    used = np.linalg.norm(a, axis=0) > 1e-12 * max(1.0, float(np.abs(a).max()))
    if a.shape[0] < 2 * int(used.sum()):
        raise IdentificationError(f"{src}: too few samples ({a.shape[0]}) for {int(used.sum())} "
                                  f"parameters of joint {name!r}")
    x_used, sv, vt, keep = truncated_lstsq(a[:, used], y)
    r = y - a[:, used] @ x_used
    sigma2 = float(r @ r) / max(a.shape[0] - int(keep.sum()), 1)
    cov = (vt[keep].T / sv[keep] ** 2) @ vt[keep] * sigma2
    values = np.zeros(len(JOINT_PARAMETERS))
    std = np.full(len(JOINT_PARAMETERS), np.inf)
    values[used] = x_used
    ok = np.zeros(len(JOINT_PARAMETERS), bool)
    ok_used = ~np.any(np.abs(vt[~keep]) > 1e-6, axis=0)
    ok[used] = ok_used
    std[np.flatnonzero(used)[ok_used]] = np.sqrt(np.diag(cov))[ok_used]
    return JointIdentification(joint=j, joint_name=name, names=JOINT_PARAMETERS, values=values,
                               std=std, identifiable=ok, target=target, preprocess=settings,
                               revolute=revolute, residual_std=float(np.sqrt(sigma2)))
