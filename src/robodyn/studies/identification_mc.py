"""Identification Monte Carlo as a study task: a virtual-lab recording, ``rd.identify``, its errors.

Each case runs the excitation program on the robot in the virtual laboratory
(:func:`robodyn.studies.virtual_lab`, every random draw from the case's seed) with the case's
sensor noise, identifies the base parameters from the joint torques (``rd.identify``, decimated to
100 Hz) and compares them with the truth. The held-out figures are the identified model's, without
the local correction of the residual (``local=False``,
:mod:`robodyn.identification.local_residual`): the plant is the description, so a correction could
only learn the preprocessing's own artefacts, and its kernel sums would make a case's last digits
depend on the worker's BLAS threads. The plant is the description itself, so the true base
parameters are ``relations.to_base(nominal_standard(robot))`` -- the same base relations and
standard vector ``rd.identify`` uses (:mod:`robodyn.identification.base`).

Excitations: ``"optimal"`` (``rd.excitation``: a Fourier trajectory of ``harmonics`` harmonics,
design seed 0, one period of ``1 / base_frequency`` s) or ``"jointwise"`` (the thesis's one joint
at a time program, :func:`robodyn.studies.testprog.jointwise`). The held-out program is always an
optimal excitation of another design seed (1), recorded with the same sensors and a new noise
draw. Designs are made once, when the task is built, and travel with it (a design made on each
worker could differ in the last digits with the worker's BLAS threads).

Results: ``base_error`` (``||theta - theta_true|| / ||theta_true||``, all base parameters),
``inertial_error`` (the same over the rigid-body base parameters only, friction and rotor inertia
left out), ``heldout_rms`` (N m: RMS over samples and joints of the predicted minus the true
torque on the held-out run), ``heldout_rel`` (that over the RMS true torque) and ``condition``
(of the weighted, column-scaled identification matrix).
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any

import numpy as np

from robodyn.robot.errors import StudyError
from robodyn.studies.models import ModelSpec, RobotSource, model_of, robot_of

__all__ = ["IDENTIFICATION_PARAMETERS", "IdentificationMonteCarlo"]

#: Case parameters of :class:`IdentificationMonteCarlo` (besides ``seed``) and their defaults.
IDENTIFICATION_PARAMETERS: Mapping[str, Any] = {
    "torque_noise": 0.05,      # joint torque sensor noise std, N m
    "counts_per_rev": 0.0,     # motor encoder counts per revolution (0: no quantisation)
    "jitter": 0.0,             # sample-time jitter std, s
    "excitation": "optimal",   # "optimal" (excitation) or "jointwise"
    "harmonics": 4,            # Fourier harmonics of the optimal excitation
    "base_frequency": 0.2,     # its base frequency, Hz (duration one period)
    "method": "ols",           # identify method: "ols", "wls" or "consistent"
}
_EXCITATIONS = ("optimal", "jointwise")
#: Logger period of the virtual lab, s; identification decimates to 100 Hz.
SAMPLE_PERIOD = 1e-3
_DECIMATE = 10


@lru_cache(maxsize=16)
def _program(source: RobotSource, kind: str, harmonics: int, base_frequency: float, seed: int) -> Any:
    """The test program, designed once per process."""
    from robodyn.studies.excitation import excitation
    from robodyn.studies.testprog import jointwise

    model = model_of(source)
    if kind == "jointwise":
        return jointwise(model, dt=0.01)
    return excitation(model, harmonics=harmonics, base_frequency=base_frequency, seed=seed,
                         starts=2, dt=0.01)


@dataclass(frozen=True)
class IdentificationMonteCarlo:
    """Identification Monte-Carlo task: ``task(case) -> {"base_error": ..., ...}`` (module docstring).

    Attributes
    ----------
    robot : RobotSource
        The robot, plant and nominal description at once (default: the built-in planar_2r).
    defaults : mapping
        Case parameter values used when a case does not give them.
    programs : mapping
        Test programs by ``(kind, harmonics, base_frequency, design seed)``; the default ones
        are designed when the task is built (others once per process).
    """

    robot: RobotSource = field(default_factory=lambda: RobotSource.of("planar_2r"))
    defaults: Mapping[str, Any] = field(default_factory=dict)
    programs: Mapping[tuple[str, int, float, int], Any] = field(default_factory=dict, repr=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "defaults", dict(self.defaults))
        self.check_case(self.defaults, "IdentificationMonteCarlo: defaults")
        p = {**IDENTIFICATION_PARAMETERS, **self.defaults}
        # the default designs, made here once so that every worker runs the same programs
        harmonics, f0 = int(p["harmonics"]), float(p["base_frequency"])
        keys = [(str(p["excitation"]), harmonics, f0, 0), ("optimal", harmonics, f0, 1)]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            made = {k: _program(self.robot, *k) for k in keys if k[0] in _EXCITATIONS}
        object.__setattr__(self, "programs", {**made, **dict(self.programs)})

    def _design(self, kind: str, harmonics: int, f0: float, seed: int) -> Any:
        key = (kind, harmonics, f0, seed)
        return self.programs[key] if key in self.programs else _program(self.robot, *key)

    def parameters(self) -> tuple[str, ...]:
        """Names a case may set."""
        return (*IDENTIFICATION_PARAMETERS, "seed")

    def compiled_models(self, cases: Sequence[Mapping[str, Any]]) -> list[ModelSpec]:
        """The one compiled model every case uses (the robot's, C backend), for a sweep to build
        once and ship to its workers (:mod:`robodyn.studies.shipping`)."""
        return [ModelSpec(self.robot)] if cases else []

    def check_case(self, case: Mapping[str, Any], where: str) -> None:
        """Raise :class:`StudyError` naming ``where`` for a parameter this task does not know."""
        known = self.parameters()
        for key in case:
            if key not in known:
                raise StudyError(f"{where}: unknown parameter {key!r} for identification Monte Carlo "
                                 f"(known: {', '.join(known)})")

    def __call__(self, case: Mapping[str, Any]) -> dict[str, float]:
        from robodyn.identification.pipeline import identify, nominal_standard
        from robodyn.studies.virtual_lab import Sensors, virtual_lab
        from robodyn.symbolic.regressor import INERTIAL_NAMES, PER_JOINT

        self.check_case(case, "case")
        if "seed" not in case:
            raise StudyError("case: identification Monte Carlo needs a 'seed' (sweep adds one)")
        p = {**IDENTIFICATION_PARAMETERS, **self.defaults, **case}
        kind = p["excitation"]
        if kind not in _EXCITATIONS:
            raise StudyError(f"case: excitation: expected one of {', '.join(_EXCITATIONS)}, got {kind!r}")
        noise = float(p["torque_noise"])
        if not np.isfinite(noise) or noise < 0:
            raise StudyError(f"case: torque_noise: expected a standard deviation >= 0 N m, got {noise!r}")
        robot, model = robot_of(self.robot), model_of(self.robot)
        harmonics, f0 = int(p["harmonics"]), float(p["base_frequency"])
        sensors = Sensors(sample_period=SAMPLE_PERIOD, jitter=float(p["jitter"]),
                          counts_per_rev=float(p["counts_per_rev"]), current_noise=0.0,
                          current_offset=0.0, torque_constant_error=0.0, torque_noise=noise,
                          tracker_period=0.0)
        seed = int(p["seed"])
        rng = np.random.default_rng(seed)
        lab_seed, test_seed = (int(s) for s in rng.integers(0, 2**31, 2))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # design and identifiability notes: same every case
            train = virtual_lab(model, self._design(kind, harmonics, f0, 0), sensors=sensors,
                                seed=lab_seed, oversample=2)
            test = virtual_lab(model, self._design("optimal", harmonics, f0, 1),
                               sensors=sensors, seed=test_seed, oversample=2)
            ident = identify(robot, train.recording, target="tau", method=str(p["method"]),
                                cutoff=None, regularization=None, decimate=_DECIMATE, model=model,
                                local=False)
        relations = ident.relations
        # true base parameters: the plant's standard vector through identify's own relations
        true = relations.to_base(nominal_standard(robot))
        est = ident.base_parameters.values
        # rigid-body columns come first in each joint's block of the standard vector
        rigid = relations.independent % PER_JOINT < len(INERTIAL_NAMES)
        predicted = ident.predict(test.recording)
        miss = predicted - test.truth.tau
        rms_true = float(np.sqrt(np.mean(test.truth.tau**2)))
        heldout = float(np.sqrt(np.mean(miss**2)))
        return {"base_error": float(np.linalg.norm(est - true) / np.linalg.norm(true)),
                "inertial_error": float(np.linalg.norm((est - true)[rigid]) / np.linalg.norm(true[rigid])),
                "heldout_rms": heldout, "heldout_rel": heldout / rms_true,
                "condition": float(ident.condition)}
