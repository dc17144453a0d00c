"""Position ripple: a torque periodic in a joint's own angle, fitted after the rigid-body model.

What a rigid-body model with friction leaves of a real joint's torque often repeats once per
revolution of that joint: a gear's or a torque sensor's once-per-turn error (eccentricity,
cogging, strain-gauge crosstalk), a cable pulled around the axis, a base mounted slightly off
level (gravity then acts on a vertical first axis). The model adds to joint ``j`` (revolute)::

    tau_R,j = a_j sin(q_j) + b_j cos(q_j)

It is fitted after the identification, like the nonlinear friction laws
(:mod:`robodyn.identification.friction`): with the identified parameters fixed, what they leave
of the (filtered) target, ``r = K H(y) - H(Y) p`` (the friction law's torque taken off for a
nonlinear law), is regressed joint by joint on the low-passed ``sin q_j, cos q_j`` and a
constant ``c_j`` (the friction offset has already taken the ripple's mean over the run: without
the constant the coefficients would be biased by it, with it ``c_j`` hands that mean back and the
prediction adds ``a_j sin q_j + b_j cos q_j + c_j``). After the
rigid body, not with it: the first moments of a link carry the same harmonics of its joint
angle through gravity, and a joint fit would trade one for the other; fitted on what the
rigid body leaves, the ripple only takes what the rigid-body model cannot explain.

``ripple="auto"`` (the default of :func:`robodyn.identify`) keeps it only when it predicts
held-out time blocks of that residual (:data:`robodyn.identification.estimate.FOLDS` per
recording) better than no ripple by more than one standard error of the paired block
differences (the rule of :mod:`robodyn.identification.choices`) and by more than
:data:`~robodyn.identification.friction_choice.MIN_GAIN` of its error. A description cannot hold
it: :meth:`Identification.predict` adds it, the written robot does not.

Only a joint whose travel in the fit data separates ``sin q_j``, ``cos q_j`` and the constant
carries one (:func:`separated_joints`): over a short travel the three columns are nearly
dependent (``sin q ~ q``, ``cos q ~ 1 - q^2 / 2``), the least-squares coefficients grow like
the inverse of their separation, and the fitted curve is a polynomial in ``q_j`` that held-out
time blocks, at the same positions, cannot refute. Measured on a virtual PUMA 560 whose joints
moved about 0.01 rad each (2026-12-07): a ripple of 8e4 N m amplitude in each of its terms,
kept by the time blocks, predicted another run at other positions with a relative error of
653 (0.41 without it).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from robodyn.identification.estimate import FOLDS, paired_se
from robodyn.identification.friction_choice import MIN_GAIN
from robodyn.identification.preprocess import Preprocess, Samples, evaluation_step, filtered_rows

__all__ = ["RippleFit", "choose_ripple", "fit_ripple", "gravity_free_joints", "ripple_columns",
           "ripple_rows", "separated_joints", "with_ripple"]

#: Relative residual below which ``sin q_j, cos q_j`` count as explained by joint ``j``'s gravity
#: columns (:func:`gravity_free_joints`).
SPAN_TOL = 1e-3
#: Directions of the gravity columns weaker than this fraction of the strongest (over all joints)
#: do not count: a description's rounding (an axis tilted by 1e-5 rad) is no gravity torque.
WEAK = 1e-4
#: Random postures at which the gravity columns are evaluated.
POSTURES = 64
#: Least separation of a joint's unit-norm columns ``(sin q_j, cos q_j, 1)`` over the fit samples
#: (smallest singular value over the largest) for it to carry a ripple: 1 over a whole turn,
#: 0.02 over a travel of about 1.1 rad (coefficients then up to about 50 times the residual's
#: noise), 1.6e-4 over 0.1 rad. The KUKA LWR4+ runs' joints have 0.03-0.53.
MIN_SEPARATION = 0.02


def ripple_columns(q: np.ndarray, revolute: np.ndarray) -> np.ndarray:
    """``(sin q_j, cos q_j)`` of each revolute joint, (N, n, 2); zeros for a prismatic joint.

    Parameters
    ----------
    q : numpy.ndarray, shape (N, n)
        Joint positions, rad (m).
    revolute : numpy.ndarray of bool, shape (n,)
    """
    out = np.stack([np.sin(q), np.cos(q)], axis=2)
    out[:, ~np.asarray(revolute, bool), :] = 0.0
    return out


def ripple_rows(full: Sequence[Samples], settings: Preprocess, revolute: np.ndarray) -> list[np.ndarray]:
    """The ripple columns of processed samples ``full`` (not decimated), low-passed with the
    target's filter and decimated like the fit's regressor rows: (N_k / d, n, 2) each."""
    d = settings.decimate
    out = []
    for s in full:
        m = evaluation_step(s.t, settings, d)
        out.append(filtered_rows(s.t[::m], ripple_columns(s.q[::m], revolute), settings, d // m))
    return out


def gravity_free_joints(model: Any, revolute: np.ndarray, seed: int = 0) -> np.ndarray:
    """The revolute joints whose own angle's first harmonic is not a gravity torque of theirs.

    Joint ``j`` qualifies unless ``sin q_j`` and ``cos q_j`` lie in the span of its row of the
    regressor at rest, ``Y(q, 0, 0)[j, :]`` over all postures (tested at :data:`POSTURES`
    random postures: relative least-squares residual below :data:`SPAN_TOL`). Where they lie in
    it (a shoulder or elbow lifting its own link) a ripple would be the same function of the
    posture as the first moments of the link it lifts, and fitted after a fit pulled toward a
    description it would take up the gravity the rigid-body parameters leave, which does not
    carry over to postures held still; a vertical first axis or a roll joint keeps it.

    Parameters
    ----------
    model : Model
        Compiled model (its regressor).
    revolute : numpy.ndarray of bool, shape (n,)
    seed : int
        Seed of the random postures (the test does not depend on it beyond rounding).

    Returns
    -------
    numpy.ndarray of bool, shape (n,)
    """
    from robodyn.identification.stacking import regressor_rows_of

    revolute = np.asarray(revolute, bool)
    n = revolute.size
    q = np.random.default_rng(seed).uniform(-np.pi, np.pi, (POSTURES, n))
    zero = np.zeros_like(q)
    rows = regressor_rows_of(model, q, zero, zero)  # Y(q, 0, 0), (POSTURES, n, 15 n)
    bases = [np.linalg.svd(rows[:, j, :], full_matrices=False)[:2] for j in range(n)]
    strongest = max(float(s[0]) for _, s in bases if s.size)
    keep = revolute.copy()
    for j in np.flatnonzero(revolute):
        u, s = bases[j]
        u = u[:, s > WEAK * strongest]  # the joint's gravity (and offset) directions
        harmonics = np.column_stack([np.sin(q[:, j]), np.cos(q[:, j])])
        left = np.linalg.norm(harmonics - u @ (u.T @ harmonics)) / np.linalg.norm(harmonics)
        keep[j] = bool(left > SPAN_TOL)  # not explained by its gravity columns
    return keep


def separated_joints(q: np.ndarray, revolute: np.ndarray) -> np.ndarray:
    """The revolute joints whose positions separate their ripple from a constant.

    Parameters
    ----------
    q : numpy.ndarray, shape (N, n)
        The fit data's joint positions, rad (m).
    revolute : numpy.ndarray of bool, shape (n,)

    Returns
    -------
    numpy.ndarray of bool, shape (n,)
        ``revolute`` and the separation of ``(sin q_j, cos q_j, 1)`` at least
        :data:`MIN_SEPARATION`.
    """
    q = np.asarray(q, dtype=float)
    keep = np.asarray(revolute, bool).copy()
    for j in np.flatnonzero(keep):
        cols = np.column_stack([np.sin(q[:, j]), np.cos(q[:, j]), np.ones(q.shape[0])])
        s = np.linalg.svd(cols / np.linalg.norm(cols, axis=0), compute_uv=False)
        keep[j] = bool(s[-1] >= MIN_SEPARATION * s[0])  # nearly dependent over a short travel
    return keep


@dataclass(frozen=True, eq=False)
class RippleFit:
    """Ripple coefficients per joint (module docstring), target-torque units (N m).

    Attributes
    ----------
    sine : numpy.ndarray, shape (n,)
        ``a_j``, N m.
    cosine : numpy.ndarray, shape (n,)
        ``b_j``, N m.
    revolute : numpy.ndarray of bool, shape (n,)
        The joints that carry a ripple.
    offset : numpy.ndarray, shape (n,)
        ``c_j``, N m: the correction of the friction offset that comes with the ripple.
    """

    sine: np.ndarray
    cosine: np.ndarray
    revolute: np.ndarray
    offset: np.ndarray

    def torque(self, q: np.ndarray) -> np.ndarray:
        """``a sin q + b cos q + c`` (N, n), N m, at positions ``q`` (N, n), rad."""
        cols = ripple_columns(q, self.revolute)
        return (cols[:, :, 0] * self.sine[None, :] + cols[:, :, 1] * self.cosine[None, :]
                + self.offset[None, :])


def _lstsq(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``(a_j, b_j, c_j)`` of ``b ~ a[:, 0] a_j + a[:, 1] b_j + c_j``, ``a`` (N, 2), ``b`` (N,)."""
    cols = np.column_stack([a, np.ones(a.shape[0])])
    return np.linalg.lstsq(cols, b, rcond=1e-9)[0]


