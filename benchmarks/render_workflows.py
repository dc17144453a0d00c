"""README sections of the workflow benchmarks: calibration, validation (Kinova identification)
and the sizing sweep (issue 22, item 2).

``RENDERERS`` maps each section name to a function of the whole results file (``results.py``)
returning the section's Markdown; ``render_readme.py`` registers them. Standard library only;
nothing here times anything.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))
import render_common as rc  # noqa: E402 - sibling module of a script folder


def _met(ok: bool) -> str:
    return "met" if ok else "not met"


def _s(summary: dict[str, float]) -> str:
    """``"X s (median Y)"`` of a seconds summary."""
    return f"{rc.sig(summary['min'])} s (median {rc.sig(summary['median'])})"


def _calibration_solver(e: dict[str, Any]) -> list[str]:
    """The 200-pose table, the Jacobian comparison and the 1000-pose paragraph."""
    m, j, c = e["models"], e["jacobian"], e["combined"]
    rows = [[r["model"], str(r["parameters"]), str(r["evaluations"]), f"{r['after_rms_mm']:.4f}",
             *rc.mm(r["seconds"]), f"< {m['target_s']:g} s: {_met(r['seconds']['min'] < m['target_s'])}"]
            for r in m["rows"]]
    lines = [""] + rc.table(["error model", "parameters", "evaluations", "RMS after, mm",
                             "min s", "median s", "target"], rows)
    js, ev = j["seconds"], j["evaluations"]
    lines += [""] + rc.wrap(
        f"The same Levenberg-Marquardt problem ({j['model']}, its {j['parameters']} identifiable "
        "parameters, the same start, weights and tolerances) in SciPy's "
        "`least_squares(method=\"lm\")`, the analytic Jacobian against 2-point finite "
        f"differences, in the same solver and the same rounds: {_s(js['analytic'])} in "
        f"{ev['analytic']} evaluations against {_s(js['2-point'])} in {ev['2-point']}: finite "
        f"differences cost {rc.x(j['ratio_fd_vs_analytic'])} the analytic Jacobian; the two "
        f"solutions agree to {j['max_parameter_difference']:.1e}. The finite-difference step "
        f"alone takes {rc.x(j['ratio_fd_vs_calibrate'], 2)} the whole `rd.calibrate` "
        f"({_s(js['calibrate'])}: placement, identifiability, solve, covariance, calibrated "
        "Robot).")
    cs = c["seconds"]
    lines += [""] + rc.wrap(
        f"{c['poses']} poses x {c['targets']} targets, the truth with joint compliance and "
        f"transmission errors, S-model + {' + '.join(c['terms'])} ({c['parameters']} parameters, "
        f"{c['evaluations']} evaluations, RMS after {c['after_rms_mm']:.4f} mm), "
        f"{c['repeats']} rounds: end to end {_s(cs['calibrate'])} (target under "
        f"{c['target_s']:g} s: {_met(cs['calibrate']['min'] < c['target_s'])}); its "
        f"least-squares step {_s(cs['analytic'])} with the analytic Jacobian against "
        f"{_s(cs['2-point'])} with 2-point finite differences "
        f"({rc.x(c['ratio_fd_vs_analytic'])}).")
    return lines


#: Rows of the CLI table: key in the entry's ``seconds``, label, what it is.
CLI_ROWS = (
    ("command", "whole command", "with the HTML report (matplotlib's import and figure); the "
     "console command's exit, which skips the interpreter's teardown once its files are written"),
    ("command --no-report", "whole command, `--no-report`", "the same without the HTML report"),
    ("before the solve", "before the solve", "a probe process: interpreter start, the CLI's "
     "import and parser, the robot's numbers (from robodyn's cache: no SymPy), the calibration "
     "modules, the CSV (`robodyn.cli.workflows.calibration_inputs`), then `import "
     "scipy.optimize` (the solver's import, which the command makes inside the solve), and the "
     "command's exit"),
    ("command: solve", "the solve", "the command's own progress line (0.1 s steps): "
     "`rd.calibrate`, with the optimizer's import and first calls, and SymPy's import with the "
     "description's full load for the calibrated descriptions it builds after the fit"),
    ("command: terms", "the terms' cross-validation", "the command's own progress line: "
     "5-fold cross-validation over poses of geometry, + compliance, + harmonics"),
    ("import scipy.optimize after numpy", "`import scipy.optimize`", "in a fresh process once "
     "NumPy is loaded, timed inside it"),
    ("import sympy after numpy", "`import sympy`", "the same for SymPy (which the command no "
     "longer imports before the solve)"),
    ("import numpy process", '`python -c "import numpy"`', "the issue's pairing: "
     "interpreter start + NumPy, whole process"),
    ("numpy + scipy.optimize", "the dependencies' bare imports", "NumPy and `scipy.optimize` "
     "(what the command needs by then) in a fresh process, whole process, exit without teardown"),
    ("robodyn --help", "`robodyn --help`", "whole process"),
    ("empty interpreter", '`python -c "pass"`', "the interpreter's start and exit alone"),
)


def _calibration_cli(e: dict[str, Any]) -> list[str]:
    """The ``robodyn calibrate`` start-up table and its sentence."""
    c = e["cli"]
    s = c["seconds"]
    lines = [""] + rc.wrap(
        f"`robodyn calibrate` on that data (`{c['command_line']}`) in fresh processes, "
        f"{c['rounds']} rounds in which the rows take turns, the robot's compiled model cached "
        "and Python's bytecode cache on; seconds:")
    rows = [[label, *rc.mm(s[key]), what] for key, label, what in CLI_ROWS]
    after = c["after_solve_s"]
    rows += [["after the solve", *rc.mm(after["command"]), "per round: the whole command less "
              "before the solve, the solve and the terms' cross-validation, plus the optimizer's "
              "import (counted in both): the files written, the report, the exit; to within the "
              "progress lines' 0.1 s steps"],
             ["after the solve, `--no-report`", *rc.mm(after["command --no-report"]),
              "the same, without the report"]]
    lines += [""] + rc.table(["step", "min", "median", "what it is"], rows)
    before, target, earlier = s["before the solve"]["min"], c["target_before_s"], \
        c["earlier_target_before_s"]
    sympy = (f"SymPy's import {rc.sig(s['import sympy after numpy']['min'])} s (SymPy is loaded "
             "before the solve)" if c["sympy_loaded_before_solve"] else
             "no SymPy (not loaded before the solve)")
    lines += [""] + rc.wrap(
        f"Before the solve {rc.sig(before)} s (median "
        f"{rc.sig(s['before the solve']['median'])}; issue 22's target at most {target:g} s: "
        f"{_met(before <= target)}; the earlier target of {earlier:g} s: "
        f"{_met(before <= earlier)}), of which SciPy's optimizer import "
        f"{rc.sig(s['import scipy.optimize after numpy']['min'])} s and {sympy}, against "
        f"`python -c \"import numpy\"` {rc.sig(s['import numpy process']['min'])} s in the "
        f"same rounds ({rc.x(c['before_vs_import_numpy'], 2)}). Above the dependencies' bare "
        f"imports ({rc.sig(s['numpy + scipy.optimize']['min'])} s) robodyn's own share "
        f"is {c['before_minus_floor_s']['min']:.2f} s ({rc.x(c['before_vs_floor'], 2)} the "
        "floor). Minima judged against the targets.")
    return lines


def render_calibration(data: dict[str, Any]) -> str:
    """Markdown of the ``calibration`` entry: error models, Jacobians, 1000 poses, the CLI."""
    e = data["benchmarks"]["calibration"]
    m = e["models"]
    lines = rc.wrap(rc.run(data, e, (
        f"Kinematic calibration of a PUMA 560 whose true kinematics carry millimetre-level "
        f"errors, measured by a tracker with {m['noise_mm']:g} mm noise per coordinate, "
        f"`rd.calibrate` end to end from {m['poses']} poses per error model (placement, "
        "identifiability, Levenberg-Marquardt with the analytic Jacobian, covariance, "
        f"calibrated Robot), seconds, min / median of {m['repeats']} rounds in which the "
        "compared rows take turns")) + " Targets are judged on the minima.")
    lines += _calibration_solver(e)
    lines += _calibration_cli(e)
    return "\n".join(lines) + "\n"


def _joints(row: dict[str, Any]) -> str:
    return f"all {len(row['joints'])}" if len(row["joints"]) > 1 else row["joints"][0]


def _held_out_table(e: dict[str, Any]) -> list[str]:
    """One row per case and recording, a raw / filtered column per method."""
    methods = list(e["seconds"])
    cells: dict[tuple[str, str], dict[str, Any]] = {}
    for r in e["held_out"]:
        key = (r["case"], r["recording"])
        cell = cells.setdefault(key, {"row": r})
        cell[r["method"]] = f"{r['raw']:.3f} / {r['filtered']:.3f}"
    rows = [[case, rec, _joints(c["row"]), *(c.get(m, "") for m in methods),
             f"{c['row']['noise_floor']:.3f}", str(c["row"]["samples"])]
            for (case, rec), c in cells.items()]
    return rc.table(["case", "recording", "joints", *(f"{m} raw / filtered" for m in methods),
                     "noise floor", "samples"], rows, text_last=False)


def render_validation(data: dict[str, Any]) -> str:
    """Markdown of the ``validation`` entry: identification times, held-out and cross-run tables."""
    e = data["benchmarks"]["validation"]
    lines = rc.wrap(rc.run(data, e, (
        f"Whole identification of the Kinova Gen3 from its three whole-arm runs ({', '.join(e['runs'])}; "
        f"real recordings, {e['target']} target): `rd.identify` on the first 70 % of each "
        f"({e['train_samples']} samples), friction {e['friction']}, every other option at its "
        "default, the compiled model passed in (compiled once, not timed), per method; "
        f"seconds, min / median of {e['repeats']} rounds in which the "
        "methods take turns")))
    rows = [[m, *rc.mm(s), rc.x(e["vs_ols"][m], 2) if e["vs_ols"] else "",
             rc.sig(e["first_call_s"][m])] for m, s in e["seconds"].items()]
    lines += [""] + rc.table(["method", "min s", "median s", "time / OLS (min / median)",
                              "first call in the process, s (one run, before the rounds)"], rows,
                             text_last=False)
    b = e["baseline"]
    pooled = [r for r in e["held_out"] if r["recording"] == "all three pooled"]
    verdicts = "; ".join(
        f"{r['method']} {r['raw']:.3f} / {r['filtered']:.3f} "
        f"({'below both' if r['raw'] < b['raw'] and r['filtered'] < b['filtered'] else 'not below both'})"
        for r in pooled)
    lines += [""] + rc.wrap(
        "Held-out relative current error ||e|| / ||y|| of each method's identification, raw and "
        f"against the reference-filtered current (zero-phase Butterworth, order 4 per pass, "
        f"{e['reference_filter_hz']:g} Hz), the noise floor ||y - y_f|| / ||y|| beside it: the last "
        "30 % of each whole-arm run (all joints) and of the three pooled, and the seven jointwise "
        "runs, never used in fitting, scored on their moving joint. Pooled last 30 % against the "
        f"data README's baseline of {b['raw']:g} raw and {b['filtered']:g} filtered "
        f"(`{b['source']}`, noise floor {b['noise_floor']}): {verdicts}.")
    lines += [""] + _held_out_table(e)
    if e["cross_run"]:
        method = e["cross_run"][0]["method"]
        rows = [["+".join(r["fit_on"]), r["recording"], f"{r['raw']:.3f}", f"{r['filtered']:.3f}",
                 f"{r['noise_floor']:.3f}", str(r["samples"])] for r in e["cross_run"]]
        lines += [""] + rc.wrap(
            f"Across runs (the {method} method, robodyn's default, friction {e['friction']}): "
            "identified on whole runs, predicting a different whole run.")
        lines += [""] + rc.table(["fit on", "predicted", "raw", "filtered", "noise floor",
                                  "samples"], rows, text_last=False)
    return "\n".join(lines) + "\n"


def _sweep_size(s: dict[str, Any]) -> list[str]:
    """Table and sentence of one size."""
    rows = [[k, *rc.mm(v), f"{s['cases'] / v['min']:.0f}", rc.x(s["speed_up_vs_serial"][k], 2)]
            for k, v in s["seconds"].items()]
    oh, ms = s["overhead_percent"], s["overhead_ms_per_case"]
    lines = [""] + rc.wrap(f"{s['cases']:,} cases, batches of {s['batch']} ({s['tasks']} tasks), "
                           f"{s['rounds']} rounds; seconds:")
    lines += [""] + rc.table(["runner", "min s", "median s", "cases/s (min)",
                              "speed-up over the serial loop (min / median)"], rows,
                             text_last=False)
    lines += [""] + rc.wrap(
        f"Dask's per-case overhead with one worker against the serial loop: {ms['min']:+.2f} ms "
        f"= {oh['min']:+.1f} % of a case's compute time ({rc.sig(s['ms_per_case_serial']['min'])} "
        f"ms; medians {oh['median']:+.1f} %; target under {s['target_overhead_percent']:g} %: "
        f"{_met(oh['min'] < s['target_overhead_percent'])}); two Dask workers "
        f"{rc.x(s['scaling_2_vs_1'], 2)} the throughput of one; Dask with two workers "
        f"{rc.x(s['dask2_vs_pool'], 2)} the throughput of `ProcessPoolExecutor` with two "
        "processes.")
    return lines


def render_sweep(data: dict[str, Any]) -> str:
    """Markdown of the ``sweep`` entry: each size run, the quoted 20,000-case figure if not run."""
    e = data["benchmarks"]["sweep"]
    lines = rc.wrap(rc.run(data, e, (
        f"The actuator-sizing sweep ({e['task']}): a serial loop, `ProcessPoolExecutor` "
        "and Dask with 1 and 2 workers on the same cases and batches, min / median over rounds "
        "in which the runners take turns, pool and clusters started and warmed up before the "
        "first round")))
    for s in e["sizes"]:
        lines += _sweep_size(s)
    if "quoted" in e:
        q = e["quoted"]
        lines += [""] + rc.wrap(
            f"{q['cases']:,} cases (the issue's size) were not run in this run (`{q['run_with']}` "
            f"adds them: about {q['expected_minutes']:.0f} minutes at this run's rates): an earlier "
            f"run gave two Dask workers {q['scaling_2_vs_1']:g}x the throughput of one "
            f"({q['source']}; not measured in this run).")
    lines += ["", "What each runner is and differs in:", ""]
    for k, v in e["peers"].items():
        lines += rc.wrap(f"{k}: {v}.", bullet=True)
    return "\n".join(lines) + "\n"


RENDERERS: dict[str, Callable[[dict[str, Any]], str]] = {
    "calibration": render_calibration, "validation": render_validation, "sweep": render_sweep}
