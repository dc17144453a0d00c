"""``rd.identify``: inertial, drive and friction parameters from measured motion and effort.

Steps (each a function of its own module):

1. check the recordings (joints, shapes, finite values, a target signal);
2. preprocess each recording (:mod:`robodyn.identification.preprocess`: zero-phase filter, derivatives,
   the same filter on the target; ``regressor_rows``: the same filter on every column of the
   regressor, then decimation; candidates that differ only in the dead band share both,
   :class:`~robodyn.identification.preprocess.SharedRows`);
3. base parameters of the robot (:mod:`robodyn.identification.base`, Gautier's QR on random states);
4. identification matrix: the compiled, batched regressor ``Y(q, qd, qdd)`` (N, n, 15 n) of every
   sample, restricted to the base columns and stacked, one row per joint per sample;
5. the prior (:mod:`robodyn.identification.prior`): the description's inertial parameters with each
   joint's rotor inertia and friction (and, for ``target="current"``, its drive gain ``K_j``,
   N m / A) fitted joint by joint; rows of a current target are scaled by ``K_j`` so that the fit
   is in torque units, ``K_j i_j = Y_j p``;
6. estimate (:mod:`robodyn.identification.estimate`, :mod:`robodyn.identification.consistent`);
7. the full standard parameter set and a :class:`Robot` carrying it.

Steps 2 to 5 for one candidate processing are :mod:`robodyn.identification.prepared`; the
candidates are scored by :func:`robodyn.identification.choices.choose`, and the velocity source
kept by :func:`robodyn.identification.velocity_choice.kept_source`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from functools import partial
from typing import Any

import numpy as np

from robodyn.identification.bandwidth import check_prediction_cutoff
from robodyn.identification.base import BaseRelations
from robodyn.identification.choices import (
    Candidate,
    Choices,
    Problem,
    candidates,
    choose,
    cutoff_candidates,
    reference_targets,
)
from robodyn.identification.completion import completed, consistent_completion
from robodyn.identification.estimate import FOLDS, LinearFit, fit_linear
from robodyn.identification.hydro_load import hydro_load
from robodyn.identification.inputs import check_recording, checked_inputs
from robodyn.identification.options import IdentifyOptions
from robodyn.identification.payload import Payload
from robodyn.identification.prediction_terms import with_model_terms
from robodyn.identification.prepared import (
    CandidateSetup,
    Drive,
    Prepared,
    candidate_problem,
    nominal_standard,
    stacked_rows,
)
from robodyn.identification.preprocess import DEAD_BAND, SharedRows, auto_cutoff
from robodyn.identification.result import BaseParameters, Identification
from robodyn.identification.spikes import without_spikes
from robodyn.identification.state_noise import state_noise_std, torque_variance
from robodyn.identification.thermal import ThermalFit
from robodyn.identification.to_robot import robot_with_parameters
from robodyn.identification.unobserved import (
    filled,
    imputed_samples,
    note_unobserved,
    observed_joints,
    seen_joints,
    unobserved_names,
    with_data,
)
from robodyn.identification.velocity_choice import kept_source
from robodyn.keywords import resolve
from robodyn.numeric.model import Model, compile_model
from robodyn.robot.errors import IdentificationError
from robodyn.robot.model import Robot

__all__ = ["check_recording", "identify", "nominal_standard"]

#: Floor of the measurement variance, as a fraction of the first fit's residual variance.
MEAS_FLOOR = 0.01
#: Unit directions whose singular value is below this fraction of the largest are reported.
UNEXCITED_RTOL = 1e-6


def identify(robot: Robot, recordings: Any, target: str | None = None, method: str = "consistent", *,
             friction: str = "auto", regularization: float | str | None = "auto",
             cutoff: float | str | None = "auto", decimate: int | str = "auto",
             velocity: str = "auto", dead_band: float | str = 0.0,
             coulomb_width: float | str = "auto", gains: str = "auto",
             bounds: dict[str, tuple[float, float]] | None = None, model: Model | None = None,
             payloads: Sequence[Payload | None] | None = None, weights: str = "residual",
             state_noise: Any = None, thermal: bool | str = False, sensor: str = "motor",
             spikes: str = "auto", ripple: bool | str = "auto", resonance: bool | str = "auto",
             prediction_cutoff: float | str = "motion", local: bool | str = "auto",
             options: IdentifyOptions | None = None) -> Identification:
    """Identify the base inertial, drive and friction parameters of a robot from recordings.

    Parameters
    ----------
    robot : Robot
        The nominal description (with per-joint drive and friction fits, the prior of the
        regularisation: :mod:`robodyn.identification.prior`).
    recordings : Recording or sequence of Recording
        Measured runs, joints in the robot's order: ``t`` (N,) s, ``q`` (N, n) and the target
        ``tau`` or ``current`` (N, n).
    target : {"tau", "current"}, optional
        Default: ``"tau"`` when every recording has torques, else ``"current"``.
    method, friction, regularization, cutoff, decimate, velocity, dead_band, coulomb_width
        The choices: the attributes of the same names of
        :class:`~robodyn.identification.options.IdentifyOptions` (what each does, its values
        and default). ``method``: "ols", "wls" or "consistent" (default).
    gains, bounds, weights, state_noise, thermal, sensor, spikes, ripple, resonance,
    prediction_cutoff, local
        Likewise.
    model : Model, optional
        A compiled model of ``robot`` to reuse (default ``rd.compile_model(robot)``).
    payloads : sequence of Payload or None, optional
        One per recording: the known payload attached to the last link during that run (None:
        none). Its torque is taken off the target; with ``target="current"``, a payload run
        together with a run without it (or with another payload) identifies the drive gains
        (:mod:`robodyn.identification.drive_gains`; ``gains_source="payload"``, ``gains_std``).
        ``ident.robot`` is the robot without payloads.
    options : IdentifyOptions, optional
        All the choices at once, instead of the keywords (a keyword other than its default
        given as well is refused); ``ident.options`` is the set a run used.

    Returns
    -------
    Identification

    Raises
    ------
    IdentificationError
        Joints not matching the robot, NaN, a missing target, too few samples for the
        parameters, an unknown option, an infeasible or failed semidefinite program.
    """
    opts = resolve(IdentifyOptions, options, dict(
        method=method, friction=friction, regularization=regularization, cutoff=cutoff,
        decimate=decimate, velocity=velocity, dead_band=dead_band, coulomb_width=coulomb_width,
        gains=gains, bounds=bounds, weights=weights, state_noise=state_noise, thermal=thermal,
        sensor=sensor, spikes=spikes, ripple=ripple, resonance=resonance,
        prediction_cutoff=prediction_cutoff, local=local),
        IdentificationError)
    recs, target, pays = checked_inputs(robot, recordings, target, opts.sensor, payloads)
    observed = observed_joints(recs, target)
    note_unobserved(observed, robot.joint_names, target)
    recs = filled(recs, target, observed)  # copies: a joint without data holds 0, its rows unused
    check_prediction_cutoff(recs, opts.prediction_cutoff)
    recs = without_spikes(recs, target, opts.spikes)  # glitches of the fit's recordings (spikes, bursts)
    model = model if model is not None else compile_model(robot)
    hydro = hydro_load(robot, model)  # None for a dry robot
    measured = all(r.qd is not None and "qd" not in getattr(r, "estimated", frozenset()) for r in recs)
    temps = all(getattr(r, "temperature", None) is not None for r in recs)

    # the "auto" cut-off's rule, computed once for every candidate that uses it
    rule = auto_cutoff(recs) if opts.cutoff == "auto" else None
    cutoffs = cutoff_candidates(recs, opts.cutoff, rule)
    cands = candidates(opts.velocity, opts.dead_band, opts.thermal, measured, temps, DEAD_BAND, cutoffs)
    # samples and rows shared by the candidates that differ in the band only
    setup = CandidateSetup(robot, recs, target, pays, opts, model, hydro, observed, rule,
                           SharedRows(model), reference_targets(recs, target, cutoffs[0], rule))
    # each velocity source's candidates chosen by the blocks, its model finished; the source by
    # the finished models' fit (robodyn.identification.velocity_choice)
    winners, scored = choose(cands, partial(candidate_problem, setup))
    setup.shared.clear()
    return kept_source(winners, scored, partial(_model_fit, robot, recs, pays, target,
                                                observed=observed, hydro=hydro), opts, pays, target)


def _model_fit(robot: Robot, recs: list[Any], pays: list[Payload | None], target: str,
               opts: IdentifyOptions, best: Candidate, problem: Problem, scored: list[Candidate], *,
               observed: list[np.ndarray], hydro: Any) -> tuple[Identification, list[Any]]:
    """The model of the chosen candidate ``best`` (its ``problem``; ``scored``: its group's
    candidates): the linear step, the full parameters and the terms of
    :func:`~robodyn.identification.prediction_terms.with_model_terms`; with the recordings the
    later steps see."""
    data, drive, prior, loads = problem.payload
    # the consistent program's constraints bound what the weight bounds for least squares: its
    # weight is the smallest within one standard error of the best (estimate.cv_weight)
    reg = "auto-least" if opts.regularization == "auto" and opts.method == "consistent" \
        else opts.regularization
    step, thermal_fit = _linear_step(robot, data, drive.k, loads, prior, opts.method, reg,
                                     opts.weights, opts.state_noise)
    theta, standard = _estimate_standard(robot, data.relations, step, prior, opts.method, opts.bounds)
    result = _identification(robot, data, step, theta, standard, drive, target, opts.method)
    reason = (f"held-out time blocks ({FOLDS} per recording), {len(scored)} candidates: the plain "
              "processing unless another is better by more than one standard error"
              if len(scored) > 1 else "as given")
    result = replace(result, choices=Choices(best.velocity, best.dead_band, data.settings.cutoff,
                                             step.fit.lam, tuple(scored), reason, best.thermal, best),
                     thermal_fit=thermal_fit, hydro=hydro)
    # the terms fitted after the linear step see the target without the known loads and the
    # thermal friction too (the linear step took them off; K y - P - tau_T = Y p, so
    # y - (P + tau_T) / K in the target's unit)
    known = loads if thermal_fit is None else [
        load + rows @ thermal_fit.coefficients
        for load, rows in zip(loads, data.thermal.fit_rows, strict=True)]
    samples = [s if not np.any(k) else replace(s, y=s.y - k / result.gains[None, :])
               for s, k in zip(data.samples, known, strict=True)]
    samples = imputed_samples(samples, data.y_full, standard, result.gains, observed)
    # a joint without data anywhere has no residual
    result = replace(result, unobserved=unobserved_names(observed, robot.joint_names),
                     residual_std=np.where(seen_joints(observed), result.residual_std, np.nan))
    return with_model_terms(result, recs, pays, target, opts, samples, data.y_full, data.full,
                            data.settings, observed)


@dataclass(frozen=True, eq=False)
class _LinearStep:
    """The stacked identification problem of :func:`identify` and its linear fit (m = sum N_k n).

    Attributes
    ----------
    phi : ndarray, shape (m, b)
        Identification matrix restricted to the base columns.
    y : ndarray, shape (m,)
        Target in torque units with the payload torque taken off, N m.
    joint : ndarray, shape (m,)
        Joint of each row.
    blocks : ndarray, shape (m,)
        Cross-validation block of each row.
    theta0 : ndarray, shape (b,)
        Base parameters of the prior.
    fit : LinearFit
        The (weighted) least-squares fit.
    """

    phi: np.ndarray
    y: np.ndarray
    joint: np.ndarray
    blocks: np.ndarray
    theta0: np.ndarray
    fit: LinearFit


def _linear_step(robot: Robot, data: Prepared, k: np.ndarray, loads: list[np.ndarray],
                 prior: np.ndarray, method: str, regularization: float | str | None, weights: str,
                 state_noise: Any) -> tuple[_LinearStep, ThermalFit | None]:
    """The stacked problem and its (weighted) least-squares fit toward ``prior`` (steps 4 and 6),
    and the thermal friction fit (None without ``data.thermal``).

    ``k`` (n,) are the drive gains, N m / A, ``loads`` (N_k, n) the payload torques, N m, and
    ``prior`` (15 n,) the standard parameters of the prior. With thermal columns the thermal
    coefficients are estimated together with the base parameters (toward 0), their torque is
    then taken off the target and the base parameters fitted again alone, so that every later
    step (weights, the consistent program) sees the base columns only.
    """
    th, cols = data.thermal, data.relations.independent
    phi, y, joint, blocks = stacked_rows(data.samples, data.y_full, cols, k, loads,
                                   None if th is None else th.fit_rows, data.observed)
    phi, extra = phi[:, :cols.size], phi[:, cols.size:]  # base columns, thermal columns
    theta0 = data.relations.to_base(prior)
    lin_method = "ols" if method == "ols" else "wls"
    thermal_fit = None
    if th is not None:
        coef = _thermal_coefficients(phi, y, theta0, joint, blocks, extra, lin_method, regularization)
        y = y - extra @ coef  # tau - (T - T_ref)(cv qd + cc sign qd)
        thermal_fit = ThermalFit(data.thermal.t_ref, coef[0::2], coef[1::2])
    fit = fit_linear(phi, y, theta0, joint, blocks, method=lin_method, regularization=regularization)
    step = _LinearStep(phi, y, joint, blocks, theta0, fit)
    if weights == "state-noise":
        step = replace(step, fit=_state_noise_fit(robot, data, step, prior, regularization, state_noise))
    return step, thermal_fit


def _thermal_coefficients(phi: np.ndarray, y: np.ndarray, theta0: np.ndarray, joint: np.ndarray,
                          blocks: np.ndarray, extra: np.ndarray, method: str,
                          regularization: float | str | None) -> np.ndarray:
    """Thermal coefficients (e,) of the columns ``extra`` (m, e), not regularised.

    ``min |y - Phi theta - E c|^2 + lam |theta - theta0|^2`` (Tikhonov on the base parameters
    only: a weight chosen for them would pull the small thermal columns to zero): for any
    ``theta`` the best ``c`` is ``E^+ (y - Phi theta)``, so ``theta`` is the usual fit of the
    rows projected off the thermal columns, ``P = 1 - Q Q^T`` with ``E = Q R``.
    """
    used = np.linalg.norm(extra, axis=0) > 0  # a joint without data or motion: no column
    q, _ = np.linalg.qr(extra[:, used])
    # P Phi, P y: the base problem with the thermal columns projected out
    fit = fit_linear(phi - q @ (q.T @ phi), y - q @ (q.T @ y), theta0, joint, blocks, method=method,
                     regularization=regularization)
    # c = E^+ (y - Phi theta)
    coef = np.zeros(extra.shape[1])
    coef[used] = np.linalg.lstsq(extra[:, used], y - phi @ fit.theta, rcond=None)[0]
    return coef


def _state_noise_fit(robot: Robot, data: Prepared, step: _LinearStep, prior: np.ndarray,
                     regularization: float | str | None, state_noise: Any) -> LinearFit:
    """The fit again with row weights ``1 / sigma_tau`` (m,) from the first fit ``step.fit``.

    ``sigma_tau^2`` (N m^2) is the state noise propagated through the first fit's model plus the
    measurement variance of each joint, floored at ``MEAS_FLOOR`` times its residual variance.
    """
    noise = state_noise_std(state_noise, robot.dof)
    first = completed(data.relations, step.fit.theta, prior)
    var = np.concatenate([torque_variance(data.model, s.q, s.qd, s.qdd, *noise, standard=first)
                          for s in data.samples]).reshape(-1)
    var = with_data(var, data.observed, [len(s.q) for s in data.samples])
    # sigma_meas^2: what the propagated variance leaves of each joint's residual variance
    prop = np.array([np.mean(var[step.joint == j]) for j in range(robot.dof)])
    meas = np.maximum(step.fit.sigma**2 - prop, MEAS_FLOOR * step.fit.sigma**2)
    return fit_linear(step.phi, step.y, step.theta0, step.joint, step.blocks,
                      regularization=regularization, row_sigma=np.sqrt(meas[step.joint] + var))


def _estimate_standard(robot: Robot, relations: BaseRelations, step: _LinearStep, prior: np.ndarray,
                       method: str, bounds: dict[str, tuple[float, float]] | None
                       ) -> tuple[np.ndarray, np.ndarray]:
    """Base parameters (b,) and the full standard set (15 n,) of the estimate (steps 6 and 7).

    ``method="consistent"``: the physically consistent standard set; otherwise the linear fit
    completed with ``prior`` (15 n,) for the dependent parameters, or, when that is not
    physical, with the physical completion closest to it that has the same base parameters
    (:mod:`robodyn.identification.completion`).
    """
    if method == "consistent":
        from robodyn.identification.consistent import consistent_standard

        standard = consistent_standard(robot, relations, step.phi, step.y, step.joint, step.fit, prior,
                                       bounds)
        return relations.to_base(standard), standard
    theta = step.fit.theta
    # the same base parameters, with a physical standard set when one exists
    return theta, consistent_completion(relations, completed(relations, theta, prior), robot.dof)


def _identification(robot: Robot, data: Prepared, step: _LinearStep, theta: np.ndarray,
                    standard: np.ndarray, drive: Drive, target: str, method: str) -> Identification:
    """The :class:`Identification` of base parameters ``theta`` (b,) and standard set (15 n,)."""
    table = _table(data.relations, theta, step.fit, step.theta0)
    ident_robot = robot_with_parameters(robot, standard, drive.k if target == "current" else None,
                                        source=f"identified ({method}) from {robot.source}")
    s = step.fit.singular_values
    weak = step.fit.directions[:, s < UNEXCITED_RTOL * s[0]]
    return Identification(
        robot=ident_robot, base_parameters=table, standard=standard, preprocess=data.settings,
        target=target, method=method, gains=drive.k, gains_source=drive.source, gains_std=drive.std,
        regularization=step.fit.lam,
        condition=step.fit.condition, singular_values=s, unexcited_directions=weak,
        residual_std=step.fit.sigma / drive.k, samples=data.count, relations=data.relations,
        _model=data.model)


def _table(relations: Any, theta: np.ndarray, fit: LinearFit, theta0: np.ndarray) -> BaseParameters:
    std = np.sqrt(np.clip(np.diag(fit.cov), 0.0, np.inf))
    return BaseParameters(names=relations.names, values=theta, std=std, nominal=theta0,
                          base=relations, identifiable=~fit.unexcited)

