"""The underwater effect series as a study task: coefficients and current per case, torques out.

Each case sets named parameters of an underwater description (default the built-in
``underwater_2r``: ``Cd``, ``Ca``, ``CL``, ``vc``, ``rho``, ``m1``, ...; see
``rd.load("underwater_2r").parameters``) and runs :func:`robodyn.studies.underwater.effect_series` with
short durations and one variant besides ``dry`` (``effect``, default ``"current"``: every effect
on). Results, per joint ``j`` (N m or N; rad or m), of that variant:

* ``peak_tau.j``, ``rms_tau.j``: max |tau| and RMS torque of the PD-tracked move and hold;
* ``free_amplitude.j``: half the peak-to-peak swing over the second half of the free run;
* ``max_error.j``: largest tracking error.

Compiled variants are cached by robodyn (description and values), so a worker compiles each
variant of the robot once; a sweep builds them once and ships them to its workers
(:meth:`UnderwaterEffects.compiled_models`, :mod:`robodyn.studies.shipping`), so workers need
no compiler.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, NamedTuple

from robodyn.robot.errors import StudyError
from robodyn.studies.models import RobotSource, robot_of

__all__ = ["UNDERWATER_RESULTS", "EffectModelSpec", "UnderwaterEffects"]

#: Table columns of :func:`effect_series` reported per joint.
UNDERWATER_RESULTS = ("peak_tau", "rms_tau", "free_amplitude", "max_error")


class EffectModelSpec(NamedTuple):
    """One compiled model of the effect series (:func:`robodyn.studies.underwater.effect_model`),
    listed by :meth:`UnderwaterEffects.compiled_models` for a sweep to ship."""

    source: RobotSource
    effect: str
    parameters: tuple[tuple[str, float], ...] = ()
    backend: str = "c"

    def model(self) -> Any:
        """The compiled model (cached on disk by robodyn)."""
        from robodyn.studies.underwater import effect_model

        return effect_model(robot_of(self.source), self.effect, dict(self.parameters), backend=self.backend)


@dataclass(frozen=True)
class UnderwaterEffects:
    """Underwater effect task: ``task(case) -> {"peak_tau.q1": ..., ...}`` (module docstring).

    Attributes
    ----------
    robot : RobotSource
        A description with ``hydro`` blocks (default the built-in underwater_2r).
    effect : str
        The variant reported (one of :data:`robodyn.studies.underwater_effects.EFFECTS` other than ``dry``).
    move_time, hold_time, free_time, dt : float
        Durations and step of :func:`effect_series`, s.
    bandwidth : float
        PD bandwidth, Hz.
    backend : {"c", "numpy"}
    defaults : mapping
        Parameter values used when a case does not give them.
    """

    robot: RobotSource = field(default_factory=lambda: RobotSource.of("underwater_2r"))
    effect: str = "current"
    move_time: float = 1.0
    hold_time: float = 0.5
    free_time: float = 2.0
    dt: float = 2e-3
    bandwidth: float = 2.0
    backend: str = "c"
    defaults: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        from robodyn.studies.underwater_effects import EFFECTS

        if self.effect not in EFFECTS or self.effect == "dry":
            raise StudyError(f"UnderwaterEffects: effect: expected one of "
                             f"{', '.join(e for e in EFFECTS if e != 'dry')}, got {self.effect!r}")
        object.__setattr__(self, "defaults", dict(self.defaults))
        self.check_case(self.defaults, "UnderwaterEffects: defaults")

    def parameters(self) -> tuple[str, ...]:
        """Names a case may set: the description's named parameters."""
        return tuple(robot_of(self.robot).parameters)

    def check_case(self, case: Mapping[str, Any], where: str) -> None:
        """Raise :class:`StudyError` naming ``where`` for a parameter this task does not know."""
        known = self.parameters()
        for key in case:
            if key not in known:
                raise StudyError(f"{where}: unknown parameter {key!r} for the underwater effects of "
                                 f"{self.robot.name} (known: {', '.join(known)})")

    def _values(self, case: Mapping[str, Any]) -> dict[str, float]:
        values = {k: v for k, v in case.items() if k != "seed"}  # deterministic: no draws
        self.check_case(values, "case")
        return {k: float(v) for k, v in {**self.defaults, **values}.items()}

    def compiled_models(self, cases: Sequence[Mapping[str, Any]]) -> list[EffectModelSpec]:
        """The compiled models ``cases`` use (the dry arm, with its controller's gains, and the
        reported variant, per distinct parameter values), for a sweep to build once and ship
        to its workers (:mod:`robodyn.studies.shipping`). Cases this task would refuse are skipped."""
        specs: dict[EffectModelSpec, None] = {}
        for case in cases:
            try:
                params = tuple(sorted(self._values(case).items()))
            except (StudyError, TypeError, ValueError):
                continue  # the case itself reports it
            for effect in ("dry", self.effect):
                specs[EffectModelSpec(self.robot, effect, params, self.backend)] = None
        return list(specs)

    def __call__(self, case: Mapping[str, Any]) -> dict[str, float]:
        from robodyn.studies.underwater import effect_series

        params = self._values(case)
        robot = robot_of(self.robot)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # plausibility notes: the same for every case
            series = effect_series(robot, move_time=self.move_time, hold_time=self.hold_time,
                                   free_time=self.free_time, dt=self.dt, bandwidth=self.bandwidth,
                                   parameters=params, effects=(self.effect,), backend=self.backend)
        rows = series.table[series.table["effect"] == self.effect]
        return {f"{name}.{row['joint']}": float(row[name])
                for name in UNDERWATER_RESULTS for _, row in rows.iterrows()}
