"""Actuator sizing as a study task: one simulated manoeuvre per case, peak/RMS torque and power.

:class:`ActuatorSizing` is the AA300 design study (:mod:`robodyn.studies.aa300`) cut down
to one case of a sweep: a robot (description text), a planned joint motion, a PD controller
(with or without gravity compensation) tuned from a closed-loop bandwidth, and per case
parameters (payload, bandwidth, damping, controller, the description's named parameters). The
plan depends only on the kinematics, so each worker plans it once; the model for each payload
and parameter set is compiled or loaded once per worker (:mod:`robodyn.studies.models`).

Results per joint ``J`` (N m and rad for rotations, N and m for slides):

===========================  ================================================================
``peak_torque.J``            largest |torque| the controller applied
``rms_torque.J``             root-mean-square torque over the run (thermal sizing)
``peak_ideal_torque.J``      largest |inverse-dynamics torque| along the plan (perfect tracking)
``peak_speed.J``             largest |joint velocity|
``peak_power.J``             largest |torque x velocity|, W
``rms_power.J``              root-mean-square of torque x velocity, W
``tracking_error.J``         largest |q_plan - q|
===========================  ================================================================
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any

import numpy as np

from robodyn.robot.errors import StudyError
from robodyn.studies.models import ModelSpec, RobotSource, model_of, robot_of

__all__ = ["SIZING_PARAMETERS", "ActuatorSizing"]

#: Case parameters of :class:`ActuatorSizing` (besides the robot's named parameters and ``seed``),
#: with their defaults.
SIZING_PARAMETERS: Mapping[str, Any] = {
    "payload": 0.0,               # kg at the tool point
    "bandwidth_hz": 4.0,          # closed-loop natural frequency of each PD loop, Hz
    "zeta": 1.0,                  # damping ratio of each loop
    "gravity_compensation": True,  # PD + g(q), or plain PD (sags under gravity)
    "speed_scale": 1.0,           # trapezoid only: vmax x s, amax x s^2 (same path, time / s)
}

TRAJECTORIES = ("aa300_cycle", "trapezoid")


@dataclass(frozen=True)
class ActuatorSizing:
    """Sizing task: ``task(case) -> {"peak_torque.J": ..., ...}`` (module docstring).

    Attributes
    ----------
    robot : RobotSource
        ``RobotSource.of("aa300")`` or a description file.
    trajectory : {"aa300_cycle", "trapezoid"}
        The AA300 pick-lift-rotate-place cycle (:func:`robodyn.studies.aa300.plan_cycle`,
        AA300 only), or a synchronised trapezoidal joint move from ``q_start`` to ``q_goal``.
    q_start, q_goal : (n,) tuple of float
        Trapezoid end points, rad or m.
    vmax, amax : (n,) tuple of float
        Trapezoid velocity and acceleration limits (rad/s, m/s; rad/s^2, m/s^2).
    dt : float
        Plan sampling and RK4 step, s.
    settle : float
        Simulated time after the plan ends, s.
    backend : {"c", "numpy"}
    defaults : mapping
        Case parameter values used when a case does not give them (over :data:`SIZING_PARAMETERS`).
    """

    robot: RobotSource
    trajectory: str = "aa300_cycle"
    q_start: tuple[float, ...] = ()
    q_goal: tuple[float, ...] = ()
    vmax: tuple[float, ...] = ()
    amax: tuple[float, ...] = ()
    dt: float = 1e-3
    settle: float = 0.5
    backend: str = "c"
    defaults: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.trajectory not in TRAJECTORIES:
            raise StudyError(f"ActuatorSizing: trajectory must be one of {TRAJECTORIES}, got "
                             f"{self.trajectory!r}")
        if self.trajectory == "trapezoid":
            lengths = {len(v) for v in (self.q_start, self.q_goal, self.vmax, self.amax)}
            if len(lengths) != 1 or 0 in lengths:
                raise StudyError("ActuatorSizing: a trapezoid needs q_start, q_goal, vmax and amax, "
                                 "one value per joint each")
        if not (self.dt > 0 and self.settle >= 0):
            raise StudyError(f"ActuatorSizing: dt must be > 0 and settle >= 0, got {self.dt}, "
                             f"{self.settle}")
        object.__setattr__(self, "defaults", dict(self.defaults))

    def parameters(self) -> tuple[str, ...]:
        """Names a case may set: :data:`SIZING_PARAMETERS`, the robot's named parameters, ``seed``."""
        return (*SIZING_PARAMETERS, *robot_of(self.robot).parameters, "seed")

    def check_case(self, case: Mapping[str, Any], where: str) -> None:
        """Raise :class:`StudyError` naming ``where`` for a parameter this task does not know."""
        known = self.parameters()
        for key in case:
            if key not in known:
                raise StudyError(f"{where}: unknown parameter {key!r} for actuator sizing of "
                                 f"{self.robot.name} (known: {', '.join(known)})")

    def __call__(self, case: Mapping[str, Any]) -> dict[str, float]:
        from robodyn.simulation.controllers import PD, GravityCompensation
        from robodyn.simulation.simulation import simulate

        self.check_case(case, "case")
        robot = robot_of(self.robot)
        p, overrides = self._values(case)
        model = model_of(self.robot, float(p["payload"]), overrides, self.backend)
        plan = self._plan(overrides, float(p["speed_scale"]))
        q0 = plan.at(0.0)[0]
        # gains: Kp = M_ii w^2, Kd = 2 zeta w M_ii (M at the start pose, payload included)
        w = 2 * np.pi * float(p["bandwidth_hz"])
        mdiag = np.diag(model.mass_matrix(q0))
        kp, kd = mdiag * w**2, 2 * float(p["zeta"]) * mdiag * w
        gravity = bool(p["gravity_compensation"])
        controller = (GravityCompensation if gravity else PD)(kp, kd, plan)
        # plain PD starts at its static sag q0 - Kp^-1 g(q0), so the run starts at rest
        start = q0 if gravity else q0 - model.gravity(q0) / kp
        steps = int(round((plan.duration + self.settle) / self.dt))
        sim = simulate(model, start, None, steps * self.dt, self.dt, "rk4", controller)
        q_r, qd_r, qdd_r = plan.at(sim.t)
        ideal = model.inverse_dynamics(q_r, qd_r, qdd_r)
        power = sim.tau * sim.qd
        out: dict[str, float] = {}
        for j, name in enumerate(robot.joint_names):
            out[f"peak_torque.{name}"] = float(np.max(np.abs(sim.tau[:, j])))
            out[f"rms_torque.{name}"] = float(np.sqrt(np.mean(sim.tau[:, j] ** 2)))
            out[f"peak_ideal_torque.{name}"] = float(np.max(np.abs(ideal[:, j])))
            out[f"peak_speed.{name}"] = float(np.max(np.abs(sim.qd[:, j])))
            out[f"peak_power.{name}"] = float(np.max(np.abs(power[:, j])))
            out[f"rms_power.{name}"] = float(np.sqrt(np.mean(power[:, j] ** 2)))
            out[f"tracking_error.{name}"] = float(np.max(np.abs(q_r[:, j] - sim.q[:, j])))
        return out

    def compiled_models(self, cases: Sequence[Mapping[str, Any]]) -> list[ModelSpec]:
        """The compiled models ``cases`` use (one per distinct payload and parameter values, and
        the payload-free one the AA300 cycle is planned on), for a sweep to build once and ship
        to its workers (:mod:`robodyn.studies.shipping`). Cases this task would refuse are skipped.
        """
        specs: dict[ModelSpec, None] = {}
        for case in cases:
            try:
                self.check_case(case, "case")
                p, overrides = self._values(case)
                specs[ModelSpec(self.robot, float(p["payload"]), overrides, self.backend)] = None
            except (StudyError, TypeError, ValueError):
                continue  # the case itself reports it
            if self.trajectory == "aa300_cycle":
                specs[ModelSpec(self.robot, 0.0, overrides, self.backend)] = None
        return list(specs)

    def _values(self, case: Mapping[str, Any]) -> tuple[dict[str, Any], tuple[tuple[str, float], ...]]:
        """The case over the defaults, and its values of the robot's named parameters (sorted)."""
        p = {**SIZING_PARAMETERS, **self.defaults, **case}
        names = robot_of(self.robot).parameters
        return p, tuple(sorted((k, float(v)) for k, v in p.items() if k in names))

    def _plan(self, overrides: tuple[tuple[str, float], ...], speed_scale: float) -> Any:
        return _plan(self.robot, overrides, self.backend, self.trajectory, self.dt, self.q_start,
                     self.q_goal, self.vmax, self.amax, speed_scale)


