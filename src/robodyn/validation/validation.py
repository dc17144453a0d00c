"""``validate``: a robot's model against a measured recording, per joint.

Two checks, as in the thesis's chapter 5:

(a) prediction: the model's inverse dynamics (friction and rotor inertia included) at the
    measured motion against the measured torque or motor current;
(b) simulation: the model's forward dynamics from the measured state, driven by the measured
    torque over short windows, against the measured motion.

Beside them: the noise floor of the target (what a perfect model would still miss), residual
spectra, and the friction the data imply (measured torque minus the model's rigid-body part).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from robodyn.measure.angles import unwrap_turns
from robodyn.measure.filtering import differentiate
from robodyn.numeric.model import Model, compile_model
from robodyn.robot.errors import ValidationError
from robodyn.robot.model import Robot
from robodyn.validation.effort import (
    MIN_SAMPLES,
    Target,
    check_finite,
    drive_gains,
    friction_torque,
    ignored_joints,
    in_chain_order,
    measured_target,
    resolve_target,
    target_unit,
)
from robodyn.validation.heldout import REFERENCE_CUTOFF_HZ, reference_filter
from robodyn.validation.metrics import ErrorMetrics, error_metrics
from robodyn.validation.spectra import NoiseFloor, ResidualSpectra, noise_floor, residual_spectra
from robodyn.validation.windows import WindowDrift, simulate_windows

__all__ = ["Validation", "validate"]

#: A joint whose velocity never exceeds this (rad/s or m/s) counts as held still.
MOVING_SPEED = 0.02


@dataclass(frozen=True, eq=False)
class Validation:
    """Result of :func:`validate` (arrays read-only).

    Attributes
    ----------
    robot : str
        Name of the validated robot.
    source : str
        The recording's source (file name).
    target : {"tau", "current"}
    unit : str
        Unit of ``measured``/``predicted`` ("N m" or "A").
    joint_names : tuple of str
        Chain order.
    t : (N,) ndarray
        s.
    qd : (N, n) ndarray
        Velocities the model was evaluated at: the recording's (measured, or estimated when
        ``"qd" in estimated``), or differentiated from the filtered positions (``cutoff``).
    measured, predicted : (N, n) ndarray
        Measured and predicted target.
    filtered : (N, n) ndarray
        Zero-phase low-pass filtered measured target (cut-off ``noise.cutoff``).
    prediction : ErrorMetrics
        ``predicted`` against ``measured``.
    prediction_filtered : ErrorMetrics
        ``predicted`` against ``filtered``.
    noise : NoiseFloor
        ``measured - filtered``: reported beside every figure.
    spectra : ResidualSpectra
    simulation : WindowDrift or None
        None when not requested or when the recording is shorter than one window.
    gains : (n,) ndarray or None
        Joint torque per ampere used with ``target="current"``.
    friction_velocity, friction_data : (N, n) ndarray
        The data's friction cloud: velocity and measured joint torque minus the model's
        rigid-body and rotor part (N m): what friction the measurement implies.
    friction_grid, friction_model : (G, n) ndarray
        The model's friction torque (N m) on a velocity grid spanning the data.
    moving : (n,) ndarray of bool
        Joints whose speed exceeds ``MOVING_SPEED`` somewhere (a jointwise run moves one).
    estimated : frozenset of str
        Recording fields that were estimated rather than measured (e.g. ``{"qdd"}``).
    notes : tuple of str
        What was skipped or cannot be judged, in words.
    """

    robot: str
    source: str
    target: Target
    unit: str
    joint_names: tuple[str, ...]
    t: np.ndarray
    qd: np.ndarray
    measured: np.ndarray
    predicted: np.ndarray
    filtered: np.ndarray
    prediction: ErrorMetrics
    prediction_filtered: ErrorMetrics
    noise: NoiseFloor
    spectra: ResidualSpectra
    simulation: WindowDrift | None
    gains: np.ndarray | None
    friction_velocity: np.ndarray
    friction_data: np.ndarray
    friction_grid: np.ndarray
    friction_model: np.ndarray
    moving: np.ndarray
    estimated: frozenset[str]
    notes: tuple[str, ...]

    @property
    def dof(self) -> int:
        """Number of joints n."""
        return len(self.joint_names)

    def table_rows(self) -> list[list[object]]:
        """One row per joint: errors against raw and filtered target, noise floor, drift."""
        rows = []
        for k, name in enumerate(self.joint_names):
            p, pf = self.prediction, self.prediction_filtered
            row: list[object] = [name, "yes" if self.moving[k] else "no", f"{p.rms[k]:.4g}",
                                 f"{p.max[k]:.4g}", f"{p.relative[k]:.3f}", f"{p.nrmse[k]:.3f}",
                                 f"{pf.relative[k]:.3f}", f"{self.noise.relative[k]:.3f}"]
            if self.simulation is not None:
                row += [f"{np.degrees(self.simulation.median_final[k]):.3g}",
                        f"{np.degrees(self.simulation.median_baseline[k]):.3g}"]
            rows.append(row)
        return rows

    def table_headers(self) -> list[str]:
        """Headers of :meth:`table_rows`."""
        u = self.unit
        headers = ["joint", "moves", f"RMS / {u}", f"max / {u}", "rel. error", "NRMSE",
                   "rel. vs filtered", "noise floor"]
        if self.simulation is not None:
            w = f"{self.simulation.window:g} s"
            headers += [f"drift / deg ({w})", "const.-velocity drift / deg"]
        return headers

    def summary(self) -> str:
        """A few lines of text: what was compared, and the whole-arm figures."""
        from robodyn.text import table

        lines = [f"{self.robot} vs {self.source or 'recording'}: target {self.target} "
                 f"({self.unit}), {len(self.t)} samples, {self.t[-1] - self.t[0]:.3g} s"
                 + (f"; estimated: {', '.join(sorted(self.estimated))}" if self.estimated else ""),
                 table(self.table_headers(), self.table_rows()),
                 f"whole arm: relative error {self.prediction.total_relative:.3f} (raw), "
                 f"{self.prediction_filtered.total_relative:.3f} (filtered, {self.noise.cutoff:g} "
                 f"Hz); noise floor {self.noise.total_relative:.3f}"]
        if self.simulation is not None:
            s = self.simulation
            lines.append(f"simulation: {len(s.starts)} windows of {s.window:g} s at dt "
                         f"{s.dt * 1e3:.3g} ms" + (f", {s.failed} failed" if s.failed else ""))
        lines += [f"note: {n}" for n in self.notes]
        return "\n".join(lines)


def validate(robot: Robot, recording: Any, target: str | None = None, *, ident: Any = None,
             model: Model | None = None, gains: np.ndarray | None = None, window: float | None = 0.2,
             noise_cutoff: float = REFERENCE_CUTOFF_HZ, cutoff: float | None = None,
             backend: str = "c") -> Validation:
    """Validate ``robot``'s dynamic model against a measured recording.

    Parameters
    ----------
    robot : Robot
        The model to validate (e.g. ``ident.robot``, or the manufacturer's description).
    recording : robodyn.measure.Recording
        Measured ``t``, ``q`` (and ``qd``/``qdd``, measured or estimated by the recording) and the
        target ``tau`` (N m) or ``current`` (A). Joints are matched to the robot by name.
    target : {"tau", "current"}, optional
        What to compare; default: ``ident.target`` when ``ident`` is given, else ``tau`` when
        the recording has it, else ``current``.
    ident : object with ``predict(recording) -> (N, n)``, optional
        An identification result (:func:`robodyn.identification`); when given, its prediction (which
        processes the raw recording as identification did) replaces the model's inverse
        dynamics in check (a).
    model : Model, optional
        ``compile_model(robot)`` when already at hand.
    gains : (n,) array_like, optional
        Joint torque per motor ampere for ``target="current"`` (default: ``ident.gains`` when
        ``ident`` is given, else the robot's drives, ``gear_ratio * torque_constant``, signed).
    window : float or None
        Simulation window, s (None: no simulation check).
    cutoff : float, optional
        When given, the model's states are the positions low-passed at ``cutoff`` Hz (zero-phase
        Butterworth) with velocities and accelerations differentiated from them
        (:func:`robodyn.measure.filtering.differentiate`), as identification does; when None,
        the recording's ``q``, ``qd``, ``qdd`` as they are, except with ``ident``: then the
        cut-off its prediction of this recording uses (``ident.recording_cutoff(rec)``; and
        ``preprocess.velocity == "measured"``: the measured velocity filtered and
        differentiated), so that the friction cloud and the simulation's start states are those
        of the prediction.
    noise_cutoff : float
        Cut-off of the zero-phase Butterworth low-pass (order 4) that separates the target
        from its noise, Hz (limited to 0.4 x the sample rate); default: the reference filter of
        :mod:`robodyn.validation.heldout` (2.5 Hz, the cut-off that reproduces the Kinova data
        README's noise floor), used for every "against filtered" figure robodyn reports.
    backend : {"c", "numpy"}
        For ``compile_model`` when ``model`` is not given.

    Returns
    -------
    Validation

    Raises
    ------
    ValidationError
        The joints do not match the robot, the target is missing, fewer than ``MIN_SAMPLES``
        samples, or a value is not finite (the field, row and column are named).
    """
    rec = in_chain_order(robot, recording)
    where = getattr(rec, "source", "") or "recording"
    if target is None and ident is not None:
        target = getattr(ident, "target", None)
    tgt = resolve_target(rec, target)
    t, arrays = _checked_arrays(rec, where)
    y = np.array(measured_target(rec, tgt))
    has = ~np.all(np.isnan(y), axis=0)  # an all-NaN column: that joint has no such sensor
    if cutoff is None and hasattr(ident, "recording_cutoff"):
        cutoff = ident.recording_cutoff(rec)  # the band ident.predict uses for this recording
    q, qd, qdd = _model_states(t, arrays, ident, cutoff)
    if model is None:
        model = compile_model(robot, backend=backend)
    if ident is not None and getattr(ident, "target", tgt) != tgt:
        raise ValidationError(f"{where}: the identification predicts {ident.target!r}, but "
                              f"target={tgt!r} was asked for")
    if ident is not None and gains is None and tgt == "current" and hasattr(ident, "gains"):
        gains = ident.gains  # the gains the identification divided its torque by
    k = _current_gains(robot, model, tgt, gains)
    scale = k if k is not None else np.ones(robot.dof)
    # tau_model = M(q) qdd + C(q, qd) qd + g(q) + friction(qd)
    tau_model = model.inverse_dynamics(q, qd, qdd)
    if ident is not None:
        predicted = np.array(ident.predict(rec), dtype=float)  # joints in chain order
        if predicted.shape != y.shape:
            raise ValidationError(f"{where}: ident.predict returned shape {predicted.shape}, the "
                                  f"recording's {tgt} is {y.shape}")
    else:
        # current = tau / (N K_t)
        predicted = tau_model / scale
    dt = float(np.median(np.diff(t)))
    cutoff = min(float(noise_cutoff), 0.4 / dt)
    filtered = np.full_like(y, np.nan)
    filtered[:, has] = reference_filter(t, y[:, has], cutoff)
    # tau_measured = N K_t current
    tau_meas = y * scale
    # friction the data imply = measured torque - (model torque - model friction)
    friction_data = tau_meas - (tau_model - friction_torque(robot, qd, model.parameters))
    vmax = np.maximum(np.abs(qd).max(axis=0), 1e-3)
    grid = np.linspace(-vmax, vmax, 201)
    moving = np.abs(qd).max(axis=0) > MOVING_SPEED
    notes = _notes(robot, recording, rec, tgt, moving, has)
    simulation = None
    if window is not None and not has.all():
        notes.append("simulation check skipped: the measured torque is missing on some joints")
    elif window is not None:
        try:
            simulation = simulate_windows(model, t, q, qd, tau_meas, window, q_measured=arrays["q"])
        except ValueError as exc:
            notes.append(f"simulation check skipped: {exc}")
    out = Validation(
        robot=robot.name, source=where, target=tgt, unit=target_unit(tgt, robot),
        joint_names=robot.joint_names, t=t, qd=qd, measured=y, predicted=predicted,
        filtered=filtered, prediction=error_metrics(y, predicted),
        prediction_filtered=error_metrics(filtered, predicted),
        noise=noise_floor(y, filtered, cutoff),
        spectra=residual_spectra(predicted - y, y - filtered, dt), simulation=simulation,
        gains=k, friction_velocity=qd, friction_data=friction_data, friction_grid=grid,
        friction_model=friction_torque(robot, grid, model.parameters), moving=moving,
        estimated=frozenset(getattr(rec, "estimated", frozenset())), notes=tuple(notes))
    for arr in (out.t, out.qd, out.measured, out.predicted, out.filtered, out.friction_data,
                out.friction_grid, out.friction_model, out.moving, out.friction_velocity):
        arr.flags.writeable = False
    return out


def _checked_arrays(rec: Any, where: str) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """Copies of ``t`` (N,) and ``q``, ``qd``, ``qdd`` (N, n), checked present and finite.

    Copies: the result's arrays are frozen, the user's are not.
    """
    t = np.array(rec.t, dtype=float)
    if len(t) < MIN_SAMPLES:
        raise ValidationError(f"{where}: {len(t)} samples; validation needs at least {MIN_SAMPLES}")
    check_finite(rec, "t", t)
    arrays = {}
    for field in ("q", "qd", "qdd"):
        value = getattr(rec, field, None)
        if value is None:
            raise ValidationError(f"{where}: field {field} is missing (a Recording estimates qd and "
                                  "qdd; pass a robodyn.measure.Recording)")
        arrays[field] = np.array(value, dtype=float)
        check_finite(rec, field, arrays[field])
    return t, arrays


def _model_states(t: np.ndarray, arrays: dict[str, np.ndarray], ident: Any,
                  cutoff: float | None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The states (N, n) the model is evaluated at: as recorded, or processed as identification did."""
    q, qd, qdd = arrays["q"], arrays["qd"], arrays["qdd"]
    settings = getattr(ident, "prediction_settings", getattr(ident, "preprocess", None))
    if cutoff is None and settings is not None:
        cutoff = getattr(settings, "cutoff", None)
    if cutoff is None:
        return q, qd, qdd
    cut = min(float(cutoff), 0.4 / float(np.median(np.diff(t))))
    if getattr(settings, "velocity", "position") == "measured":
        # qd = lowpass(qd_measured), qdd = d/dt of it
        qd, qdd, _ = differentiate(t, qd, cut)
        return q, qd, qdd
    # q = lowpass(q), qd and qdd its derivatives (wrap-around steps undone first)
    return differentiate(t, unwrap_turns(q), cut)


def _current_gains(robot: Robot, model: Model, tgt: str, gains: Any) -> np.ndarray | None:
    """Joint torque per motor ampere (n,) for a current target (None for a torque target)."""
    if tgt != "current":
        return None
    if gains is None:
        return drive_gains(robot, model.parameters)
    k = np.asarray(gains, dtype=float).reshape(-1)
    if k.shape != (robot.dof,) or not np.all(np.isfinite(k)) or np.any(k == 0):
        raise ValidationError(f"gains: expected {robot.dof} finite non-zero values (N m per A), "
                              f"got {np.asarray(gains).tolist()}")
    return k


def _notes(robot: Robot, recording: Any, rec: Any, tgt: str, moving: np.ndarray,
           has: np.ndarray) -> list[str]:
    """Notes on joints that never move, joints left out and joints without the target."""
    notes = [f"{name} never moves (|qd| <= {MOVING_SPEED} rad/s): its friction and inertia are not "
             "exercised by this recording" for name, m in zip(robot.joint_names, moving, strict=True)
             if not m]
    extra = ignored_joints(robot, recording) if rec is not recording else []
    if extra:
        notes.append(f"joints not in {robot.name} left out of the recording: {', '.join(extra)}")
    notes += [f"{name} has no {tgt} measurement: its errors are NaN"
              for name, h in zip(robot.joint_names, has, strict=True) if not h]
    return notes
