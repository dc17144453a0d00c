"""A virtual laboratory: simulate a robot running a test program and measure it with realistic sensors.

The plant is the compiled model of ``robot``; a computed-torque controller (default: exact model,
5 Hz critically damped error dynamics) tracks the program, sampled at the simulation step. The
exact motion (``Truth``) is then *measured* by the sensors of the thesis' laboratory (ch. 4):

* time: the logger stamps sample k with the nominal ``k dt`` while the samples are actually taken
  at ``k dt + delta_k``, ``delta_k`` normal with standard deviation ``jitter`` (clipped to
  ``+-dt/4``) -- sample-time jitter;
* joint position: a motor encoder of ``counts_per_rev`` counts behind a gear of ratio ``G``:
  ``q_meas = 2 pi round(q G cpr / 2 pi) / (G cpr)`` (quantisation step ``2 pi / (G cpr)``);
* motor current: ``I = tau / (G k_t (1 + e)) + I_off + noise``: the joint torque through the
  drive's gain with a per-joint torque-constant error ``e`` (normal, std
  ``torque_constant_error``), a per-joint offset (normal, std ``current_offset``) and white
  noise (std ``current_noise``); ``G`` and ``k_t`` are the description's drive values;
* joint torque sensor: ``tau + noise`` (std ``torque_noise``; None: no sensor);
* tracker: the tool position ``p(t - latency) + noise`` (std ``tracker_noise`` per axis) every
  ``tracker_period`` s, stamped ``t`` on the joint clock (so the tracker lags by ``latency``).

Velocities and accelerations are *not* measured: the :class:`~robodyn.measure.Recording`
estimates them from the encoder positions, as it would for a real arm. The exact values, the
drawn sensor errors and the actual drive gains are kept on :class:`LabRun.truth`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import CubicHermiteSpline

from robodyn.measure.recording import Recording
from robodyn.numeric.model import Model, compile_model
from robodyn.robot.errors import InputError
from robodyn.robot.model import Robot
from robodyn.simulation.controllers import ComputedTorque, Controller
from robodyn.simulation.simulation import simulate
from robodyn.simulation.trajectory import JointTrajectory
from robodyn.studies.excitation import Excitation
from robodyn.studies.testprog import TestProgram

__all__ = ["LabRun", "Sensors", "Truth", "virtual_lab"]


@dataclass(frozen=True)
class Sensors:
    """Sensor models of the virtual laboratory (module docstring); SI units.

    Attributes
    ----------
    sample_period : float
        Joint logger period dt, s.
    jitter : float
        Standard deviation of the sample-time jitter, s.
    counts_per_rev : float
        Motor encoder counts per motor revolution (after quadrature); 0 disables quantisation.
    current_noise, current_offset : float
        Standard deviation of the current noise and of the per-joint current offsets, A.
    torque_constant_error : float
        Standard deviation of the relative torque-constant error.
    torque_noise : float or None
        Standard deviation of the joint torque sensor noise, N m; None: no torque sensors.
    tracker_noise : float
        Standard deviation of the tracker position noise per axis, m.
    tracker_latency : float
        Tracker delay, s (>= 0).
    tracker_period : float
        Tracker period, s; 0 disables the tracker.
    """

    sample_period: float = 1e-3
    jitter: float = 2e-5
    counts_per_rev: float = 4096.0
    current_noise: float = 0.02
    current_offset: float = 0.01
    torque_constant_error: float = 0.03
    torque_noise: float | None = 0.05
    tracker_noise: float = 2e-5
    tracker_latency: float = 0.005
    tracker_period: float = 0.01

    def __post_init__(self) -> None:
        for name in ("sample_period",):
            if not getattr(self, name) > 0:
                raise InputError(f"Sensors.{name} must be > 0, got {getattr(self, name)!r}")
        for name in ("jitter", "counts_per_rev", "current_noise", "current_offset",
                     "torque_constant_error", "tracker_noise", "tracker_latency", "tracker_period"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v >= 0):
                raise InputError(f"Sensors.{name} must be a finite number >= 0, got {v!r}")
        if self.torque_noise is not None and not (np.isfinite(self.torque_noise) and self.torque_noise >= 0):
            raise InputError(f"Sensors.torque_noise must be >= 0 or None, got {self.torque_noise!r}")


@dataclass(frozen=True, eq=False)
class Truth:
    """What the virtual sensors measured, exactly.

    Attributes
    ----------
    t : (N,) ndarray
        The recording's (nominal) time stamps, s.
    t_actual : (N,) ndarray
        When each sample was actually taken (``t`` + jitter), s.
    q, qd, qdd, tau : (N, n) ndarray
        Exact joint motion and applied joint torque at ``t`` (the time stamps), SI units.
    current : (N, n) ndarray
        Noise-free motor current at ``t``, A.
    drive_gain : (n,) ndarray
        Actual ``G k_t (1 + e)`` per joint, N m/A.
    current_offset : (n,) ndarray
        Drawn current offsets, A.
    tool_t : (M,) ndarray
        Tracker time stamps, s.
    tool_points : (M, 3) ndarray
        Exact tool positions at ``tool_t`` (no latency, no noise), m.
    latency : float
        Tracker delay, s.
    reference : JointTrajectory
        The program the controller tracked.
    """

    t: np.ndarray
    t_actual: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    tau: np.ndarray
    current: np.ndarray
    drive_gain: np.ndarray
    current_offset: np.ndarray
    tool_t: np.ndarray
    tool_points: np.ndarray
    latency: float
    reference: JointTrajectory = field(repr=False)


@dataclass(frozen=True, eq=False)
class LabRun:
    """Output of :func:`virtual_lab`: the measured recording and the exact truth behind it.

    Attributes
    ----------
    recording : Recording
        What a logger would have written (q from encoders, current, torque sensor, tracker).
    truth : Truth
    sensors : Sensors
    """

    recording: Recording
    truth: Truth
    sensors: Sensors


def _reference(trajectory: JointTrajectory | TestProgram | Excitation) -> JointTrajectory:
    if isinstance(trajectory, JointTrajectory):
        return trajectory
    if isinstance(trajectory, TestProgram):
        return trajectory.trajectory
    if isinstance(trajectory, Excitation):
        return trajectory.trajectory()
    raise TypeError(f"virtual_lab: trajectory must be a JointTrajectory, TestProgram or Excitation, "
                    f"got {type(trajectory).__name__}")


def virtual_lab(robot: Robot | Model, trajectory: JointTrajectory | TestProgram | Excitation, *,
                sensors: Sensors | None = None, seed: int = 0, controller: Controller | None = None,
                oversample: int = 4) -> LabRun:
    """Simulate ``robot`` running ``trajectory`` and measure it with ``sensors``.

    Parameters
    ----------
    robot : Robot or Model
        The plant (its compiled model is simulated).
    trajectory : JointTrajectory, TestProgram or Excitation
        The program to run (from :mod:`robodyn.studies.testprog`, :func:`robodyn.excitation` or
        :mod:`robodyn.simulation.trajectory`); the arm starts at rest at its first position.
    sensors : Sensors, optional
        Default ``Sensors()``.
    seed : int
        Seed of every random draw (noise, offsets, torque-constant errors, jitter).
    controller : Controller, optional
        Default ``ComputedTorque(reference, kp=(2 pi 5)^2, kd=2 (2 pi 5))`` with the exact model.
    oversample : int
        Simulation steps per logger period (the controller runs at this rate too).

    Returns
    -------
    LabRun
    """
    model = robot if isinstance(robot, Model) else compile_model(robot)
    sens = Sensors() if sensors is None else sensors
    ref = _reference(trajectory)
    n = model.dof
    if ref.dof != n:
        raise InputError(f"virtual_lab: the trajectory has {ref.dof} joints, robot "
                         f"{model.robot.name!r} has {n}")
    rng = np.random.default_rng(seed)
    dt = sens.sample_period
    h = dt / int(oversample)
    steps = int(np.floor(ref.duration / h + 1e-9))
    w = 2.0 * np.pi * 5.0
    ctrl = controller or ComputedTorque(ref, kp=w * w, kd=2.0 * w)
    q0 = ref.at(0.0)[0]
    sim = simulate(model, q0, None, steps * h, h, "rk4", ctrl)
    # exact motion between steps: cubic Hermite on (q, qd), to fourth order in h
    qs = CubicHermiteSpline(sim.t, sim.q, sim.qd)
    qds = CubicHermiteSpline(sim.t, sim.qd, sim.qdd)

    def tau_at(t: np.ndarray) -> np.ndarray:
        # the torque is held over each step: tau[k] on [t_k, t_k+1)
        k = np.clip(np.floor(t / h + 1e-9).astype(int), 0, sim.t.size - 1)
        return sim.tau[k]

    # --- time base with jitter -----------------------------------------------------------------
    count = int(np.floor(sim.t[-1] / dt + 1e-9)) + 1
    t = dt * np.arange(count)
    delta = np.zeros(count)
    if sens.jitter > 0:
        delta = np.clip(rng.normal(0.0, sens.jitter, count), -dt / 4, dt / 4)
    t_act = np.clip(t + delta, 0.0, sim.t[-1])
    # --- exact values (at the stamps) and the values the sensors saw (at the actual instants) ---
    q_true, qd_true = qs(t), qs(t, 1)
    qdd_true = qds(t, 1)
    tau_true = tau_at(t)
    q_seen, tau_seen = qs(t_act), tau_at(t_act)
    drives = model.robot.joints
    gear = np.array([abs(float(j.drive.gear_ratio)) for j in drives])
    kt = np.array([float(j.drive.torque_constant) for j in drives])
    sign = np.sign([float(j.drive.gear_ratio) for j in drives])
    # encoder: counts of the motor shaft, q = 2 pi counts / (G cpr)
    if sens.counts_per_rev > 0:
        step = 2.0 * np.pi / (gear * sens.counts_per_rev)
        q_meas = step * np.round(q_seen / step)
    else:
        q_meas = q_seen.copy()
    # current: I = tau / (G k_t (1 + e)) + offset + noise  (signed gear ratio: motor direction)
    gain = sign * gear * kt * (1.0 + rng.normal(0.0, sens.torque_constant_error, n))
    offset = rng.normal(0.0, sens.current_offset, n)
    current = tau_seen / gain + offset + rng.normal(0.0, sens.current_noise, (count, n))
    tau_meas = None
    if sens.torque_noise is not None:
        tau_meas = tau_seen + rng.normal(0.0, sens.torque_noise, (count, n))
    # tracker: p(t - latency) + noise, stamped t
    tool_t = tool_true = tool_meas = None
    if sens.tracker_period > 0:
        tool_t = np.arange(0.0, sim.t[-1] + 1e-12, sens.tracker_period)
        tool_true = model.forward_kinematics(qs(tool_t))[:, :3, 3]
        lagged = qs(np.clip(tool_t - sens.tracker_latency, 0.0, None))
        tool_meas = (model.forward_kinematics(lagged)[:, :3, 3]
                     + rng.normal(0.0, sens.tracker_noise, (tool_t.size, 3)))
    rec = Recording(t=t, q=q_meas, tau=tau_meas, current=current, joint_names=model.robot.joint_names,
                    tool_t=tool_t, tool_points=tool_meas, source=f"virtual_lab({model.robot.name})")
    truth = Truth(t=_frozen(t), t_actual=_frozen(t_act), q=_frozen(q_true), qd=_frozen(qd_true),
                  qdd=_frozen(qdd_true), tau=_frozen(tau_true), current=_frozen(tau_true / gain),
                  drive_gain=_frozen(gain), current_offset=_frozen(offset),
                  tool_t=_frozen(np.zeros(0) if tool_t is None else tool_t),
                  tool_points=_frozen(np.zeros((0, 3)) if tool_true is None else tool_true),
                  latency=float(sens.tracker_latency), reference=ref)
    return LabRun(rec, truth, sens)


def _frozen(a: np.ndarray) -> np.ndarray:
    a = np.array(a, dtype=float)
    a.flags.writeable = False
    return a
