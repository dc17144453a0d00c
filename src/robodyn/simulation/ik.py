"""Numerical inverse kinematics: damped least squares on the compiled Jacobian.

Solves ``forward_kinematics(q) = target`` for the tool position (3 equations) or the full pose
(6 equations) by Levenberg-Marquardt-damped least squares::

    dq = J^T (J J^T + lambda^2 I)^-1 e

with ``e = [p_target - p; log(R_target R^T)]`` in the base frame (the model's Jacobian is
``[v; omega]`` in that frame). The damping ``lambda`` shrinks after a step that lowers ``|e|`` and
grows after one that does not, so the iteration is robust far from the solution and quadratic
near it. Joint limits (``Joint.lower``/``Joint.upper``) are kept by projection with an active set:
a joint at a limit whose step points outwards is frozen and the step is recomputed without it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from robodyn.numeric.model import Model
from robodyn.robot.errors import InputError


class UnreachableError(InputError):
    """The inverse kinematics found no joint values that reach the target within the limits.

    An :class:`~robodyn.errors.InputError` (so a :class:`~robodyn.errors.RobodynError` and a
    ``ValueError``): a target out of reach is bad input, which the command line reports in one
    line with exit code 2.
    """


@dataclass(frozen=True, eq=False)
class IKResult:
    """Outcome of :func:`inverse_kinematics`.

    Attributes
    ----------
    q : (n,) ndarray
        Best joint values found (rad or m), within the joint limits.
    success : bool
        True when ``position_error <= tol`` (and ``orientation_error <= tol`` for a full pose).
    position_error : float
        Distance from the tool origin to the target position, m.
    orientation_error : float
        Angle between the tool and target orientations, rad (0 for a position-only target).
    iterations : int
        Iterations used (all restarts together).
    at_limit : tuple of str
        Joints sitting at a limit in the returned solution.
    message : str
        Human-readable outcome; for a failure it names the target, the closest point reached and
        the joints blocked by their limits.
    """

    q: np.ndarray
    success: bool
    position_error: float
    orientation_error: float
    iterations: int
    at_limit: tuple[str, ...]
    message: str


def joint_limits(model: Model) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper joint limits of the model's robot, (n,) each; ``-inf``/``inf`` where none."""
    lower = np.array([-np.inf if j.lower is None else float(j.lower) for j in model.robot.joints])
    upper = np.array([np.inf if j.upper is None else float(j.upper) for j in model.robot.joints])
    return lower, upper


def pose_error(model: Model, q: np.ndarray, target: np.ndarray) -> np.ndarray:
    """Task-space error of ``q``: (3,) position error, or (6,) ``[dp; rotation vector]`` for a pose."""
    pose = model.forward_kinematics(q)
    if target.shape == (3,):
        return target - pose[:3, 3]
    # e_R = log(R_target R^T) as a rotation vector (base frame)
    rot = Rotation.from_matrix(target[:3, :3] @ pose[:3, :3].T).as_rotvec()
    return np.concatenate([target[:3, 3] - pose[:3, 3], rot])


def inverse_kinematics(model: Model, target: np.ndarray, q0: np.ndarray | None = None, *,
                       tol: float = 1e-10, max_iterations: int = 200, restarts: int = 8,
                       seed: int = 0, raise_on_failure: bool = True) -> IKResult:
    """Joint values that put the tool at ``target``.

    Parameters
    ----------
    model : Model
    target : (3,) or (4, 4) array_like
        Tool position in the base frame (m), solved position-only; or a homogeneous pose, solved
        for position and orientation.
    q0 : (n,) array_like, optional
        Initial guess (default: mid-range of each limited joint, 0 otherwise). The solver starts
        here, so a nearby ``q0`` selects the nearby solution branch.
    tol : float
        Convergence on the position error (m) and orientation error (rad).
    max_iterations : int
        Per start.
    restarts : int
        Further starts when the first one fails: across the gap of a revolute joint stuck at a
        limit, then from those of 256 random joint values within the limits (seeded by
        ``seed``) whose tool pose is nearest the target.
    raise_on_failure : bool
        Raise :class:`UnreachableError` (default) instead of returning ``success=False``.

    Returns
    -------
    IKResult

    Raises
    ------
    UnreachableError
        When no start converges and ``raise_on_failure`` is set; the message gives the closest
        point reached and the joints held by their limits.
    ValueError
        On a target or guess of the wrong shape, or non-finite values.
    """
    n = model.dof
    target = np.asarray(target, dtype=float)
    if target.shape not in ((3,), (4, 4)) or not np.all(np.isfinite(target)):
        raise InputError(f"inverse_kinematics: target must be a finite (3,) position or (4, 4) pose, "
                         f"got shape {target.shape}")
    lower, upper = joint_limits(model)
    if q0 is None:
        q0 = np.where(np.isfinite(lower) & np.isfinite(upper), 0.5 * (lower + upper), 0.0)
    q0 = np.asarray(q0, dtype=float)
    if q0.shape != (n,) or not np.all(np.isfinite(q0)):
        raise InputError(f"inverse_kinematics: q0 must be a finite ({n},) array, got shape {q0.shape}")
    rng = np.random.default_rng(seed)
    lo = np.where(np.isfinite(lower), lower, -np.pi)
    hi = np.where(np.isfinite(upper), upper, np.pi)
    revolute = np.array([j.type == "revolute" for j in model.robot.joints])
    pool = _sampled_starts(model, target, rng.uniform(lo, hi, (256, n)))
    best: tuple[float, np.ndarray] | None = None
    total = 0
    start = np.clip(q0, lower, upper)
    for attempt in range(restarts + 1):
        q, iters = _solve(model, target, start, lower, upper, tol, max_iterations)
        total += iters
        err = np.linalg.norm(pose_error(model, q, target)[:3]), _angle(model, q, target)
        score = max(err)
        if best is None or score < best[0]:
            best = (score, q)
        if score <= tol:
            break
        # stuck against a revolute limit: the solution may be across the gap between the limits
        stuck = revolute & ((q <= lower) | (q >= upper))
        if attempt == 0 and stuck.any():
            start = q.copy()
            start[stuck] = (lower + upper - q)[stuck]
        else:
            # then the random joint values whose tool pose is nearest the target, nearest first
            start = pool[attempt % len(pool)]
    assert best is not None
    q = best[1]
    pos_err, ang_err = float(np.linalg.norm(pose_error(model, q, target)[:3])), _angle(model, q, target)
    names = model.robot.joint_names
    span = np.maximum(upper - lower, 1.0)
    blocked = tuple(names[i] for i in range(n)
                    if min(q[i] - lower[i], upper[i] - q[i]) <= 1e-9 * span[i])
    ok = pos_err <= tol and ang_err <= tol
    if ok:
        message = f"reached in {total} iterations"
    else:
        reached = model.forward_kinematics(q)[:3, 3]
        what = "position" if target.shape == (3,) else "pose"
        goal = target if target.shape == (3,) else target[:3, 3]
        message = (f"target {what} {np.array2string(goal, precision=4)} "
                   f"is not reachable by robot {model.robot.name!r}: the closest tool position found is "
                   f"{np.array2string(reached, precision=4)} ({pos_err:.3g} m away"
                   + (f", orientation off by {ang_err:.3g} rad" if target.shape == (4, 4) else "")
                   + f") after {restarts + 1} starts"
                   + (f"; joints at a limit: {', '.join(blocked)}" if blocked else ""))
    result = IKResult(_frozen(q), ok, pos_err, ang_err, total, blocked, message)
    if not ok and raise_on_failure:
        raise UnreachableError(message)
    return result


