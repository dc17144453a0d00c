"""``make demo``: the PUMA 560 three ways, generated code, simulations, and an HTML report.

The report is the ``demo.html.j2`` template around a list of sections. Each section comes from a
:class:`DemoSection`: a function that runs one analysis, writes its files into the output folder
and returns its HTML fragment and whether its checks passed. To add an analysis to the demo,
write such a function and append one entry to :data:`SECTIONS`.
"""

from __future__ import annotations

import csv
import io
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path

import sympy as sp

from robodyn._version import __version__
from robodyn.report.agreement import (
    AGREEMENT_HEADERS,
    COUNT_HEADERS,
    TOLERANCE,
    Agreement,
    agreement,
    agreement_rows,
    count_rows,
    derive_all,
    verdict,
)
from robodyn.report.html import Markup, html_table, render
from robodyn.report.simulation_sections import simulation_sections
from robodyn.robot.load import load
from robodyn.robot.model import Robot
from robodyn.symbolic.eom import EquationsOfMotion, derive
from robodyn.symbolic.render import render_json, render_latex, render_text
from robodyn.symbolic.render_mathml import render_mathml
from robodyn.text import markdown_table, progress, steps, table

#: The thesis the demo re-creates, cited in the report.
CITATION = ("The thesis: a PhD thesis on robotic manipulator modelling (dynamic formulations, "
            "modelling packages, instrumentation of a PUMA 560, model validation, kinematic "
            "calibration, underwater manipulators), whose abstract opens \"The accuracy and "
            "performance of robotic manipulators are crucial to their commercial viability\"; its "
            "author and title are not recorded in this project. Equation, figure and table numbers "
            "in this report (eqs. 2.46-2.47, Fig. 3.1, Tables 3.1-3.2) are the thesis'.")


@dataclass(frozen=True)
class DemoContext:
    """What every section builder gets: the output folder, the demo robot and the backend.

    Attributes
    ----------
    out : Path
        Output folder (exists); a section writes its files here or in a subfolder.
    robot : Robot
        The PUMA 560.
    backend : str
        "c" (compiled) or "numpy" (no compiler found) for every simulated model.
    """

    out: Path
    robot: Robot
    backend: str


@dataclass(frozen=True)
class DemoSection:
    """One analysis of the demo report.

    Attributes
    ----------
    name : str
        Printed at the end of the demo with "ok" or "FAILED".
    build : callable
        ``build(context: DemoContext) -> (html_fragment, ok)``; the fragment is trusted HTML
        (escape anything that comes from data), its figures embedded with
        :func:`robodyn.report.html.figure`.
    steps : int
        Number of :func:`robodyn.text.progress` steps it runs (for the progress bar).
    """

    name: str
    build: Callable[[DemoContext], tuple[str, bool]]
    steps: int = 1


def _simulation(ctx: DemoContext) -> tuple[str, bool]:
    return simulation_sections(ctx.robot, ctx.out, ctx.backend)


def _calibration(ctx: DemoContext) -> tuple[str, bool]:
    """Run the PUMA 560 calibration study into ``out/calibration``; (HTML section, all ok)."""
    from robodyn.report.calibration_report import study_section
    from robodyn.studies.calibration_study import puma_study

    with progress("PUMA 560 calibration study (DH, Hayati, S-model, POE; 2 tracker noises)"):
        study = puma_study(ctx.out / "calibration")
    (ctx.out / "calibration" / "study.txt").write_text(study.table() + "\n\n"
                                                       + "\n".join(study.notes) + "\n")
    # every model but standard DH from the nominal start must explain all but the noise
    ok = all(c.test_after.rms < 1.3 * c.sigma * 3**0.5 for c in study.cases
             if (c.model, c.initial) != ("dh", "nominal"))
    return study_section(study, "calibration"), ok


def _kinova(ctx: DemoContext) -> tuple[str, bool]:
    from robodyn.report.identification_report import kinova_section

    return kinova_section(ctx.out)


