"""``make demo``: the PUMA 560 three ways, generated code, simulations, and an HTML report."""

from __future__ import annotations

import csv
import html
import io
from collections.abc import Sequence
from datetime import UTC, datetime
from pathlib import Path

import sympy as sp

import robodyn as rd
from robodyn.report.agreement import (
    AGREEMENT_HEADERS,
    COUNT_HEADERS,
    TOLERANCE,
    Agreement,
    agreement,
    agreement_rows,
    count_rows,
    derive_all,
)
from robodyn.report.html import CSS as _CSS
from robodyn.report.html import html_table
from robodyn.report.simulation_sections import simulation_sections
from robodyn.report.text import progress, table
from robodyn.symbolic.render import render_json, render_latex, render_mathml, render_text


def run_demo(output: str | Path, samples: int = 20, seed: int = 0) -> int:
    """Write the demo files into ``output``; returns 0 when every check passed, else 1."""
    out = Path(output)
    out.mkdir(parents=True, exist_ok=True)
    robot = rd.load("puma560")
    backend = demo_backend()
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
    trolley = rd.load("trolley_pendulum")
    with progress("deriving trolley_pendulum (kane) and checking eqs. 2.46-2.47"):
        teom = rd.derive(trolley, "kane")
        closed = _trolley_closed_form_ok(teom)
        (out / "trolley_pendulum.tex").write_text(render_latex(teom))
    counts = count_rows(eoms)
    csv_text = io.StringIO()
    writer = csv.writer(csv_text, lineterminator="\n")
    writer.writerow(["method", "derivation_time_s"] + [
        f"{k}_{op}" for k in ("tau", "M", "g")
        for op in ("additions", "multiplications", "functions")])
    writer.writerows(counts)
    (out / "comparison.csv").write_text(csv_text.getvalue())
    (out / "comparison.md").write_text(_markdown(robot, counts, results, samples))
    sections, sim_ok = simulation_sections(robot, out, backend)
    cal_section, cal_ok = _calibration_section(out)
    sections += "\n" + cal_section
    from robodyn.report.identification_report import kinova_section

    kinova_html, kinova_ok = kinova_section(out)
    sections += "\n" + kinova_html
    page = _html_page(robot, counts, results, samples, teom, closed,
                      render_mathml(teom), render_latex(teom), render_text(teom))
    page = page.replace("</body></html>", sections + "\n</body></html>")
    (out / "report.html").write_text(page, encoding="utf-8")
    print(table(COUNT_HEADERS, counts))
    print()
    print(table(AGREEMENT_HEADERS, agreement_rows(results)))
    print("\ntrolley pendulum (kane) equals the seed's eqs. 2.46-2.47: "
          + ("yes" if closed else "NO"))
    print(f"wrote {', '.join(sorted(p.name for p in out.iterdir()))} in {out}")
    print(f"report: {(out / 'report.html').resolve()}")
    print("chapter 3 (computed torque, balance): " + ("ok" if sim_ok else "FAILED"))
    print("chapter 4 (calibration study, held-out error within 1.3x the noise): "
          + ("ok" if cal_ok else "FAILED"))
    return 0 if all(r.ok for r in results) and closed and sim_ok and cal_ok and kinova_ok else 1


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


def _calibration_section(out: Path) -> tuple[str, bool]:
    """Run the PUMA 560 calibration study into ``out/calibration``; (HTML section, all ok)."""
    from robodyn.calibrate.simulate_study import puma_study
    from robodyn.report.calibration_report import study_section

    with progress("PUMA 560 calibration study (DH, Hayati, S-model, POE; 2 tracker noises)"):
        study = puma_study(out / "calibration")
    (out / "calibration" / "study.txt").write_text(study.table() + "\n\n"
                                                   + "\n".join(study.notes) + "\n")
    # every model but standard DH from the nominal start must explain all but the noise
    ok = all(c.test_after.rms < 1.3 * c.sigma * 3**0.5 for c in study.cases
             if (c.model, c.initial) != ("dh", "nominal"))
    return study_section(study, "calibration"), ok


def _trolley_closed_form_ok(eom: rd.EquationsOfMotion) -> bool:
    """tau of the trolley pendulum equals the seed's eqs. 2.46-2.47 (solved for F and tau)."""
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


def _markdown(robot: rd.Robot, counts: list[list[object]], results: Sequence[Agreement],
              samples: int) -> str:
    def mdtable(headers: Sequence[str], rows: Sequence[Sequence[object]]) -> list[str]:
        out = ["| " + " | ".join(headers) + " |", "|" + "---|" * len(headers)]
        return out + ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]

    lines = [f"# Efficiency of the formulations: {robot.name}", "",
             f"robodyn {rd.__version__}; description sha256 `{robot.description_hash}`.", "",
             f"Derivation time (s) and {_CSV_NOTE}.", ""]
    lines += mdtable(COUNT_HEADERS, counts)
    lines += ["", f"## Agreement (max relative difference over {samples} random states, "
              f"tolerance {TOLERANCE:g})", ""]
    lines += mdtable(AGREEMENT_HEADERS, agreement_rows(results))
    return "\n".join(lines) + "\n"


def _html_page(robot: rd.Robot, counts: list[list[object]], results: Sequence[Agreement],
               samples: int, trolley: rd.EquationsOfMotion, closed_ok: bool, mathml: str,
               latex: str, text: str) -> str:
    ok = all(r.ok for r in results)
    verdict = ('<span class="ok">the three formulations agree</span>' if ok
               else '<span class="bad">the formulations disagree</span>')
    closed = ('<span class="ok">yes</span>' if closed_ok else '<span class="bad">no</span>')
    stamp = datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC")
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<title>robodyn report: {html.escape(robot.name)}</title>
<style>{_CSS}</style></head>
<body>
<h1>robodyn: equations of motion of the {html.escape(robot.name)}, three ways</h1>
<p class="meta">robodyn {html.escape(rd.__version__)}, {stamp}. Source
<code>{html.escape(robot.source)}</code>, description sha256
<code>{robot.description_hash}</code>.</p>

<h2>Efficiency of the formulations</h2>
<p>Derivation time in seconds, and {html.escape(_CSV_NOTE)}.</p>
{html_table(COUNT_HEADERS, counts)}

<h2>Agreement</h2>
<p>Largest relative difference of M(q), g(q) and the full inverse dynamics tau between each pair
of formulations over {samples} random states (q in [&minus;&pi;, &pi;], qd in [&minus;2, 2],
qdd in [&minus;3, 3]); tolerance {TOLERANCE:g}. Result: {verdict}.</p>
{html_table(AGREEMENT_HEADERS, agreement_rows(results))}

<h2>Trolley pendulum (the seed's worked example), Kane's method</h2>
<p>q<sub>1</sub> = x (trolley position, prismatic), q<sub>2</sub> = &theta; (rod angle from the
upward vertical). tau<sub>1</sub> is the driving force F of eq. 2.46, tau<sub>2</sub> the
torque that eq. 2.47 sets to zero. Equal to eqs. 2.46&ndash;2.47 after simplification: {closed}.
Derived in {trolley.derivation_time:.3f} s.</p>
{mathml}
<details><summary>Plain text (<code>robodyn derive trolley_pendulum --method kane</code>)
</summary><pre>{html.escape(text)}</pre></details>
<details><summary>LaTeX source (<code>trolley_pendulum.tex</code>)</summary>
<pre>{html.escape(latex)}</pre></details>
</body></html>
"""