def _sampled_starts(model: Model, target: np.ndarray, samples: np.ndarray) -> np.ndarray:
    """``samples`` sorted by the distance of their tool pose to ``target`` (one batched FK call)."""
    poses = model.forward_kinematics(samples)
    goal = target if target.shape == (3,) else target[:3, 3]
    dist = np.linalg.norm(poses[:, :3, 3] - goal, axis=1)
    if target.shape == (4, 4):
        # add the rotation angle, |log(R_target R^T)| from the trace, weighted by 0.1 m/rad
        cos = (np.einsum("ij,kij->k", target[:3, :3], poses[:, :3, :3]) - 1.0) / 2.0
        dist = dist + 0.1 * np.arccos(np.clip(cos, -1.0, 1.0))
    return samples[np.argsort(dist)]


def _angle(model: Model, q: np.ndarray, target: np.ndarray) -> float:
    if target.shape == (3,):
        return 0.0
    return float(np.linalg.norm(pose_error(model, q, target)[3:]))


def _solve(model: Model, target: np.ndarray, q: np.ndarray, lower: np.ndarray, upper: np.ndarray,
           tol: float, max_iterations: int) -> tuple[np.ndarray, int]:
    """Damped least squares from one start; returns the best q and the iterations used."""
    rows = 3 if target.shape == (3,) else 6
    e = pose_error(model, q, target)
    cost = float(e @ e)
    lam2 = 1e-4
    for it in range(1, max_iterations + 1):
        if np.sqrt(cost) <= 0.1 * tol:
            return q, it - 1
        jac = model.jacobian(q)[:rows]
        step = _projected_step(jac, e, q, lower, upper, lam2)
        q_new = np.clip(q + step, lower, upper)
        e_new = pose_error(model, q_new, target)
        cost_new = float(e_new @ e_new)
        if cost_new < cost:
            # accepted: trust the Gauss-Newton model more
            q, e, cost = q_new, e_new, cost_new
            lam2 = max(lam2 / 9.0, 1e-16)
        else:
            lam2 *= 16.0
            if lam2 > 1e8:
                break
        if cost <= tol**2 and np.linalg.norm(step) < 1e-14:
            break
    return q, it


def _projected_step(jac: np.ndarray, e: np.ndarray, q: np.ndarray, lower: np.ndarray,
                    upper: np.ndarray, lam2: float) -> np.ndarray:
    """DLS step with joints at a limit (and pushing outwards) removed from the Jacobian."""
    n = jac.shape[1]
    free = np.ones(n, dtype=bool)
    step = np.zeros(n)
    for _ in range(n + 1):
        j = jac * free
        # dq = J^T (J J^T + lambda^2 I)^-1 e
        step = j.T @ np.linalg.solve(j @ j.T + lam2 * np.eye(j.shape[0]), e)
        blocked = free & (((q <= lower) & (step < 0)) | ((q >= upper) & (step > 0)))
        if not blocked.any():
            break
        free &= ~blocked
    return step


def _frozen(a: np.ndarray) -> np.ndarray:
    a = np.array(a, dtype=float)
    a.flags.writeable = False
    return a


__all__ = ["IKResult", "UnreachableError", "inverse_kinematics", "joint_limits", "pose_error"]