def _underwater(ctx: DemoContext) -> tuple[str, bool]:
    """The thesis's chapter-7 effect series on the built-in two-link underwater arm."""
    import numpy as np

    from robodyn.report.underwater import write_study
    from robodyn.studies.underwater import effect_series
    from robodyn.studies.underwater_model_error import model_error_study
    from robodyn.studies.underwater_sensitivity import sensitivity

    robot = load("underwater_2r")
    with progress("underwater effect series (underwater_2r: dry, buoyancy, added mass, drag, ...)"):
        series = effect_series(robot, move_time=1.0, hold_time=0.5,
                               free_time=1.5, dt=2e-3, backend=ctx.backend)
    t = series.runs[0].tracked.t
    with progress("underwater sensitivity to C_d and current speed"):
        sens = sensitivity(robot, series.reference, t, free_time=1.5, dt=2e-3,
                           direction=series.current, backend=ctx.backend)
    with progress("underwater computed torque with a model omitting each effect"):
        errors = model_error_study(robot, series.reference, float(t[-1]), dt=2e-3,
                                   current=series.current, backend=ctx.backend)
    write_study(series, ctx.out / "underwater", sens, errors)
    table = series.table
    amplitude = table.groupby("effect", sort=False)["free_amplitude"].max()
    exact = errors.table[errors.table["omitted"] == "nothing"]["max_error"].max()
    # drag dissipates: the free swing with drag is smaller than with added mass alone; the exact
    # model tracks to round-off, the dry model does not
    ok = bool(np.isfinite(table.select_dtypes("number").to_numpy()).all()
              and amplitude["drag"] < amplitude["added_mass"] and exact < 1e-8
              and errors.table["max_error"].max() > 1e-3)
    return (ctx.out / "underwater" / "underwater_section.html").read_text(encoding="utf-8"), ok


def _sweep(ctx: DemoContext) -> tuple[str, bool]:
    """A small AA300 actuator-sizing sweep (3 payloads x 3 bandwidths) on a local Dask cluster."""
    import numpy as np

    from robodyn.report.sweep_demo import aa300_sweep_demo

    with progress("AA300 actuator-sizing sweep on a local Dask cluster (9 cases)"):
        table, fragment = aa300_sweep_demo(ctx.out / "aa300_sweep", workers=2, progress=False)
    ok = bool(len(table) == 9 and ("error" not in table or table["error"].isna().all())
              and np.isfinite(table.select_dtypes("number").to_numpy()).all())
    return fragment, ok


#: The report's analyses after the formulations, in page order.
SECTIONS: list[DemoSection] = [
    DemoSection("chapter 3 (computed torque, balance)", _simulation, steps=4),
    DemoSection("chapter 3 (AA300 actuator-sizing sweep on Dask)", _sweep),
    DemoSection("chapter 5 (Kinova Gen3 identification and validation)", _kinova, steps=2),
    DemoSection("chapter 6 (calibration study, held-out error within 1.3x the noise)", _calibration),
    DemoSection("chapter 7 (underwater effect series)", _underwater),
]

#: progress steps of run_demo itself: derive 3, evaluate 3, write 5, trolley 1
_OWN_STEPS = 12


def run_demo(output: str | Path, samples: int = 20, seed: int = 0) -> int:
    """Write the demo files into ``output``; returns 0 when every check passed, else 1."""
    out = Path(output)
    out.mkdir(parents=True, exist_ok=True)
    robot = load("puma560")
    ctx = DemoContext(out, robot, demo_backend())
    with steps(_OWN_STEPS + sum(s.steps for s in SECTIONS), "demo"):
        eoms = derive_all(robot)
        results = agreement(eoms, samples, seed)
        by_method = {e.method: e for e in eoms}
        with progress("writing puma560_newton_euler.txt"):
            (out / "puma560_newton_euler.txt").write_text(render_text(by_method["newton_euler"]))
        for eom in eoms:
            with progress(f"writing puma560_{eom.method}.json"):
                (out / f"puma560_{eom.method}.json").write_text(render_json(eom))
        with progress("writing puma560_equations.tex"):
            (out / "puma560_equations.tex").write_text(render_latex(by_method["newton_euler"]))
        with progress("deriving trolley_pendulum (kane) and checking eqs. 2.46-2.47"):
            teom = derive(load("trolley_pendulum"), "kane")
            closed = _trolley_closed_form_ok(teom)
            (out / "trolley_pendulum.tex").write_text(render_latex(teom))
        counts = count_rows(eoms)
        (out / "comparison.csv").write_text(_csv(counts))
        (out / "comparison.md").write_text(_markdown(robot, counts, results, samples))
        built = [(s, *s.build(ctx)) for s in SECTIONS]
    page = render("demo.html.j2", **_page_context(robot, counts, results, samples, teom, closed),
                  sections=[Markup(fragment) for _, fragment, _ in built])
    (out / "report.html").write_text(page, encoding="utf-8")
    print(table(COUNT_HEADERS, counts))
    print()
    print(table(AGREEMENT_HEADERS, agreement_rows(results)))
    print("\ntrolley pendulum (kane) equals the thesis' eqs. 2.46-2.47: " + ("yes" if closed else "NO"))
    print(f"wrote {', '.join(sorted(p.name for p in out.iterdir()))} in {out}")
    print(f"report: {(out / 'report.html').resolve()} (self-contained: figures embedded)")
    for section, _, ok in built:
        print(f"{section.name}: " + ("ok" if ok else "FAILED"))
    every = all(r.ok for r in results) and closed and all(ok for _, _, ok in built)
    return 0 if every else 1


