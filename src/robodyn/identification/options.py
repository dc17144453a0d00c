"""Every choice of an identification other than its data, in one checked object.

:func:`robodyn.identify` takes the same choices as keywords (and builds an
:class:`IdentifyOptions` from them) or as ``options=IdentifyOptions(...)``; the result keeps the
one it ran with (``ident.options``), so a run can be repeated with one choice changed
(``dataclasses.replace(ident.options, method="consistent")``). The checks live here, once: a bad
value is refused when the options are made, naming the field.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from robodyn.identification.friction import FRICTION_MODELS
from robodyn.robot.errors import IdentificationError

__all__ = ["METHODS", "SENSORS", "SPIKES", "VELOCITIES", "WEIGHTS", "IdentifyOptions"]

METHODS = ("ols", "wls", "consistent")
WEIGHTS = ("residual", "state-noise")
VELOCITIES = ("auto", "position", "measured")
SENSORS = ("motor", "link")
SPIKES = ("auto", "keep", "drop")


@dataclass(frozen=True, eq=False)
class IdentifyOptions:
    """The choices of :func:`robodyn.identify` (keywords of the same names).

    Attributes
    ----------
    method : {"ols", "wls", "consistent"}
        Ordinary or weighted least squares, or physically consistent (pseudo-inertia LMIs).
    friction : {"linear", "none", "stribeck", "load", "polynomial", "auto"}
        "linear": viscous, Coulomb (+/-) and offset per joint in the linear fit; "none": no
        friction; the others: a nonlinear law fitted after the linear step
        (:mod:`robodyn.identification.friction`); "auto": linear or Stribeck, chosen by time-block
        cross-validation (:mod:`robodyn.identification.friction_choice`).
    regularization : "auto", float or None
        Tikhonov weight toward the description's values (dimensionless, see
        :mod:`robodyn.identification.estimate`); "auto": chosen by time-block cross-validation;
        None: plain least squares (not-excited directions stay at the prior).
    cutoff : "auto", float or None
        Zero-phase low-pass cut-off, Hz (:mod:`robodyn.identification.preprocess`); None: none
        (the recordings' own velocities and accelerations).
    decimate : "auto" or int
        Keep every ``decimate``-th filtered sample.
    velocity : {"auto", "position", "measured"}
        Joint velocities from the filtered positions or the filtered measured ones; "auto":
        when every recording has a measured velocity, each source's model is finished (its other
        settings chosen by time-block cross-validation, :mod:`robodyn.identification.choices`)
        and the one with the smaller residual on the identification data is kept
        (:mod:`robodyn.identification.velocity_choice`), else "position".
    dead_band : "auto" or float
        Coulomb dead band, rad/s (m/s): below it a joint's Coulomb columns are zero and only the
        friction offset acts, in the fit and in :meth:`Identification.predict` alike; 0: none;
        "auto": 0 or ``DEAD_BAND`` (1e-3), chosen by time-block cross-validation.
    coulomb_width : "auto" or float
        Velocity, rad/s (m/s), over which :meth:`Identification.predict` smooths the linear
        law's Coulomb step: where the joint moves, ``H(qd)`` becomes ``(1 + tanh(qd / w)) / 2``,
        the expected step where the estimated velocity's sign is uncertain (a joint held still
        or creeping through a reversal); the fit and the other choices keep the step. "auto"
        (the default): per joint, from the noise of the identification recordings' processed
        velocity (:mod:`robodyn.identification.coulomb_width`); 0: no smoothing.
    gains : {"auto", "description", "absorbed"}
        Drive gains for ``target="current"`` (:func:`robodyn.identification.prior.joint_prior`).
    bounds : mapping of str to (float, float), optional
        Box constraints on named standard parameters for ``method="consistent"``
        (e.g. ``{"M7": (0.3, 2.0)}`` for a known payload range).
    weights : {"residual", "state-noise"}
        Row weights of ``"wls"``/``"consistent"``: per joint from the residuals of a first fit,
        or per sample and joint ``1 / sigma_tau`` with the state noise propagated through the
        first fit's model (errors in variables, :mod:`robodyn.identification.state_noise`).
    state_noise : (s_q, s_qd, s_qdd), optional
        Standard deviations of the processed states' noise (rad, rad/s, rad/s^2; scalars or
        (n,)), required by ``weights="state-noise"``.
    thermal : bool or "auto"
        Temperature-dependent viscous and Coulomb friction (:mod:`robodyn.identification.thermal`;
        needs the recordings' ``temperature``); "auto": with and without, chosen by time-block
        cross-validation when every recording has temperatures.
    sensor : {"motor", "link"}
        Where the effort is measured: "motor" (motor current, or a torque that includes the
        drive: the reflected rotor inertia ``Ia`` is identified), or "link" (a joint torque
        sensor after the gear, which does not see the rotor: the ``Ia`` columns are dropped and
        ``Ia = 0`` in the prior and the result; ``target="tau"`` only).
    spikes : {"auto", "keep", "drop"}
        One-sample glitches of the identification recordings (a sample of ``q`` or of the target
        far off the line through its neighbours, :mod:`robodyn.identification.spikes`): kept, or
        their rows dropped before anything else (estimated velocities then re-estimated).
        "drop": beyond 12 robust standard deviations, which on the real logs here also flags
        0.5-3 % of ordinary samples (the quality table's held-out errors moved by -0.4 % to
        +5.5 %); "auto" (the default): gross glitches only, beyond 100 (none to nine rows per
        real run here; every real row of the quality table within 0.1 %), with a warning.
    ripple : bool or "auto"
        A torque once per revolution of each revolute joint, ``a_j sin q_j + b_j cos q_j``,
        fitted on what the identified model leaves of the target
        (:mod:`robodyn.identification.ripple`); "auto": kept when it predicts held-out time
        blocks of that residual better than none.
    resonance : bool or "auto"
        One lightly damped drive mode per joint added to the prediction
        (:mod:`robodyn.identification.resonance`): frequency, damping and share chosen by
        held-out time blocks of the model's residual; "auto": a joint's mode kept only when it
        beats none by one standard error; True: every joint's best mode; False: none.
    prediction_cutoff : float, "motion", "auto" or "fit"
        Cut-off (Hz) of the states :meth:`Identification.predict` evaluates the model at
        (:mod:`robodyn.identification.bandwidth`): "motion" (the default) is the fit's cut-off,
        widened for a predicted recording whose own positions move faster than the
        identification data (the ``cutoff="auto"`` rule applied to that recording alone; only
        after a fit with ``cutoff="auto"``); "fit" is the fit's cut-off; "auto" tries it and
        wider ones on the identification recordings against their raw target and keeps a wider
        one only when it is better by more than one standard error (lower error against the raw
        target, higher against a low-passed one: see the module).
    local : bool or "auto"
        A kernel correction of the residual near the identification data's states, zero far
        from them (:mod:`robodyn.identification.local_residual`): what the model repeatably
        misses where the arm passes again; "auto": kept only when it predicts held-out time
        blocks of the residual better than none by one standard error; True: the best setting
        of its grid; False: none.

    Raises
    ------
    IdentificationError
        On construction: a value outside its choices, naming the field.
    """

    method: str = "consistent"
    friction: str = "auto"
    regularization: float | str | None = "auto"
    cutoff: float | str | None = "auto"
    decimate: int | str = "auto"
    velocity: str = "auto"
    dead_band: float | str = 0.0
    coulomb_width: float | str = "auto"
    gains: str = "auto"
    bounds: Mapping[str, tuple[float, float]] | None = None
    weights: str = "residual"
    state_noise: Any = None
    thermal: bool | str = False
    sensor: str = "motor"
    spikes: str = "auto"
    ripple: bool | str = "auto"
    resonance: bool | str = "auto"
    prediction_cutoff: float | str = "motion"
    local: bool | str = "auto"

    def __post_init__(self) -> None:
        _choice("method", self.method, METHODS)
        _choice("friction", self.friction, (*FRICTION_MODELS, "auto"))
        _choice("weights", self.weights, WEIGHTS)
        if self.weights == "state-noise" and self.state_noise is None:
            raise IdentificationError("state_noise: weights='state-noise' needs the state noise "
                                      "(s_q, s_qd, s_qdd) in rad, rad/s, rad/s^2")
        _choice("velocity", self.velocity, VELOCITIES)
        _choice("sensor", self.sensor, SENSORS)
        if not any(self.thermal is v for v in (False, True)) and self.thermal != "auto":
            raise IdentificationError(f"thermal: expected False, True or 'auto', got {self.thermal!r}")
        if isinstance(self.dead_band, str) and self.dead_band != "auto":
            raise IdentificationError(f"dead_band: expected a velocity in rad/s or 'auto', got "
                                      f"{self.dead_band!r}")
        cw = self.coulomb_width
        if cw != "auto" and (isinstance(cw, (bool, str))
                             or not isinstance(cw, (int, float, np.integer, np.floating))
                             or not (np.isfinite(cw) and 0 <= cw < 1e3)):
            raise IdentificationError(f"coulomb_width: expected 'auto' or a velocity in "
                                      f"[0, 1000) rad/s, got {cw!r}")
        _choice("gains", self.gains, ("auto", "description", "absorbed"))
        _choice("spikes", self.spikes, SPIKES)
        for name in ("ripple", "resonance", "local"):
            value = getattr(self, name)
            if not any(value is v for v in (False, True)) and value != "auto":
                raise IdentificationError(f"{name}: expected False, True or 'auto', got {value!r}")
        pc = self.prediction_cutoff
        if isinstance(pc, str):
            if pc not in ("motion", "auto", "fit"):
                raise IdentificationError(f"prediction_cutoff: expected a frequency in Hz, 'motion', "
                                          f"'auto' or 'fit', got {pc!r}")
        else:
            positive_frequency(pc, "prediction_cutoff")


def positive_frequency(value: Any, name: str) -> float:
    """``value`` as a finite positive frequency (Hz), or an error naming ``name``."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) \
            or not (np.isfinite(value) and value > 0):
        raise IdentificationError(f"{name}: expected a positive frequency in Hz, got {value!r}")
    return float(value)


def _choice(name: str, value: Any, choices: tuple[str, ...]) -> None:
    if not isinstance(value, str) or value not in choices:
        raise IdentificationError(f"{name}: expected one of {choices}, got {value!r}")
