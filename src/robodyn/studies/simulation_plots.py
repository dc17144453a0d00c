"""Figures and animations of the simulation studies (matplotlib figures without pyplot: files only, the
user's backend untouched)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.animation import FuncAnimation, PillowWriter
from matplotlib.figure import Figure

from robodyn.numeric.model import Model
from robodyn.simulation.energy import frame_origins

if TYPE_CHECKING:
    from robodyn.simulation.simulation import Trajectory
    from robodyn.simulation.trajectory import JointTrajectory
    from robodyn.studies.aa300 import AA300Study
    from robodyn.studies.balance import BalanceResult


def _shade(ax, study: AA300Study) -> None:
    for k, m in enumerate(study.manoeuvres):
        if k % 2:
            ax.axvspan(m.start, m.end, color="0.93", zorder=0)


def aa300_figures(study: AA300Study, model: Model, directory: Path) -> tuple[Path, ...]:
    """Joint motion, actuator torques and tool path of the AA300 study, saved as PNG files."""
    sim, names = study.simulation, model.robot.joint_names
    units = ["rad", "m", "rad"]
    q_r = study.plan.at(sim.t)[0]
    paths = []

    fig = Figure(figsize=(11, 8))

    axes = fig.subplots(3, 2, sharex=True)
    for j in range(3):
        ax = axes[j, 0]
        _shade(ax, study)
        ax.plot(sim.t, q_r[:, j], "k--", lw=1, label="plan")
        ax.plot(sim.t, sim.q[:, j], lw=1.2, label="simulated")
        ax.set_ylabel(f"{names[j]} ({units[j]})")
        ax = axes[j, 1]
        _shade(ax, study)
        ax.plot(sim.t, 1e3 * (q_r[:, j] - sim.q[:, j]), lw=1)
        ax.set_ylabel(f"error (m{units[j]})")
    axes[0, 0].legend(loc="best", fontsize=8)
    for m in study.manoeuvres:
        axes[0, 0].text(0.5 * (m.start + m.end), axes[0, 0].get_ylim()[1], m.name, ha="center",
                        va="bottom", fontsize=7, rotation=20)
    axes[-1, 0].set_xlabel("t (s)")
    axes[-1, 1].set_xlabel("t (s)")
    fig.suptitle(f"AA300 cycle, {study.controller} tracking, payload {study.payload:g} kg")
    fig.tight_layout()
    paths.append(directory / "aa300_joints.png")
    fig.savefig(paths[-1], dpi=110)

    fig = Figure(figsize=(9, 8))

    axes = fig.subplots(3, 1, sharex=True)
    for j, d in enumerate(study.demands):
        ax = axes[j]
        _shade(ax, study)
        unit = "N" if j == 1 else "N m"
        ax.plot(sim.t, study.ideal_tau[:, j], "k--", lw=1, label="inverse dynamics of the plan")
        ax.plot(sim.t, sim.tau[:, j], lw=1.2, label="applied (simulation)")
        for sign in (-1, 1):
            ax.axhline(sign * d.peak, color="C3", lw=0.8, ls=":")
        ax.set_ylabel(f"{d.joint} ({unit})")
        ax.set_title(f"peak {d.peak:.0f} {unit}, RMS {d.rms:.0f} {unit}", fontsize=9)
    axes[0].legend(loc="best", fontsize=8)
    axes[-1].set_xlabel("t (s)")
    fig.tight_layout()
    paths.append(directory / "aa300_torques.png")
    fig.savefig(paths[-1], dpi=110)

    tool = model.forward_kinematics(sim.q)[:, :3, 3]
    fig = Figure(figsize=(10, 4.5))
    ax = fig.add_subplot(1, 2, 1)
    ax.plot(tool[:, 0], tool[:, 1])
    ax.plot(0, 0, "ko")
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title("tool path, top view")
    ax = fig.add_subplot(1, 2, 2, projection="3d")
    ax.plot(tool[:, 0], tool[:, 1], tool[:, 2])
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.set_zlabel("z")
    ax.set_title("tool path")
    fig.tight_layout()
    paths.append(directory / "aa300_tool_path.png")
    fig.savefig(paths[-1], dpi=110)
    return tuple(paths)


def aa300_animation(study: AA300Study, model: Model, path: Path, fps: int = 12) -> Path:
    """GIF of the arm moving through the cycle (a stick figure with the tool's trail)."""
    sim = study.simulation
    every = max(1, int(round(1.0 / (fps * sim.dt))))
    frames = np.arange(0, sim.t.size, every)
    tool = model.forward_kinematics(sim.q)[:, :3, 3]
    fig = Figure(figsize=(5.5, 5))
    ax = fig.add_subplot(projection="3d")
    ax.set_xlim(-1.5, 1.5)
    ax.set_ylim(-1.5, 1.5)
    ax.set_zlim(0, 2.2)
    ax.set_box_aspect((3.0, 3.0, 2.2))
    ax.view_init(elev=20, azim=-60)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_zlabel("z (m)")
    (arm,) = ax.plot([], [], [], "-o", lw=4, color="C0", ms=4)
    (trail,) = ax.plot([], [], [], lw=1, color="C3")
    title = ax.set_title("")

    def draw(k: int):
        pts = stick_figure(model, sim.q[k])
        arm.set_data_3d(pts[:, 0], pts[:, 1], pts[:, 2])
        trail.set_data_3d(tool[: k + 1, 0], tool[: k + 1, 1], tool[: k + 1, 2])
        phase = next((m.name for m in study.manoeuvres if m.start <= sim.t[k] <= m.end), "")
        title.set_text(f"AA300  t = {sim.t[k]:4.1f} s  {phase}")
        return arm, trail, title

    anim = FuncAnimation(fig, draw, frames=frames, blit=False)
    anim.save(path, writer=PillowWriter(fps=fps), dpi=80)
    return path


def balance_figure(result: BalanceResult, path: Path) -> Path:
    """Angles, trolley position and force of the LQR balance run."""
    sim = result.simulation
    fig = Figure(figsize=(8, 7))
    axes = fig.subplots(3, 1, sharex=True)
    axes[0].plot(sim.t, np.degrees(sim.q[:, 1]), label="theta1 (rod 1)")
    axes[0].plot(sim.t, np.degrees(sim.q[:, 1] + sim.q[:, 2]), label="theta1 + theta2 (rod 2)")
    axes[0].set_ylabel("angle from upright (deg)")
    axes[0].legend(fontsize=8)
    axes[1].plot(sim.t, sim.q[:, 0])
    axes[1].set_ylabel("trolley x (m)")
    axes[2].plot(sim.t, sim.tau[:, 0])
    axes[2].set_ylabel("force F (N)")
    axes[2].set_xlabel("t (s)")
    fig.suptitle("Trolley double inverted pendulum held upright by LQR (force on the trolley only)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    return path


def trajectory_figure(sim: Trajectory, names: tuple[str, ...], path: Path,
                      reference: JointTrajectory | None = None) -> Path:
    """Positions (with the reference, dashed), velocities, torques and energy of a simulation.

    Parameters
    ----------
    sim : Trajectory
    names : tuple of str, length n
        Joint names for the legends.
    path : Path
        PNG file to write.
    reference : JointTrajectory, optional
        The planned motion, drawn dashed over the positions.

    Returns
    -------
    Path
    """
    fig = Figure(figsize=(9, 10))
    axes = fig.subplots(4, 1, sharex=True)
    for j, name in enumerate(names):
        (line,) = axes[0].plot(sim.t, sim.q[:, j], lw=1.2, label=name)
        if reference is not None:
            axes[0].plot(sim.t, reference.at(sim.t)[0][:, j], "--", lw=0.9, color=line.get_color())
        axes[1].plot(sim.t, sim.qd[:, j], lw=1.0)
        axes[2].plot(sim.t, sim.tau[:, j], lw=1.0)
    axes[0].set_ylabel("q (rad, m)")
    axes[0].legend(fontsize=7, ncols=min(len(names), 7))
    axes[1].set_ylabel("qd (rad/s, m/s)")
    axes[2].set_ylabel("tau (N m, N)")
    axes[3].plot(sim.t, sim.energy - sim.energy[0], label="E - E(0)")
    axes[3].plot(sim.t, sim.kinetic, lw=0.8, label="kinetic")
    axes[3].set_ylabel("energy (J)")
    axes[3].legend(fontsize=7)
    axes[3].set_xlabel("t (s)")
    fig.suptitle(f"{sim.robot}: {sim.method}, dt = {sim.dt:g} s, controller {sim.controller}")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    return path


__all__ = ["aa300_animation", "aa300_figures", "balance_figure", "trajectory_figure"]


def stick_figure(model: Model, q: np.ndarray) -> np.ndarray:
    """Points (K, 3) to draw the AA300 at ``q``: column foot and top, carriage, tube axis, tool."""
    pts = frame_origins(model, q)
    column_top = np.array([0.0, 0.0, 2.0])
    # base, column top, back to the carriage, out along the arm to the tube axis, tool
    return np.vstack([pts[0], column_top, pts[2], pts[3], pts[4]])