def _apply(a: np.ndarray, coef: np.ndarray) -> np.ndarray:
    return a @ coef[:2] + coef[2]  # a sin q + b cos q + c


def fit_ripple(residual: np.ndarray, rows: np.ndarray, revolute: np.ndarray) -> RippleFit:
    """Least-squares ripple of each joint.

    Parameters
    ----------
    residual : numpy.ndarray, shape (N, n)
        What the identified model leaves of the filtered target, N m.
    rows : numpy.ndarray, shape (N, n, 2)
        The filtered ripple columns of the same samples (:func:`ripple_rows`, stacked).
    revolute : numpy.ndarray of bool, shape (n,)
    """
    n = residual.shape[1]
    coef = np.zeros((n, 3))
    for j in np.flatnonzero(revolute):
        coef[j] = _lstsq(rows[:, j, :], residual[:, j])  # r_j = a sin q_j + b cos q_j + c
    return RippleFit(coef[:, 0], coef[:, 1], np.asarray(revolute, bool), coef[:, 2])


def choose_ripple(residual: np.ndarray, rows: np.ndarray, blocks: np.ndarray, revolute: np.ndarray
                  ) -> tuple[bool, dict[str, float]]:
    """Whether the ripple predicts held-out blocks of the residual better than none.

    Parameters
    ----------
    residual : numpy.ndarray, shape (N, n)
        What the identified model leaves of the filtered target, N m.
    rows : numpy.ndarray, shape (N, n, 2)
        Filtered ripple columns.
    blocks : numpy.ndarray of int, shape (N,)
        Time block of each sample, 0 .. FOLDS - 1.
    revolute : numpy.ndarray of bool, shape (n,)

    Returns
    -------
    (bool, dict of str to float)
        The choice, and the relative held-out error of the residual without and with the ripple
        (``sqrt(sum e^2 / sum e_none^2)`` over all blocks and joints: 1 for none).
    """
    none, with_ = np.zeros(FOLDS), np.zeros(FOLDS)
    for k in range(FOLDS):
        train, test = blocks != k, blocks == k
        if not test.any() or not train.any():
            continue
        # without: the training blocks' mean; with: their ripple and constant
        mean = np.mean(residual[train], axis=0)
        none[k] = float(np.sum((residual[test] - mean) ** 2))
        pred = np.broadcast_to(mean, residual[test].shape).copy()
        for j in np.flatnonzero(revolute):
            pred[:, j] = _apply(rows[test, j, :], _lstsq(rows[train, j, :], residual[train, j]))
        with_[k] = float(np.sum((residual[test] - pred) ** 2))
    total = max(float(np.sum(none)), 1e-300)
    scores = {"none": float(np.sqrt(none.sum() / total)), "ripple": float(np.sqrt(with_.sum() / total))}
    d = with_ - none
    return bool(d.sum() < -max(paired_se(d), MIN_GAIN * none.sum())), scores


