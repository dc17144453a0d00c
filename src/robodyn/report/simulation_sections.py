"""Demo sections for chapter 3: generated code, computed-torque tracking, balance, the AA300 study
(HTML from ``templates/simulation.html.j2``)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from robodyn.codegen.emit import generate
from robodyn.numeric.model import compile_model
from robodyn.report.html import Markup, figure, render_macro
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
    parts.append(_macro("generated_code", paths=[p.relative_to(out).as_posix() for p in files]))

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
    parts.append(_macro("computed_torque", target=np.array2string(q1, precision=2), where=where,
                        error=err, ok=ok_track, error_held=err_held,
                        peak=np.array2string(np.abs(sim.tau).max(axis=0), precision=1)))

    with progress("LQR balance of the trolley double inverted pendulum"):
        bal = balance_double_pendulum(
            model=compile_model(load("trolley_double_pendulum"), backend=backend))
        fig = balance_figure(bal, out / "balance.png")
    parts.append(_macro("balance", bal=bal, fig=Markup(figure(fig, "balance"))))

    with progress("AA300 study: plan, PD tracking, actuator sizing, animation"):
        study = run_study(out / "aa300", animate=True, backend=backend)
    figures = [figure(p, p.stem) for p in study.figures]
    if study.animation:
        figures.append(figure(study.animation, "AA300 animation"))
    parts.append(_macro("aa300", study=study, figures=Markup("".join(figures))))
    return "\n".join(parts), ok_track and bal.upright


def _macro(name: str, **arguments: object) -> str:
    """The section ``name`` of ``templates/simulation.html.j2``."""
    return render_macro("simulation.html.j2", name, **arguments)
