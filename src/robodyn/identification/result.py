"""Frozen results of an identification: the base parameter table and :class:`Identification`."""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import cached_property
from typing import Any

import numpy as np
import sympy as sp

from robodyn.identification.bandwidth import check_prediction_cutoff
from robodyn.identification.base import BaseRelations
from robodyn.identification.choices import Choices
from robodyn.identification.coulomb_width import held_widths
from robodyn.identification.friction import FrictionFit, without_friction
from robodyn.identification.local_residual import LocalResidualFit, local_features
from robodyn.identification.options import IdentifyOptions, positive_frequency
from robodyn.identification.preprocess import (
    Preprocess,
    Samples,
    auto_cutoff,
    prediction_rows,
    preprocess,
)
from robodyn.identification.resonance import ResonanceFit
from robodyn.identification.ripple import RippleFit
from robodyn.identification.thermal import ThermalFit, temperatures
from robodyn.numeric.model import Model
from robodyn.robot.model import Robot

__all__ = ["BaseParameters", "Identification"]



#: Samples per regressor chunk of :meth:`Identification.effort` (7 joints: 4096 x 7 x 105
#: doubles, 24 MB, one buffer reused).
EFFORT_CHUNK = 4096

@dataclass(frozen=True, eq=False)
class BaseParameters:
    """Table of the identified base parameters, one row each.

    Attributes
    ----------
    names : tuple of str, length b
    values : numpy.ndarray, shape (b,)
        SI units (kg m^2, kg m, kg, N m s/rad, N m), target-torque units.
    std : numpy.ndarray, shape (b,)
        Standard deviations (inf: not identifiable from these data; the value is then the prior).
    nominal : numpy.ndarray, shape (b,)
        The prior's values of the same combinations (the description completed by the
        per-joint drive and friction fit, :mod:`robodyn.identification.prior`).
    base : BaseRelations
        The numerical relations (:attr:`relations` gives them symbolically).
    identifiable : numpy.ndarray of bool, shape (b,)
        False where the data do not excite the parameter (it keeps its prior value).
    """

    names: tuple[str, ...]
    values: np.ndarray
    std: np.ndarray
    nominal: np.ndarray
    base: BaseRelations
    identifiable: np.ndarray

    @cached_property
    def relations(self) -> tuple[sp.Expr, ...]:
        """Each base parameter in the standard parameter symbols (``XX1``, ``MY2``, ...)."""
        return self.base.expressions

    @property
    def relative_std(self) -> np.ndarray:
        """``100 std / |value|`` (%), shape (b,); inf for a zero value or infinite std."""
        with np.errstate(divide="ignore", invalid="ignore"):
            rel = 100.0 * self.std / np.abs(self.values)
        return np.where(np.isfinite(rel), rel, np.inf)

    def __len__(self) -> int:
        return len(self.names)

    def to_frame(self) -> Any:
        """The table as a pandas DataFrame (columns name, value, std, relative_std_percent,
        nominal, identifiable, relation)."""
        import pandas as pd

        return pd.DataFrame({
            "name": self.names, "value": self.values, "std": self.std,
            "relative_std_percent": self.relative_std, "nominal": self.nominal,
            "identifiable": self.identifiable, "relation": [str(r) for r in self.relations],
        })

    def __str__(self) -> str:
        lines = [f"{'name':<8} {'value':>13} {'std':>11} {'rel std %':>10}  relation"]
        for i, name in enumerate(self.names):
            flag = "" if self.identifiable[i] else "  (not excited)"
            lines.append(f"{name:<8} {self.values[i]:>13.6g} {self.std[i]:>11.3g} "
                         f"{self.relative_std[i]:>10.3g}  {self.relations[i]}{flag}")
        return "\n".join(lines)


