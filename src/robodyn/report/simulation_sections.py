"""Demo sections for chapter 3: generated code, computed-torque tracking, balance, the AA300 study."""

from __future__ import annotations

import html
from pathlib import Path

import numpy as np

from robodyn.codegen.emit import generate
from robodyn.numeric.model import compile_model
from robodyn.report.html import figure
from robodyn.robot.load import load
from robodyn.robot.model import Robot
from robodyn.simulation.controllers import ComputedTorque
from robodyn.simulation.simulation import simulate
from robodyn.simulation.trajectory import quintic
from robodyn.studies.aa300 import run_study
from robodyn.studies.balance import balance_double_pendulum
from robodyn.studies.simulation_plots import balance_figure
from robodyn.text import progress


def simulation_sections(robot: Robot, out: Path, backend: str = "c") -> tuple[str, bool]:
    """Run the chapter-3 demo steps, write their files into ``out``; return (HTML, all ok).

    ``backend``: "c" (compiled) or "numpy" (no compiler needed) for every simulated model.
    """
    where = "generated C" if backend == "c" else "the NumPy backend"
    parts: list[str] = []
    code_dir = out / "code"
    with progress("generating C and Python code for the PUMA 560"):
        files = generate(robot, "c", code_dir) + generate(robot, "python", code_dir)
    listing = ", ".join(f"<code>{html.escape(p.relative_to(out).as_posix())}</code>" for p in files)
    parts.append(f"<h2>Generated code</h2><p>Written: {listing}. <code>robodyn codegen ROBOT "
                 f"--lang c|python|octave|fortran|julia|latex|mex</code> writes the others.</p>")

    with progress(f"computed-torque tracking of a quintic move (PUMA 560, {where})"):
        model = compile_model(robot, backend=backend)
        q0 = np.zeros(robot.dof)
        q1 = np.array([0.8, -0.6, 0.9, 0.5, -0.7, 1.0])[: robot.dof]
        plan = quintic(q0, q1, 2.0, dt=1e-3)
        ctrl = ComputedTorque(plan, kp=400.0, kd=40.0)
        sim = simulate(model, q0, None, 2.0, 1e-3, controller=ctrl, control="continuous")
        held = simulate(model, q0, None, 2.0, 1e-3, controller=ctrl)
        err = float(np.max(np.abs(sim.q - plan.q[: len(sim.t)])))
        err_held = float(np.max(np.abs(held.q - plan.q[: len(held.t)])))
    # continuous law, exact model (rotor inertia and friction included): RK4's own error only
    # (tests/simulation checks its fourth-order convergence)
    ok_track = err < 1e-8
    parts.append(
        "<h2>Computed torque, PUMA 560</h2><p>Quintic move from zero to "
        f"{html.escape(np.array2string(q1, precision=2))} rad in 2 s, RK4 at 1 ms in {where}, "
        f"K<sub>p</sub> = 400, K<sub>d</sub> = 40. Law evaluated at every RK4 stage (a "
        f"continuous-time controller) whose model is exactly the simulated plant's (rotor "
        f"inertia and friction included): largest joint tracking error {err:.2e} rad ("
        + ('<span class="ok">below 1e-8: ok</span>' if ok_track else '<span class="bad">no</span>')
        + "). That figure is RK4's own integration error with the exact model, not a measure "
        "of tracking with a real controller: with a model that differs from the plant the "
        "error is set by the mismatch instead. The same law sampled once per step and held "
        "(a 1 kHz digital controller): "
        f"{err_held:.2e} rad"
        + f"; peak torques {html.escape(np.array2string(np.abs(sim.tau).max(axis=0), precision=1))}"
        " N m.</p>")

    with progress("LQR balance of the trolley double inverted pendulum"):
        bal = balance_double_pendulum(
            model=compile_model(load("trolley_double_pendulum"), backend=backend))
        fig = balance_figure(bal, out / "balance.png")
    parts.append(
        "<h2>Double inverted pendulum on a trolley (the thesis' Fig. 3.1), LQR</h2>"
        f"<p>From rod angles (0.1, &minus;0.05) rad; largest tilt {bal.max_tilt:.3f} rad, final "
        f"tilt {bal.final_tilt:.1e} rad, peak force {bal.peak_force:.1f} N: "
        + ('<span class="ok">kept upright</span>' if bal.upright else '<span class="bad">fell</span>')
        + "</p>" + figure(fig, "balance"))

    with progress("AA300 study: plan, PD tracking, actuator sizing, animation"):
        study = run_study(out / "aa300", animate=True, backend=backend)
    imgs = "".join(figure(p, p.stem) for p in study.figures)
    anim = figure(study.animation, "AA300 animation") if study.animation else ""
    parts.append(
        "<h2>AA300: pick-and-place cycle and actuator sizing</h2>"
        f"<p>Payload {study.payload:g} kg, controller {html.escape(study.controller)}. Peak "
        "actuator demand per joint (the motor-sizing question of the thesis' section 3.8):</p>"
        f"<pre>{html.escape(study.table())}</pre>{imgs}{anim}")
    return "\n".join(parts), ok_track and bal.upright