@lru_cache(maxsize=32)
def _plan(source: RobotSource, overrides: tuple[tuple[str, float], ...], backend: str, kind: str,
          dt: float, q_start: Sequence[float], q_goal: Sequence[float], vmax: Sequence[float],
          amax: Sequence[float], speed_scale: float) -> Any:
    """The planned motion, once per process and kinematics (planned on the payload-free model)."""
    from robodyn.simulation.trajectory import trapezoidal
    from robodyn.studies.aa300 import plan_cycle

    if not speed_scale > 0:
        raise StudyError(f"speed_scale must be > 0, got {speed_scale!r}")
    if kind == "aa300_cycle":
        if speed_scale != 1.0:
            raise StudyError("speed_scale applies to the trapezoid trajectory only (the AA300 cycle's "
                             "manoeuvre times are fixed)")
        if robot_of(source).joint_names != ("column", "upper_arm", "extension_tube"):
            raise StudyError(f"trajectory 'aa300_cycle' plans the AA300's cycle; {source.name} is "
                             "not the AA300 (use trajectory 'trapezoid')")
        return plan_cycle(model_of(source, 0.0, overrides, backend), dt)[0]
    # the same path in 1/s of the time: v x s, a x s^2
    return trapezoidal(q_start, q_goal, np.asarray(vmax) * speed_scale,
                       np.asarray(amax) * speed_scale**2, dt=dt)
