"""Calibration Monte Carlo as a study task: random manufacturing errors, noisy tracker, held-out error.

Each case draws, from its own seed, a "true" robot (the nominal one with random joint placement
errors and zero offsets, :func:`robodyn.studies.calibration_study.perturbed_robot`), ``n_poses``
random calibration poses and ``n_test`` held-out poses; measures the true tool positions with
Gaussian noise ``sigma`` per coordinate; calibrates ``model`` (``rd.calibrate``) and reports the
held-out errors. Over many seeds, the table is the distribution of the calibrated accuracy for
that noise, pose count and error model.

Results (m): ``heldout_rms`` and ``heldout_max`` (calibrated model vs the noisy held-out
measurements, what a user sees), ``heldout_rms_true`` (vs the noise-free true positions: the
model error alone) and ``nominal_rms_true`` (the uncalibrated nominal kinematics vs the truth, in
the robot's own frame: what calibration has to remove).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from robodyn.robot.errors import StudyError
from robodyn.studies.models import RobotSource, robot_of

__all__ = ["CALIBRATION_PARAMETERS", "CalibrationMonteCarlo"]

#: Case parameters of :class:`CalibrationMonteCarlo` (besides ``seed``) and their defaults.
CALIBRATION_PARAMETERS: Mapping[str, Any] = {
    "sigma": 1e-4,                        # tracker noise per coordinate, m
    "n_poses": 50,                        # calibration poses
    "model": "s-model",                   # error model: "dh", "hayati", "s-model", "poe"
    "length_error": 1e-3,                 # std of each joint placement coordinate error, m
    "angle_error": math.radians(0.1),     # std of each placement rotation error, rad
    "offset_error": math.radians(0.1),    # std of each joint zero offset, rad
}


@dataclass(frozen=True)
class CalibrationMonteCarlo:
    """Calibration Monte-Carlo task: ``task(case) -> {"heldout_rms": ..., ...}`` (module docstring).

    Attributes
    ----------
    robot : RobotSource
        The nominal robot (default: the built-in PUMA 560).
    n_test : int
        Held-out poses per case.
    defaults : mapping
        Case parameter values used when a case does not give them.
    """

    robot: RobotSource = field(default_factory=lambda: RobotSource.of("puma560"))
    n_test: int = 100
    defaults: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if isinstance(self.n_test, bool) or not isinstance(self.n_test, int) or self.n_test < 1:
            raise StudyError(f"CalibrationMonteCarlo: n_test must be a positive integer, got {self.n_test!r}")
        object.__setattr__(self, "defaults", dict(self.defaults))

    def parameters(self) -> tuple[str, ...]:
        """Names a case may set."""
        return (*CALIBRATION_PARAMETERS, "seed")

    def check_case(self, case: Mapping[str, Any], where: str) -> None:
        """Raise :class:`StudyError` naming ``where`` for a parameter this task does not know."""
        known = self.parameters()
        for key in case:
            if key not in known:
                raise StudyError(f"{where}: unknown parameter {key!r} for calibration Monte Carlo "
                                 f"(known: {', '.join(known)})")

    def __call__(self, case: Mapping[str, Any]) -> dict[str, float]:
        from robodyn.calibration.pipeline import calibrate, random_configurations
        from robodyn.studies.calibration_study import perturbed_robot, robot_positions

        self.check_case(case, "case")
        if "seed" not in case:
            raise StudyError("case: calibration Monte Carlo needs a 'seed' (sweep adds one)")
        p = {**CALIBRATION_PARAMETERS, **self.defaults, **case}
        sigma, n_poses = float(p["sigma"]), int(p["n_poses"])
        robot = robot_of(self.robot)
        rng = np.random.default_rng(int(p["seed"]))
        true = perturbed_robot(robot, rng, length_error=float(p["length_error"]),
                               angle_error=float(p["angle_error"]), offset_error=float(p["offset_error"]))
        q = random_configurations(robot, n_poses, rng)
        q_test = random_configurations(robot, self.n_test, rng)
        # tracker readings: true positions + N(0, sigma^2) per coordinate
        y = robot_positions(true, q) + rng.normal(0.0, sigma, (n_poses, 3))
        clean_test = robot_positions(true, q_test)
        y_test = clean_test + rng.normal(0.0, sigma, clean_test.shape)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # identifiability notes: the same for every case
            cal = calibrate(robot, q, y, str(p["model"]), sigma=max(sigma, 1e-9))
        after = np.linalg.norm(y_test - cal.predict(q_test), axis=1)
        after_true = np.linalg.norm(clean_test - cal.predict(q_test), axis=1)
        nominal = np.linalg.norm(clean_test - robot_positions(robot, q_test), axis=1)
        return {"heldout_rms": float(np.sqrt(np.mean(after**2))), "heldout_max": float(after.max()),
                "heldout_rms_true": float(np.sqrt(np.mean(after_true**2))),
                "nominal_rms_true": float(np.sqrt(np.mean(nominal**2)))}