@dataclass(frozen=True, eq=False)
class Identification:
    """Result of :func:`robodyn.identification`.

    Attributes
    ----------
    robot : Robot
        The description carrying the identified parameters (the full standard set: physically
        consistent with ``method="consistent"``; otherwise the nominal values of the dependent
        standard parameters completed by the identified base combinations).
    base_parameters : BaseParameters
    standard : numpy.ndarray, shape (15 n,)
        The standard parameter vector of ``robot``.
    preprocess : Preprocess
        Filter cut-off, order and decimation used (applied again by :meth:`predict`).
    target : {"tau", "current"}
    method : {"ols", "wls", "consistent"}
    gains : numpy.ndarray, shape (n,)
        Drive gains ``K_j`` (N m / A) dividing the predicted torque when ``target="current"``
        (ones for ``target="tau"``).
    gains_source : {"none", "description", "absorbed", "payload"}
        "payload": estimated from a run with a known payload (:mod:`robodyn.identification.drive_gains`).
    regularization : float
        Tikhonov weight used (dimensionless; 0: none).
    condition : float
        Condition number of the weighted, column-scaled identification matrix.
    singular_values : numpy.ndarray, shape (b,)
    unexcited_directions : numpy.ndarray, shape (b, k)
        Unit directions in base-parameter space (column-scaled) whose singular value is below
        1e-6 of the largest: what the data cannot tell apart.
    residual_std : numpy.ndarray, shape (n,)
        Per-joint residual standard deviation of the fit (target units); NaN for a joint
        without data (``unobserved``).
    samples : int
        Samples (after decimation) used in the fit.
    relations : BaseRelations
    gains_std : numpy.ndarray, shape (n,)
        Standard deviations of ``gains`` (N m / A) when they were estimated (``"payload"``);
        inf when absorbed (current alone leaves a common scale of the gains free: not
        identified); nan when given (description) or not used (``target="tau"``).
    friction_fit : FrictionFit or None
        A nonlinear friction law fitted after the linear step
        (:func:`robodyn.identification.friction.fit_friction`); :meth:`predict` then uses it in place
        of the linear friction.
    choices : Choices or None
        The preprocessing chosen from the data (velocity source, Coulomb dead band, cut-off,
        regularisation) with every candidate's cross-validated score
        (:mod:`robodyn.identification.choices`).
    thermal_fit : ThermalFit or None
        Temperature coefficients of the friction (``thermal=True``,
        :mod:`robodyn.identification.thermal`): :meth:`predict` adds their torque (the recording then
        needs temperatures); ``robot`` carries the friction at the reference temperature.
    options : IdentifyOptions or None
        The choices the run was made with (:mod:`robodyn.identification.options`).
    ripple_fit : RippleFit or None
        The position ripple (:mod:`robodyn.identification.ripple`): :meth:`predict` adds its
        torque; ``robot`` does not carry it.
    coulomb_width : float or numpy.ndarray, shape (n,)
        Velocity per joint (rad/s, m/s) over which :meth:`predict` smooths the linear law's
        Coulomb step (where the joint moves, ``H(qd)`` becomes ``(1 + tanh(qd / w)) / 2``,
        :mod:`robodyn.identification.coulomb_width`); 0: the step itself. The fit and the
        other choices are made with the step (option ``coulomb_width`` of
        :func:`robodyn.identify`).
    prediction : Preprocess or None
        The processing :meth:`predict` uses when it differs from ``preprocess``: the same with
        the prediction cut-off chosen from the data (:mod:`robodyn.identification.bandwidth`).
    resonance_fit : ResonanceFit or None
        One lightly damped mode per joint (:mod:`robodyn.identification.resonance`):
        :meth:`predict` evaluates the model on states at the mode's band and adds what the modes
        add to it; ``robot`` does not carry them.
    hydro : HydroLoad or None
        An underwater arm's hydrodynamic torque from its description
        (:mod:`robodyn.identification.hydro_load`): a known load, taken off the target before
        the fit; :meth:`effort` adds it (before the drive gains); ``robot`` keeps the
        hydrodynamic blocks.
    unobserved : tuple of str
        Joints without target data in any recording (an all-NaN column: no sensor,
        :mod:`robodyn.identification.unobserved`): their rows were not fitted, their own terms
        are the description's, and :meth:`predict` gives the model's value for them.
    local_fit : LocalResidualFit or None
        A kernel correction of the residual near the identification data's states
        (:mod:`robodyn.identification.local_residual`): :meth:`predict` adds it; it vanishes
        far from those states; ``robot`` does not carry it.
    """

    robot: Robot
    base_parameters: BaseParameters
    standard: np.ndarray
    preprocess: Preprocess
    target: str
    method: str
    gains: np.ndarray
    gains_source: str
    regularization: float
    condition: float
    singular_values: np.ndarray
    unexcited_directions: np.ndarray
    residual_std: np.ndarray
    samples: int
    relations: BaseRelations
    _model: Model
    friction_fit: FrictionFit | None = None
    gains_std: np.ndarray | None = None
    choices: Choices | None = None
    thermal_fit: ThermalFit | None = None
    options: IdentifyOptions | None = None
    ripple_fit: RippleFit | None = None
    prediction: Preprocess | None = None
    resonance_fit: ResonanceFit | None = None
    coulomb_width: float | np.ndarray = 0.0
    hydro: Any = None
    unobserved: tuple[str, ...] = ()
    local_fit: LocalResidualFit | None = None

    @property
    def gains_identified(self) -> bool:
        """Whether the drive gains were identified from the data (a known-payload run)."""
        return self.gains_source == "payload"

    def predict(self, recording: Any, payload: Any = None, cutoff: float | None = None) -> np.ndarray:
        """Predicted target at the recording's own samples.

        The raw recording is processed as the identification data were, by the same functions
        (same filter order, same derivative estimates, the same Coulomb dead band; the Coulomb
        step smoothed over :attr:`coulomb_width` when it is not 0), without
        decimation, at the prediction cut-off (:attr:`prediction_settings`: the fit's, or a
        wider one chosen from the data by :mod:`robodyn.identification.bandwidth`; with the
        default ``prediction_cutoff="motion"`` after ``cutoff="auto"``, widened to this
        recording's own motion bandwidth where it moves faster than the identification data:
        the same positions' rule that chose the fit's cut-off, :func:`recording_cutoff`); the
        prediction is the model's effort ``Y(q, qd, qdd) p`` at the processed states
        (:meth:`effort`). A joint with a drive mode (:attr:`resonance_fit`) is predicted from
        states processed at the mode's band, plus what the mode adds.

        Parameters
        ----------
        recording : Recording
            ``t`` (N,), ``q`` (N, n) in the robot's joint order.
        payload : Payload, optional
            A known payload on the last link during this recording; its torque is added.
        cutoff : float, optional
            The prediction cut-off for this recording, Hz, instead of
            ``prediction_settings.cutoff`` (below its Nyquist frequency): for a recording that
            moves more sharply than the identification data (docs/identification.md, "Limits").
            The parameters and the drive modes are unchanged.

        Returns
        -------
        numpy.ndarray, shape (N, n)
            N m (N) for ``target="tau"``, A for ``target="current"``.

        Raises
        ------
        IdentificationError
            A recording that does not fit the robot, or ``cutoff`` outside (0, Nyquist).
        """
        s = self.prediction_samples(recording, cutoff)
        out = self._model_prediction(recording, s, payload)
        if self.local_fit is not None:  # + k(x, U) a: the residual where the data were
            out = out + self.local_fit.correction(local_features(s.q, s.qd, s.qdd))
        return out

    def prediction_samples(self, recording: Any, cutoff: float | None = None) -> Samples:
        """The recording's states as :meth:`predict` processes them (its cut-off: as there),
        (N, n) each."""
        from robodyn.identification.inputs import check_recording

        check_recording(self.robot, recording, 0, None)
        settings = replace(self.prediction_settings, cutoff=self.recording_cutoff(recording))
        if cutoff is not None:
            cut = positive_frequency(cutoff, "prediction_cutoff")
            check_prediction_cutoff([recording], cut)
            settings = replace(settings, cutoff=cut)
        return preprocess(recording, settings, None)

    def _model_prediction(self, recording: Any, s: Samples, payload: Any) -> np.ndarray:
        """:meth:`predict` without the local correction, ``s`` the processed states (N, n)."""
        temp = temperatures(recording, 0, self.robot.dof) if self.thermal_fit is not None else None
        plain = self.effort(s, temp, payload)
        if self.resonance_fit is None:
            return plain
        wide = preprocess(recording, replace(self.preprocess, cutoff=self.resonance_fit.band), None)
        return self.resonance_fit.combine(wide.t, self.effort(wide, temp, payload), plain)

    def recording_cutoff(self, recording: Any) -> float | None:
        """The cut-off (Hz) at which :meth:`predict` processes ``recording`` by default.

        :attr:`prediction_settings`' cut-off, or, with ``prediction_cutoff="motion"`` after a fit
        with ``cutoff="auto"``, the ``cutoff="auto"`` rule of ``recording`` alone where that is
        higher: a recording that moves faster than the identification data (a jointwise run's
        short strokes) is not low-passed below its own motion. Never lower than the fit's (the
        identification recordings, whose rule chose it, keep it unless logged faster than the
        slowest of them).
        """
        cut = self.prediction_settings.cutoff
        opts = self.options
        if cut is None or opts is None or opts.prediction_cutoff != "motion" or opts.cutoff != "auto":
            return cut
        return max(cut, auto_cutoff([recording]))

    @property
    def prediction_settings(self) -> Preprocess:
        """The processing of a recording that :meth:`predict` evaluates the model on: the fit's
        (``preprocess``) with the prediction cut-off chosen by ``rd.identify``
        (:mod:`robodyn.identification.bandwidth`)."""
        return self.preprocess if self.prediction is None else self.prediction

    def effort(self, s: Any, temperature: np.ndarray | None = None, payload: Any = None) -> np.ndarray:
        """The model's effort at processed samples ``s`` (:class:`Samples`, (N, n) states),
        in the target's unit (N m, N or A), (N, n); ``temperature`` (N, n), deg C, is needed
        with thermal friction; ``payload`` as for :meth:`predict`.

        The regressor is evaluated :data:`EFFORT_CHUNK` samples at a time into one reused
        buffer: the effort of a long log needs no regressor of every sample (100,000 samples of
        a 7-joint arm: 590 MB of fresh pages, most of the call's time)."""
        pay = None
        if payload is not None:
            from robodyn.identification.payload import payload_standard

            pay = payload_standard(self.robot, payload)
        count, n = s.q.shape
        out = np.empty((count, n))
        buf = np.empty((min(count, EFFORT_CHUNK), n, self.standard.size))
        width = held_widths(s.t, s.qd, self.coulomb_width)  # the whole run: holds span chunks
        for a in range(0, count, EFFORT_CHUNK):
            b = min(a + EFFORT_CHUNK, count)
            part = Samples(s.t[a:b], s.q[a:b], s.qd[a:b], s.qdd[a:b], None, s.source)
            y = prediction_rows(self._model, part, self.preprocess, out=buf[:b - a],
                                coulomb_width=width[a:b])
            out[a:b] = self._effort_of(part, y, None if temperature is None else temperature[a:b], pay)
        return out

    def _effort_of(self, s: Any, y: np.ndarray, temperature: np.ndarray | None,
                   payload: np.ndarray | None) -> np.ndarray:
        """:meth:`effort` of samples ``s`` whose prediction rows are ``y`` (N, n, 15 n);
        ``payload``: its standard parameters (10,) or None."""
        thermal = 0.0
        if self.thermal_fit is not None:
            thermal = self.thermal_fit.torque(s.qd, temperature, self.preprocess.dead_band)
        if self.friction_fit is None:
            tau = y @ self.standard  # tau = Y(q, qd, qdd) p
        else:
            load = y @ without_friction(self.standard)  # rigid body and rotor inertia
            tau = load + self.friction_fit.torque(s.qd, load)
        tau = tau + thermal  # (T - T_ref)(cv qd + cc sign qd)
        if self.ripple_fit is not None:
            tau = tau + self.ripple_fit.torque(s.q)  # a sin q + b cos q
        if payload is not None:
            from robodyn.identification.payload import payload_torque

            tau = tau + payload_torque(y, payload)
        if self.hydro is not None:  # the fluid's torque, from the description
            tau = tau + self.hydro.torque(s.q, s.qd, s.qdd)
        return tau / self.gains[None, :]
