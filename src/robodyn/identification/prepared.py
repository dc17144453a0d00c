"""The processed data of one candidate of :func:`robodyn.identify` and its stacked problem.

Steps 2 to 5 of :mod:`robodyn.identification.pipeline`: preprocess each recording
(:mod:`robodyn.identification.preprocess`, rows shared between candidates that differ in the dead
band only, :class:`~robodyn.identification.preprocess.SharedRows`), the base relations, the drive
gains and the prior, the stacked identification matrix of the base columns, and
:func:`candidate_problem`, one candidate's :class:`~robodyn.identification.choices.Problem` as
:func:`~robodyn.identification.choices.choose` scores it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import sympy as sp

from robodyn.identification.base import BaseRelations, base_relations
from robodyn.identification.choices import Candidate, Problem
from robodyn.identification.drive_gains import estimate_drive_gains
from robodyn.identification.estimate import FOLDS
from robodyn.identification.friction import without_friction
from robodyn.identification.hydro_load import HydroLoad, hydro_rows
from robodyn.identification.options import IdentifyOptions
from robodyn.identification.payload import Payload, payload_standard, payload_torque
from robodyn.identification.preprocess import (
    Preprocess,
    Samples,
    SharedRows,
    prediction_rows,
    resolve_preprocess,
)
from robodyn.identification.prior import joint_prior
from robodyn.identification.thermal import ThermalData, thermal_data
from robodyn.identification.unobserved import with_data
from robodyn.numeric.model import Model
from robodyn.robot.errors import IdentificationError
from robodyn.robot.model import Robot
from robodyn.symbolic.regressor import INERTIAL_NAMES, PER_JOINT, joint_columns, parameter_values

__all__ = ["CandidateSetup", "Drive", "Prepared", "candidate_problem", "gains_and_prior",
           "nominal_standard", "prepared", "stacked_rows"]

#: Fraction of a joint's samples at rest from which its friction offset is its own base parameter.
REST_FRACTION = 0.01


def nominal_standard(robot: Robot) -> np.ndarray:
    """The description's standard parameter vector (15 n,) at its parameters' defaults."""
    subs = robot.defaults()
    return np.array([float(sp.sympify(v).xreplace(subs)) for v in parameter_values(robot)])


def stacked_rows(samples: Sequence[Samples], y_full: Sequence[np.ndarray], columns: np.ndarray,
           gains: np.ndarray, loads: Sequence[np.ndarray],
           extra: Sequence[np.ndarray] | None = None,
           observed: Sequence[np.ndarray] | None = None
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``Phi`` (m, b + e), ``y`` (m,), joint of each row, CV block of each row (m = sum N_k n);
    ``loads`` (N_k, n): the known payload torque of each recording, taken off the target;
    ``extra`` (N_k, n, e): further columns appended after the base columns (thermal friction);
    ``observed`` (n,) bool per recording: only the rows of joints with data are kept."""
    phis, ys, joints, blocks = [], [], [], []
    for i, (s, y, load) in enumerate(zip(samples, y_full, loads, strict=True)):
        count, n = s.q.shape
        rows = y[:, :, columns].reshape(count * n, -1)
        if extra is not None:
            rows = np.hstack([rows, extra[i].reshape(count * n, -1)])
        phis.append(rows)
        ys.append((s.y * gains[None, :] - load).reshape(-1))  # K_j i_j - P_j (or tau_j - P_j)
        joints.append(np.tile(np.arange(n), count))
        blocks.append(np.repeat(np.arange(count) * FOLDS // count, n))
    counts = [s.q.shape[0] for s in samples]
    return tuple(with_data(np.concatenate(a), observed, counts) for a in (phis, ys, joints, blocks))


@dataclass(frozen=True, eq=False)
class Prepared:
    """The processed data of :func:`identify` (steps 2 and 3).

    Attributes
    ----------
    settings : Preprocess
        The resolved preprocessing settings.
    model : Model
        The compiled model of the robot.
    relations : BaseRelations
        The base relations (without the friction columns for ``friction="none"``).
    samples : list of Samples
        Processed and decimated samples of each recording, (N_k, n).
    y_full : list of ndarray
        Filtered and decimated full regressor of each recording, (N_k, n, 15 n).
    count : int
        Total number of samples ``sum N_k`` after decimation.
    thermal : ThermalData or None
        The thermal friction columns (``thermal=True``).
    full : list of Samples
        The processed samples before decimation (N_k, n).
    hydro : list of ndarray or None
        The filtered hydrodynamic torque at each recording's ``full`` samples (N_k, n), N m, a
        known load like a payload's (:mod:`robodyn.identification.hydro_load`); None for a dry
        robot.
    observed : list of ndarray of bool, shape (n,), or None
        The joints with target data in each recording (:mod:`robodyn.identification.unobserved`);
        None: all.
    """

    settings: Preprocess
    model: Model
    relations: BaseRelations
    samples: list[Samples]
    y_full: list[np.ndarray]
    count: int
    thermal: ThermalData | None = None
    full: list[Samples] | None = None
    hydro: list[np.ndarray] | None = None
    observed: list[np.ndarray] | None = None


@dataclass(frozen=True, eq=False)
class Drive:
    """The drive gains of :func:`identify` and where they come from.

    Attributes
    ----------
    k : ndarray, shape (n,)
        Drive gain of each joint, N m / A (ones when absorbed or for ``target="tau"``).
    source : str
        Where ``k`` comes from (``Identification.gains_source``).
    std : ndarray, shape (n,)
        Standard deviation of ``k``, N m / A (inf when absorbed, NaN when unknown).
    """

    k: np.ndarray
    source: str
    std: np.ndarray


def prepared(robot: Robot, recs: list[Any], target: str, friction: str, cutoff: float | str | None,
              decimate: int | str, velocity: str, dead_band: float, model: Model,
              thermal: bool = False, sensor: str = "motor", rule: float | None = None,
              shared: SharedRows | None = None, hydro: HydroLoad | None = None) -> Prepared:
    """Preprocessed samples, filtered regressors and base relations of ``recs`` (steps 2 and 3).

    ``rule``: the recordings' "auto" cut-off when already computed (Hz); ``shared``: the
    samples and rows of the settings seen before in this identification. Raises
    :class:`IdentificationError` when the
    ``sum N_k n`` equations left after decimation are fewer than twice the ``b`` base parameters.
    """
    settings = resolve_preprocess(recs, cutoff, decimate, velocity, dead_band=dead_band, auto=rule)
    full, y_full = (shared or SharedRows(model)).get(recs, settings, target)
    # the fluid's torque, from the description: a known load (taken off in gains_and_prior)
    taken = None if hydro is None else hydro_rows(hydro, full, settings)
    samples = [decimated(s, settings) for s in full]
    rotor = np.arange(robot.dof) * PER_JOINT + len(INERTIAL_NAMES)
    relations = base_relations(model, at_rest=at_rest(samples, settings.dead_band),
                               unseen=rotor if sensor == "link" else None)
    if friction == "none":
        relations = without_friction_columns(relations)
    count = sum(s.q.shape[0] for s in samples)
    b = relations.independent.size
    if count * robot.dof < 2 * b:
        raise IdentificationError(
            f"recordings: too few samples for the parameters: {count} samples x {robot.dof} joints "
            f"= {count * robot.dof} equations after decimation by {settings.decimate} for {b} base "
            f"parameters (at least {2 * b} needed; record longer or pass decimate=1)")
    return Prepared(settings, model, relations, samples, y_full, count,
                     thermal_data(recs, full, settings) if thermal else None, full, taken)


def at_rest(samples: Sequence[Samples], band: float) -> np.ndarray:
    """Joints (n,) bool with at least ``REST_FRACTION`` of their fitted samples at rest
    (``|qd| < band``, or exactly 0: a joint held still): their offset ``Fo`` is then seen alone."""
    qd = np.abs(np.vstack([s.qd for s in samples]))
    rest = (qd < band) | (qd == 0.0)
    return np.mean(rest, axis=0) >= REST_FRACTION


def gains_and_prior(robot: Robot, data: Prepared, pays: list[Payload | None], target: str,
                     gains: str, friction: str, sensor: str = "motor"
                     ) -> tuple[Drive, np.ndarray, list[np.ndarray]]:
    """Drive gains, the prior (15 n,) and the known torque (N_k, n), N m, of each recording: its
    payload's and an underwater arm's hydrodynamic torque (step 5).

    With ``target="current"`` and a payload in some recording, the gains are estimated from the
    payload runs (:func:`payload_gains`); for ``friction="none"`` the prior has no friction.
    """
    nominal = nominal_standard(robot)
    loads = [np.zeros_like(s.q) if p is None else payload_torque(y, payload_standard(robot, p))
             for s, y, p in zip(data.samples, data.y_full, pays, strict=True)]
    if data.hydro is not None:  # the fluid's torque at the decimated samples
        d = data.settings.decimate
        loads = [load + h[::d] for load, h in zip(loads, data.hydro, strict=True)]
    has_payload = any(p is not None for p in pays)
    k, k_source, prior = joint_prior(robot, data.samples, data.y_full, nominal, target, gains,
                                     loads, data.observed)
    drive = Drive(k, k_source, np.full(robot.dof, np.inf if k_source.startswith("absorbed") else np.nan))
    if target == "current" and has_payload:
        drive, prior = payload_gains(robot, data, loads, drive, prior)
    if friction == "none":
        prior = without_friction(prior)
    if sensor == "link":
        prior = prior.copy()
        prior[len(INERTIAL_NAMES)::PER_JOINT] = 0.0  # Ia: the sensor does not see the rotor
    return drive, prior, loads


def payload_gains(robot: Robot, data: Prepared, loads: list[np.ndarray], drive: Drive,
                   prior: np.ndarray) -> tuple[Drive, np.ndarray]:
    """Drive gains (n,), N m / A, estimated from runs with and without a payload.

    ``loads`` (N_k, n) is the payload torque of each recording, N m. Returns the gains and a
    copy of ``prior`` (15 n,) whose drive and friction terms, fitted in the units of
    ``drive.k``, are rescaled to the estimated gains.
    """
    k = drive.k
    phi, y, joint, _ = stacked_rows(data.samples, data.y_full, data.relations.independent, np.ones(robot.dof),
                              [np.zeros_like(x) for x in loads], observed=data.observed)
    known = with_data(np.concatenate([x.reshape(-1) for x in loads]), data.observed,
                      [len(x) for x in loads])
    seen = np.unique(joint)  # a joint without data keeps its gain (std inf: not estimated)
    est = estimate_drive_gains(phi, y, known, np.searchsorted(seen, joint),
                               tuple(robot.joint_names[j] for j in seen))
    gains, std = k.copy(), np.full(robot.dof, np.inf)
    gains[seen], std[seen] = est.gains, est.std
    # the prior's drive and friction terms were fitted in the units of the absorbed gains
    prior = prior.copy()
    for j in range(robot.dof):
        prior[joint_columns(j)] *= gains[j] / k[j]
    return Drive(gains, "payload", std), prior


def without_friction_columns(relations: BaseRelations) -> BaseRelations:
    """The base relations with the friction parameters (Fv, Fcp, Fcn, Fo) left out; they only
    ever combine among themselves, so the other base parameters are unchanged."""
    keep = np.array([c % PER_JOINT <= len(INERTIAL_NAMES) for c in relations.independent])
    return replace(relations, independent=relations.independent[keep], beta=relations.beta[keep])


def decimated(s: Samples, settings: Preprocess) -> Samples:
    d = settings.decimate
    if d == 1:
        return s
    return Samples(s.t[::d], s.q[::d], s.qd[::d], s.qdd[::d], None if s.y is None else s.y[::d],
                   s.source)


@dataclass(frozen=True, eq=False)
class CandidateSetup:
    """What every candidate of one :func:`robodyn.identify` call shares.

    Attributes
    ----------
    robot, recs, target, pays, opts, model, hydro, observed
        The call's robot, checked recordings, target, payloads (one per recording), options,
        compiled model, underwater load (None for a dry robot) and joints with data.
    rule : float or None
        The recordings' "auto" cut-off, computed once (Hz).
    shared : SharedRows
        The samples and rows of the settings seen before in this call.
    reference : list of ndarray
        The common held-out target of every candidate, (N_k, n) per recording.
    """

    robot: Robot
    recs: list[Any]
    target: str
    pays: list[Payload | None]
    opts: IdentifyOptions
    model: Model
    hydro: HydroLoad | None
    observed: list[np.ndarray]
    rule: float | None
    shared: SharedRows
    reference: list[np.ndarray]


def candidate_problem(setup: CandidateSetup, c: Candidate) -> Problem:
    """The identification problem of candidate ``c`` (its processing) as
    :func:`~robodyn.identification.choices.choose` scores it; its ``payload`` is
    ``(Prepared, Drive, prior (15 n,), loads (N_k, n) per recording)``."""
    st, opts = setup, setup.opts
    data = replace(prepared(st.robot, st.recs, st.target, opts.friction, c.cutoff, opts.decimate,
                            c.velocity, c.dead_band, st.model, c.thermal, opts.sensor, st.rule,
                            st.shared, st.hydro), observed=st.observed)
    drive, prior, loads = gains_and_prior(st.robot, data, st.pays, st.target, opts.gains,
                                          opts.friction, opts.sensor)
    cols, th = data.relations.independent, data.thermal
    phi, y, joint, blocks = stacked_rows(data.samples, data.y_full, cols, drive.k, loads,
                                         None if th is None else th.fit_rows, data.observed)
    test = [prediction_rows(st.model, s, data.settings)[:, :, cols] for s in data.samples]
    if th is not None:
        test = [np.concatenate([a, b], axis=2) for a, b in zip(test, th.test_rows, strict=True)]
    theta0 = np.concatenate([data.relations.to_base(prior), np.zeros(phi.shape[1] - cols.size)])
    d = data.settings.decimate
    # the common held-out target at the same samples, torque units, known loads taken off
    held = np.concatenate([(ref[::d] * drive.k - load).reshape(-1)
                           for ref, load in zip(st.reference, loads, strict=True)])
    counts = [s.q.shape[0] for s in data.samples]
    test = with_data(np.vstack([a.reshape(-1, phi.shape[1]) for a in test]), data.observed, counts)
    return Problem(phi, y, theta0, joint, blocks, test, with_data(held, data.observed, counts),
                   (data, drive, prior, loads))
