"""The AA300 design study (seed thesis section 3.8): which torques must the motors deliver?

The thesis modelled the Lamberton AA300 in I-DEAS and DADS, ran inverse kinematics, planned the
joint paths of typical manoeuvres with a FORTRAN path planner, simulated them under a PD
controller and read off the actuator torques to size the motors (the real robot had suffered
motor failures). This module repeats that chain on ``rd.load("aa300")``:

1. inverse kinematics of the tool positions of a pick-and-place cycle (:mod:`.ik`);
2. path planning: straight tool lines through IK and a synchronised trapezoidal joint move
   (:mod:`.trajectory`), joined into one continuous plan;
3. gravity-compensated PD tracking (or plain PD, as in the thesis), simulated in one C call;
4. peak and RMS torque/force, peak speed and power of every actuator, overall and per
   manoeuvre, beside the ideal inverse-dynamics torques of the plan;
5. plots and a GIF animation of the arm, like the DADS animation of the thesis' figure 3.3.

The manoeuvres (tool positions in the world frame, polar: radius from the column axis, azimuth,
height; the AA300's reach is a ring of radius ~1.12-1.30 m within its joint limits):

=====================  =============================================================  ======
manoeuvre              motion                                                          time
=====================  =============================================================  ======
approach shelf         straight line radially out, 1.18 -> 1.28 m at -80 deg, z 1.00    1.5 s
lift off shelf         straight line up 0.05 m (the load leaves the shelf)              0.5 s
retract                straight line radially back to 1.18 m                           1.5 s
lift                   straight line up to z = 1.35 m (0.30 m of slide)                 1.0 s
rotate                 joint-space trapezoid: column +120 deg, tube to radius 1.25 m   limits
place                  straight line down to z = 0.75 m (0.60 m of slide)               1.5 s
=====================  =============================================================  ======

Assumptions (the thesis gives none of these numbers): a payload of ``payload`` kg (default
50 kg) carried at the tool point for the whole cycle (conservative: the approach is made empty in
practice); joint speed limits 1.0 rad/s, 0.5 m/s, 1.5 rad/s and acceleration limits 2 rad/s^2,
2 m/s^2, 4 rad/s^2 for the rotation; PD gains from a closed-loop natural frequency
``bandwidth_hz`` (default 4 Hz) and critical damping on the diagonal of the mass matrix at the
start pose.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import sympy as sp

from robodyn.numeric.model import Model, compile_model
from robodyn.robot.errors import InputError
from robodyn.robot.load import load
from robodyn.robot.model import Link, Robot
from robodyn.simulation.controllers import PD, GravityCompensation
from robodyn.simulation.ik import inverse_kinematics
from robodyn.simulation.simulation import Trajectory, simulate
from robodyn.simulation.trajectory import JointTrajectory, cartesian_line, concatenate, trapezoidal

#: Speed and acceleration limits of the rotate move (rad/s, m/s; rad/s^2, m/s^2), assumed.
VMAX = (1.0, 0.5, 1.5)
AMAX = (2.0, 2.0, 4.0)


@dataclass(frozen=True)
class Manoeuvre:
    """One phase of the cycle.

    Attributes
    ----------
    name, description : str
    start, end : float
        Times in the plan, s.
    """

    name: str
    description: str
    start: float
    end: float


@dataclass(frozen=True, eq=False)
class ActuatorDemand:
    """What one actuator must deliver (N m and rad for rotations, N and m for the slide).

    Attributes
    ----------
    joint : str
    peak : float
        Largest |torque| applied by the controller in the simulation.
    peak_ideal : float
        Largest |torque| of the inverse dynamics along the plan (perfect tracking).
    rms : float
        Root-mean-square torque over the cycle (thermal sizing).
    peak_speed : float
        Largest |joint velocity|, rad/s or m/s.
    peak_power : float
        Largest |torque * velocity|, W.
    per_manoeuvre : tuple of float
        Peak |torque| in each manoeuvre, in the order of ``AA300Study.manoeuvres``.
    """

    joint: str
    peak: float
    peak_ideal: float
    rms: float
    peak_speed: float
    peak_power: float
    per_manoeuvre: tuple[float, ...]


@dataclass(frozen=True, eq=False)
class AA300Study:
    """Result of :func:`run_study`.

    Attributes
    ----------
    manoeuvres : tuple of Manoeuvre
    plan : JointTrajectory
        The planned joint motion of the whole cycle.
    simulation : Trajectory
        The PD-tracked simulation of the plan.
    ideal_tau : (N, 3) ndarray
        Inverse-dynamics torques of the plan at ``simulation.t``.
    demands : tuple of ActuatorDemand
        One per joint: the motor-sizing figures.
    max_tracking_error : (3,) ndarray
        Largest |q_plan - q| per joint, rad or m.
    payload : float
        kg at the tool point.
    controller : str
    figures : tuple of Path
        Saved plots (empty when no directory was given).
    animation : Path or None
        The GIF, when made.
    """

    manoeuvres: tuple[Manoeuvre, ...]
    plan: JointTrajectory
    simulation: Trajectory
    ideal_tau: np.ndarray
    demands: tuple[ActuatorDemand, ...]
    max_tracking_error: np.ndarray
    payload: float
    controller: str
    figures: tuple[Path, ...] = ()
    animation: Path | None = None

    def table(self) -> str:
        """The motor-sizing table as text."""
        cols = ("peak", "ideal peak", "RMS", "peak speed", "peak power")
        rows = [f"{'joint':16s}" + "".join(f"{c:>12s}" for c in cols)]
        for d in self.demands:
            unit = "N" if d.joint == "upper_arm" else "N m"
            rows.append(f"{d.joint:16s}{d.peak:12.1f}{d.peak_ideal:12.1f}{d.rms:12.1f}"
                        f"{d.peak_speed:12.3f}{d.peak_power:12.1f}  ({unit})")
        return "\n".join(rows)


def with_payload(robot: Robot, mass: float) -> Robot:
    """``robot`` carrying a point mass ``mass`` (kg) at its tool point (merged into the last link)."""
    if mass < 0 or not np.isfinite(mass):
        raise InputError(f"payload mass must be >= 0 kg, got {mass!r}")
    if mass == 0:
        return robot
    link = robot.links[-1]
    m1, mp = link.mass, sp.Float(mass)
    c1, p = link.com, sp.ImmutableMatrix(robot.tool[:3, 3])
    m = m1 + mp
    # combined centre of mass c = (m1 c1 + mp p) / m
    c = (m1 * c1 + mp * p) / m

    def shift(mass_: sp.Expr, d: sp.MatrixBase) -> sp.Matrix:
        # parallel axis: m (|d|^2 I - d d^T)
        return mass_ * ((d.T * d)[0, 0] * sp.eye(3) - d * d.T)

    inertia = link.inertia + shift(m1, c1 - c) + shift(mp, p - c)
    new_link = Link(link.name, m, sp.ImmutableMatrix(c),
                    sp.ImmutableMatrix(inertia), link.hydro)
    return dataclasses.replace(robot, name=f"{robot.name}+{mass:g}kg",
                               links=robot.links[:-1] + (new_link,))


def _point(radius: float, azimuth_deg: float, height: float) -> np.ndarray:
    a = np.radians(azimuth_deg)
    return np.array([radius * np.cos(a), radius * np.sin(a), height])


def plan_cycle(model: Model, dt: float = 1e-3) -> tuple[JointTrajectory, tuple[Manoeuvre, ...]]:
    """Inverse kinematics and path planning of the pick-lift-rotate-place cycle (module docstring)."""
    shelf, station = -80.0, 40.0
    home = inverse_kinematics(model, _point(1.18, shelf, 1.00), np.array([0.0, 0.78, 2.0])).q
    parts: list[tuple[str, str, JointTrajectory]] = []
    q = home

    def line(name: str, text: str, target: np.ndarray, duration: float) -> None:
        nonlocal q
        part = cartesian_line(model, q, target, duration, dt=dt)
        parts.append((name, text, part))
        q = part.at(part.duration)[0]

    line("approach shelf", "straight line radially out to the shelf", _point(1.28, shelf, 1.00), 1.5)
    line("lift off shelf", "straight line up 0.05 m: the load leaves the shelf",
         _point(1.28, shelf, 1.05), 0.5)
    line("retract", "straight line radially back out of the shelf", _point(1.18, shelf, 1.05), 1.5)
    line("lift", "straight line up 0.30 m", _point(1.18, shelf, 1.35), 1.0)
    goal = inverse_kinematics(model, _point(1.25, station, 1.35),
                              q + np.array([np.radians(station - shelf), 0.0, 0.0])).q
    rotate = trapezoidal(q, goal, VMAX, AMAX, dt=dt)
    parts.append(("rotate", "column +120 deg and tube swing, trapezoidal joint move", rotate))
    q = goal
    line("place", "straight line down 0.60 m onto the place station", _point(1.25, station, 0.75), 1.5)
    manoeuvres, start = [], 0.0
    for name, text, part in parts:
        manoeuvres.append(Manoeuvre(name, text, start, start + part.duration))
        start += part.duration
    return concatenate(*(p for _, _, p in parts), dt=dt), tuple(manoeuvres)


def run_study(directory: str | Path | None = None, *, payload: float = 50.0, dt: float = 1e-3,
              bandwidth_hz: float = 4.0, gravity_compensation: bool = True, animate: bool = True,
              fps: int = 10, settle: float = 0.5, backend: str = "c") -> AA300Study:
    """Plan, simulate and size the AA300's actuators for a pick-and-place cycle.

    Parameters
    ----------
    directory : str or Path, optional
        Where to save the plots (``aa300_joints.png``, ``aa300_torques.png``,
        ``aa300_tool_path.png``) and the animation (``aa300.gif``); nothing is saved without it.
    payload : float
        kg at the tool point.
    dt : float
        Plan sampling and integration step, s.
    bandwidth_hz : float
        Closed-loop natural frequency of the PD loops, Hz.
    gravity_compensation : bool
        PD + g(q) (default) or the plain PD of the thesis (which then sags under gravity).
    animate : bool
        Make the GIF (when ``directory`` is given).
    fps : int
        Animation frames per second of simulated time.
    settle : float
        Time simulated after the plan ends (the arm comes to rest), s.
    backend : {"c", "numpy"}

    Returns
    -------
    AA300Study
    """
    robot = with_payload(load("aa300"), payload)
    model = compile_model(robot, backend=backend)  # type: ignore[arg-type]
    plan, manoeuvres = plan_cycle(model, dt)
    q0 = plan.at(0.0)[0]
    # gains: Kp = M_ii w^2, Kd = 2 zeta w M_ii with zeta = 1
    w = 2 * np.pi * bandwidth_hz
    mdiag = np.diag(model.mass_matrix(q0))
    kp, kd = mdiag * w**2, 2 * mdiag * w
    law = GravityCompensation if gravity_compensation else PD
    controller = law(kp, kd, plan)
    qd0 = np.zeros(model.dof)
    start = q0 if gravity_compensation else q0 - np.linalg.solve(np.diag(kp), model.gravity(q0))
    # simulate the plan and `settle` seconds at rest after it
    steps = int(round((plan.duration + settle) / dt))
    sim = simulate(model, start, qd0, steps * dt, dt, "rk4", controller)
    q_r, qd_r, qdd_r = plan.at(sim.t)
    ideal = model.inverse_dynamics(q_r, qd_r, qdd_r)
    demands = []
    for j, name in enumerate(robot.joint_names):
        per = tuple(float(np.max(np.abs(sim.tau[(sim.t >= m.start) & (sim.t <= m.end), j])))
                    for m in manoeuvres)
        demands.append(ActuatorDemand(
            joint=name, peak=float(np.max(np.abs(sim.tau[:, j]))),
            peak_ideal=float(np.max(np.abs(ideal[:, j]))),
            rms=float(np.sqrt(np.mean(sim.tau[:, j] ** 2))),
            peak_speed=float(np.max(np.abs(sim.qd[:, j]))),
            peak_power=float(np.max(np.abs(sim.tau[:, j] * sim.qd[:, j]))), per_manoeuvre=per))
    error = np.max(np.abs(q_r - sim.q), axis=0)
    error.flags.writeable = False
    ideal.flags.writeable = False
    study = AA300Study(tuple(manoeuvres), plan, sim, ideal, tuple(demands), error, float(payload),
                       controller.name)
    if directory is None:
        return study
    from robodyn.studies import simulation_plots as plots

    out = Path(directory)
    out.mkdir(parents=True, exist_ok=True)
    figures = plots.aa300_figures(study, model, out)
    gif = plots.aa300_animation(study, model, out / "aa300.gif", fps) if animate else None
    return dataclasses.replace(study, figures=figures, animation=gif)


__all__ = ["AA300Study", "ActuatorDemand", "Manoeuvre", "plan_cycle", "run_study", "with_payload"]