def block_of(samples: Sequence[Samples]) -> np.ndarray:
    """The time block (0 .. FOLDS - 1) of every stacked sample, (sum N_k,)."""
    return np.concatenate([np.arange(s.q.shape[0]) * FOLDS // s.q.shape[0] for s in samples])


def residual_of(ident: Any, samples: Sequence[Samples], y_full: Sequence[np.ndarray]) -> np.ndarray:
    """What ``ident`` leaves of the filtered target of ``samples``, (sum N_k, n), N m: the linear
    model's ``K H y - H Y p``, or with a nonlinear friction law ``K H y - H Y p_nf - f(qd, H Y p_nf)``."""
    y = np.vstack([s.y for s in samples]) * ident.gains[None, :]
    if ident.friction_fit is None:
        return y - np.vstack([a @ ident.standard for a in y_full])  # r = K H y - H Y p
    from robodyn.identification.friction import without_friction

    p_nf = without_friction(ident.standard)
    load = np.vstack([a @ p_nf for a in y_full])
    qd = np.vstack([s.qd for s in samples])
    return y - load - ident.friction_fit.torque(qd, load)  # r = K H y - H Y p_nf - f


def with_ripple(result: Any, full: Sequence[Samples], samples: Sequence[Samples],
                y_full: Sequence[np.ndarray], settings: Preprocess, revolute: np.ndarray,
                ripple: bool | str) -> Any:
    """The identification ``result`` with the position ripple fitted on what it leaves.

    Parameters
    ----------
    result : Identification
    full : sequence of Samples
        The processed samples before decimation, (N_k, n) each.
    samples : sequence of Samples
        The same decimated, with the filtered target.
    y_full : sequence of numpy.ndarray, shape (N_k, n, 15 n)
        The fit's filtered regressor rows of ``samples``.
    settings : Preprocess
    revolute : numpy.ndarray of bool, shape (n,)
        The joints that may carry one; those whose travel in ``full`` does not separate it from
        a constant (:func:`separated_joints`) carry none, even with ``ripple=True``.
    ripple : bool or "auto"
        Always, never, or when it predicts held-out blocks better (``result.choices`` then
        records the choice and the scores).
    """
    if ripple is False or not np.any(revolute):
        return result
    revolute = separated_joints(np.vstack([s.q for s in full]), revolute)
    if not np.any(revolute):  # no joint travels far enough: none, and the choice says why
        return replace(result, choices=replace(result.choices, ripple=False, ripple_scores=())) \
            if ripple == "auto" else result
    rows = np.vstack(ripple_rows(full, settings, revolute))
    residual = residual_of(result, samples, y_full)
    if ripple == "auto":
        keep, scores = choose_ripple(residual, rows, block_of(samples), revolute)
        result = replace(result, choices=replace(result.choices, ripple=keep,
                                                 ripple_scores=tuple(scores.items())))
        if not keep:
            return result
    return replace(result, ripple_fit=fit_ripple(residual, rows, revolute))