def demo_backend() -> str:
    """"c" when a C compiler is installed; otherwise "numpy", with a printed note."""
    from robodyn.codegen import build

    try:
        build.find_compiler()
    except build.CompilerNotFoundError as exc:
        print(f"note: {' '.join(str(exc).split())}. The demo uses the NumPy backend instead "
              "(same results, slower simulations).")
        return "numpy"
    return "c"


def _trolley_closed_form_ok(eom: EquationsOfMotion) -> bool:
    """tau of the trolley pendulum equals the thesis' eqs. 2.46-2.47 (solved for F and tau)."""
    big_m, m, length, g = (sp.Symbol(k, real=True) for k in ("M", "m", "l", "g"))
    q2 = eom.q[1]
    x_dd, th_dd, th_d = eom.qdd[0], eom.qdd[1], eom.qd[1]
    half = m * length / 2
    closed = [
        # (2.46): F = (M + m) x'' + (m l/2) cos(theta) theta'' - (m l/2) sin(theta) theta'^2
        (big_m + m) * x_dd + half * sp.cos(q2) * th_dd - half * sp.sin(q2) * th_d**2,
        # (2.47): 0 = (m g l/2) sin(theta) - (m l/2) cos(theta) x'' - (m l^2/3) theta'' - tau
        half * sp.cos(q2) * x_dd + m * length**2 / 3 * th_dd - half * g * sp.sin(q2),
    ]
    return all(sp.simplify(eom.tau[k] - closed[k]) == 0 for k in range(2))


_CSV_NOTE = ("tau, M, g: additions (+), multiplications (*) and function calls (fn) after "
             "common-subexpression elimination (tau in its recursive form where there is one)")


def _csv(counts: list[list[object]]) -> str:
    text = io.StringIO()
    writer = csv.writer(text, lineterminator="\n")
    writer.writerow(["method", "derivation_time_s"] + [
        f"{k}_{op}" for k in ("tau", "M", "g") for op in ("additions", "multiplications", "functions")])
    writer.writerows(counts)
    return text.getvalue()


def _markdown(robot: Robot, counts: list[list[object]], results: Sequence[Agreement],
              samples: int) -> str:
    lines = [f"# Efficiency of the formulations: {robot.name}", "",
             f"robodyn {__version__}; description sha256 `{robot.description_hash}`.", "",
             f"Derivation time (s) and {_CSV_NOTE}.", ""]
    lines += [markdown_table(COUNT_HEADERS, counts)]
    lines += ["", f"## Agreement (max relative difference over {samples} random states, "
              f"tolerance {TOLERANCE:g})", ""]
    lines += [markdown_table(AGREEMENT_HEADERS, agreement_rows(results))]
    return "\n".join(lines) + "\n"


def _page_context(robot: Robot, counts: list[list[object]], results: Sequence[Agreement],
                  samples: int, trolley: EquationsOfMotion, closed_ok: bool) -> dict[str, object]:
    """The values of ``demo.html.j2`` before its sections (strings are escaped by the template)."""
    return {
        "title": f"robodyn report: {robot.name}",
        "robot": robot,
        "version": __version__,
        "stamp": datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC"),
        "count_note": _CSV_NOTE,
        "count_table": Markup(html_table(COUNT_HEADERS, counts)),
        "samples": samples,
        "tolerance": f"{TOLERANCE:g}",
        "agree": all(r.ok for r in results),
        "verdict": verdict(results),
        "agreement_table": Markup(html_table(AGREEMENT_HEADERS, agreement_rows(results))),
        "closed_ok": closed_ok,
        "trolley_time": trolley.derivation_time,
        "mathml": Markup(render_mathml(trolley)),
        "text": render_text(trolley),
        "latex": render_latex(trolley),
        "citation": CITATION,
    }
