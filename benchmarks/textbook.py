"""The textbook identification baseline of ``bench_identification_quality.py`` (issue 20).

What a robotics engineer writes in an afternoon, independent of robodyn's own code path:

* Pinocchio's ``computeJointTorqueRegressor`` (n, 10 n) for the rigid body, plus per joint a
  rotor-inertia column (``qdd_j``), viscous (``qd_j``), Coulomb (``sign(qd_j)``, 0 where
  ``|qd_j| < 1e-3`` rad/s) and an offset (1);
* measured velocity and the target low-passed by a 4th-order zero-phase Butterworth at 5 Hz
  (``scipy.signal.filtfilt`` at the median sampling rate, as such a script does), acceleration
  by central differences of the filtered velocity on the time stamps; positions as measured;
* base columns by QR with column pivoting of the stacked matrix, ordinary least squares;
* for motor currents, the drive gains absorbed per joint (the fit is in amperes);
* the rows of a joint without data (an all-NaN target column: no sensor) left out.

It needs the ``pin`` package (a test and benchmark dependency).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg
import scipy.signal

#: Filter of the textbook script: order and cut-off (Hz).
ORDER, CUTOFF = 4, 5.0
#: Coulomb dead band, rad/s.
DEAD_BAND = 1e-3


def _filtered(t: np.ndarray, x: np.ndarray) -> np.ndarray:
    fs = 1.0 / float(np.median(np.diff(t)))
    b, a = scipy.signal.butter(ORDER, min(CUTOFF, 0.4 * fs) / (0.5 * fs))
    return scipy.signal.filtfilt(b, a, x, axis=0)


def _velocity(rec) -> np.ndarray:
    """Measured velocity where the recording has one, else central differences of q."""
    if rec.qd is not None and "qd" not in getattr(rec, "estimated", frozenset()):
        return np.asarray(rec.qd, float)
    return np.gradient(np.asarray(rec.q, float), np.asarray(rec.t, float), axis=0)


def _matrix(pmodel, rec) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Full textbook regressor (N, n, 14 n) of one recording, and its t and filtered qd."""
    import pinocchio as pin

    t = np.asarray(rec.t, float)
    q = np.asarray(rec.q, float)
    qd = _filtered(t, _velocity(rec))
    qdd = np.gradient(qd, t, axis=0)
    count, n = q.shape
    data = pmodel.createData()
    out = np.zeros((count, n, 14 * n))
    config = _configuration(pmodel, q)
    for k in range(count):
        out[k, :, :10 * n] = pin.computeJointTorqueRegressor(pmodel, data, config[k], qd[k], qdd[k])
    sign = np.where(np.abs(qd) < DEAD_BAND, 0.0, np.sign(qd))
    for j in range(n):
        c = 10 * n + 4 * j
        out[:, j, c:c + 4] = np.stack([qdd[:, j], qd[:, j], sign[:, j], np.ones(count)], axis=1)
    return out, t, qd


def _configuration(pmodel, q: np.ndarray) -> np.ndarray:
    """Pinocchio configurations (N, nq) of joint angles (N, n): (cos, sin) for a continuous joint."""
    parts = []
    for j, joint in enumerate(pmodel.joints[1:]):
        parts.append(np.stack([np.cos(q[:, j]), np.sin(q[:, j])], axis=1) if joint.nq == 2
                     else q[:, j:j + 1])
    return np.hstack(parts)


@dataclass(frozen=True, eq=False)
class Textbook:
    """A fitted textbook model: base columns (b,) of the (14 n) regressor and their values."""

    pmodel: object
    columns: np.ndarray
    theta: np.ndarray

    def predict(self, rec) -> np.ndarray:
        """Predicted target (N, n) at the recording's samples (same processing as the fit)."""
        y, _, _ = _matrix(self.pmodel, rec)
        return y[:, :, self.columns] @ self.theta


def pinocchio_model(urdf: str, joint_names: tuple[str, ...]):
    """Pinocchio model of ``urdf`` with only ``joint_names`` actuated (the others locked at 0)."""
    import pinocchio as pin

    full = pin.buildModelFromUrdf(urdf)
    lock = [full.getJointId(name) for name in full.names[1:] if name not in joint_names]
    model = pin.buildReducedModel(full, lock, pin.neutral(full)) if lock else full
    if tuple(model.names[1:]) != tuple(joint_names):
        raise ValueError(f"{urdf}: joints {list(model.names[1:])} differ from {list(joint_names)}")
    return model


def fit(pmodel, recordings, target: str) -> Textbook:
    """OLS of the textbook regressor on ``recordings`` against their ``target`` (5 Hz filtered)."""
    phis, ys = [], []
    for rec in recordings:
        y_full, t, _ = _matrix(pmodel, rec)
        phis.append(y_full.reshape(-1, y_full.shape[2]))
        ys.append(_filtered(t, np.asarray(getattr(rec, target), float)).reshape(-1))
    phi, y = np.vstack(phis), np.concatenate(ys)
    known = np.isfinite(y)  # a joint without data (an all-NaN column): its rows left out
    phi, y = phi[known], y[known]
    norms = np.linalg.norm(phi, axis=0)
    used = np.flatnonzero(norms > 1e-10 * norms.max())
    _, r, piv = scipy.linalg.qr(phi[:, used] / norms[used], mode="economic", pivoting=True)
    d = np.abs(np.diag(r))
    columns = np.sort(used[piv[:int(np.sum(d > 1e-8 * d[0]))]])
    theta = np.linalg.lstsq(phi[:, columns], y, rcond=None)[0]
    return Textbook(pmodel, columns, theta)


def pinocchio_model_of(robot):
    """Pinocchio model of a robodyn description, through its URDF export (a built-in robot)."""
    import pinocchio as pin

    from robodyn.export import export

    model = pin.buildModelFromXML(export(robot, "urdf"))
    if tuple(model.names[1:]) != tuple(robot.joint_names):
        raise ValueError(f"{robot.name}: joints {list(model.names[1:])} differ from "
                         f"{list(robot.joint_names)}")
    return model
