"""Render the README's benchmark figures from a results file (issue 22, item 2).

The README holds marked sections::

    <!-- results:kernels benchmarks/results/<machine>.json -->
    ... generated text ...
    <!-- /results:kernels -->

Each names a benchmark and the results file (``results.py``) it is rendered from. This script
rewrites the text between the markers from that file; ``--results PATH`` points the markers
at another file first (e.g. the one ``make bench`` just wrote on this machine); ``--check``
changes nothing and exits 1 if the README differs from its rendering (what
``tests/test_readme_results.py`` asserts).

The same is done for the documents in :data:`DOCUMENTS` (``docs/identification.md``'s quality
table).

Run: ``.venv/bin/python benchmarks/render_readme.py [--results PATH] [--check] [--readme FILE]``.
Standard library only; nothing here times anything.
"""

from __future__ import annotations

import argparse
import importlib
import json
import re
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))
import render_common as rc  # noqa: E402 - sibling module of a script folder

ROOT = Path(__file__).resolve().parent.parent
README = ROOT / "README.md"
#: Other documents with marked sections, rendered and checked with the README.
DOCUMENTS = (ROOT / "docs" / "identification.md",)
MARKER = re.compile(r"<!-- results:(?P<name>[\w-]+) (?P<path>\S+) -->\n(?P<body>.*?)"
                    r"<!-- /results:(?P=name) -->", re.S)
LIBRARIES = {"robodyn": "robodyn, no friction", "robodyn (friction)": "robodyn, PUMA friction",
             "pinocchio native": "Pinocchio native", "pinocchio wheel": "Pinocchio wheel"}


def _ratio_cell(ratios: list[dict[str, Any]], kernel: str, library: str) -> tuple[str, str]:
    """Speed-up and target cells of one table row."""
    for r in ratios:
        if r["kernel"] != kernel:
            continue
        if library == r["peer"] and r["robodyn"] == "robodyn":
            target = (f">= {r['target']:g}x: {'met' if r['met'] else 'not met'}"
                      if "target" in r else "")
            return f"{r['min']:.1f}x / {r['median']:.1f}x", target
        if library == r["robodyn"] != "robodyn":
            return f"{r['min']:.1f}x / {r['median']:.1f}x over native", ""
    return "", ""


def render_kernels(data: dict[str, Any]) -> str:
    """Markdown of the ``kernels`` entry: a sentence on the run, a table, what each row differs in.

    Parameters
    ----------
    data : dict
        The whole results file (machine record and benchmarks).

    Returns
    -------
    str
        Lines ending in a newline.
    """
    m, e = data["machine"], data["benchmarks"]["kernels"]
    simd = "AVX-512F" if "avx512f" in m.get("simd", []) else "/".join(m.get("simd", [])).upper()
    lines = rc.wrap(
        f"PUMA 560 kernels against Pinocchio (`{e['command']}`, {e['states']:,} random states, one "
        f"thread, ns per state, min / median of {e['repeats']} rounds in which the libraries take "
        f"turns; {m['cpu_model']}, "
        f"{m['logical_cpus']} logical CPUs, {simd or 'no AVX'}; load average "
        f"{' '.join(map(str, e['load_average_at_start']))} at the start and "
        f"{' '.join(map(str, e['load_average_at_end']))} at the end; {e['date']}). "
        "Speed-up = the row's time / robodyn's without friction; the issue's targets apply to "
        "the native build and are judged on the minima.")
    lines += [
        "",
        "| kernel | library | min | median | robodyn's speed-up (min / median) | target "
        "| max rel. error vs robodyn |",
        "|---|---|---:|---:|---:|---|---:|",
    ]
    for row in e["rows"]:
        speed, target = _ratio_cell(e["ratios"], row["kernel"], row["library"])
        err = row["max_rel_error"]
        err_text = "reference" if row["library"] == "robodyn" else (
            "(has friction)" if err is None else f"{err:.1e}")
        ns = row["ns_per_state"]
        lines.append(f"| {row['kernel']} | {LIBRARIES.get(row['library'], row['library'])} | "
                     f"{rc.fmt(ns['min'])} | {rc.fmt(ns['median'])} | {speed} | {target} | {err_text} |")
    if e.get("skipped"):
        lines += ["", e["skipped"]]
    bullets = [f"{LIBRARIES.get(k, k)}: {v}." for k, v in e["peers"].items()]
    notes: dict[str, list[str]] = {r["library"]: [] for r in e["rows"]}
    for r in e["rows"]:
        if r["note"]:
            notes[r["library"]].append(f"{r['kernel']}: {r['note']}")
    bullets += [f"{LIBRARIES.get(lib, lib)} calls: {'; '.join(t)}." for lib, t in notes.items() if t]
    if e.get("native"):
        n = e["native"]
        bullets.append(f"Pinocchio native built by {n['compiler']} with `{' '.join(n['flags'])}` "
                       f"against the {n['headers']}, {n['linked']}.")
    bullets.append("The wheel's derivative loop without the Python loop's own cost: "
                   f"{rc.fmt(e['wheel']['derivatives_minus_loop_ns']['min'])} ns per state (min).")
    lines += ["", "What each row is and differs in:", ""]
    for b in bullets:
        lines += rc.wrap(b, bullet=True)
    return "\n".join(lines) + "\n"


def render_casadi(data: dict[str, Any]) -> str:
    """Markdown of the ``casadi`` entry (and of ``threads`` when the file has it)."""
    e = data["benchmarks"]["casadi"]
    lines = rc.wrap(rc.run(data, e, (
        f"PUMA 560 inverse dynamics against CasADi {e['casadi_version']}-generated C of the same "
        f"program, {e['states']:,} random states, ns per state, min / median of {e['repeats']} "
        "rounds in which the rows take turns")) + (
        " Both sides evaluate robodyn's recorded Newton-Euler program of the PUMA as described "
        f"(viscous and Coulomb friction; CasADi counts {e['instructions']['one state']} SX "
        f"instructions per state), CasADi's C compiled with robodyn's flags "
        f"`{' '.join(e['flags'])}`. Speed-up = the row's time / robodyn's on as many threads."))
    ratio = {r["peer"]: r for r in e["ratios"]}
    rows = []
    for r in e["rows"]:
        err = r["max_rel_error"]
        speed = rc.x(ratio[r["library"]]) if r["library"] in ratio else ""
        rows.append([r["library"], str(r["threads"]), *rc.mm(r["ns_per_state"]), speed,
                     "reference" if err is None else f"{err:.1e}", r["note"]])
    lines += [""] + rc.table(["evaluation", "threads", "min", "median",
                            "robodyn's speed-up (min / median)", "max rel. error", "what differs"],
                           rows)
    if "threads" in data["benchmarks"]:
        lines += [""] + rc.wrap(_threads_text(data))
    return "\n".join(lines) + "\n"


def _threads_text(data: dict[str, Any]) -> str:
    """The sentence on two-thread efficiencies and the mass matrix against ``crba``."""
    t = data["benchmarks"]["threads"]
    ns, eff, m = t["ns_per_state"], t["efficiency"], t["mass_matrix_vs_crba"]
    effs = "; ".join(f"{k} {v:.2f}" for k, v in eff.items())
    return (rc.run(data, t, f"Two threads and the mass matrix, {t['states']:,} states, min of "
                          f"{t['repeats']} rounds") +
            f" Two-thread efficiency t1 / (2 t2): {effs} (robodyn: {t['peers']['robodyn']}; "
            f"Pinocchio: {t['peers']['pinocchio wheel']}; the logical CPUs may be shared with "
            f"other jobs, which the two-thread figures feel first). Mass matrix: robodyn "
            f"{rc.fmt(ns['robodyn M 1']['min'])} ns per state against `crba` from a Python loop "
            f"{rc.fmt(ns['crba loop']['min'])} ns ({m['with_loop']:.1f}x), of which the loop "
            f"itself {rc.fmt(ns['python loop']['min'])} ns ({m['minus_loop']:.1f}x without it).")


def render_ensemble(data: dict[str, Any]) -> str:
    """Markdown of the ``ensemble`` entry."""
    e = data["benchmarks"]["ensemble"]
    lines = rc.wrap(rc.run(data, e, (
        f"Ensemble RK4: {e['trajectories']:,} trolley double-pendulum trajectories of "
        f"{e['steps'] * e['dt']:g} s at {e['dt'] * 1e3:g} ms, ms per trajectory, min / median of "
        f"{e['repeats']} rounds in which the rows take turns")) + (
        " Ratio = the row's time / robodyn's ensemble on as many threads; MuJoCo and robodyn "
        f"agree to {e['mujoco_agreement_rad']:.1e} rad over all trajectories and steps."))
    rows = [[r["library"], str(r["threads"]), *rc.mm(r["ms_per_trajectory"]),
             rc.x(r["vs_ensemble"], 2)] for r in e["rows"]]
    lines += [""] + rc.table(["run", "threads", "min", "median", "ratio (min / median)"], rows,
                           text_last=False)
    lines += ["", "What each row is and differs in:", ""]
    for k, v in e["peers"].items():
        lines += rc.wrap(f"{k}: {v}.", bullet=True)
    return "\n".join(lines) + "\n"


def _sweeps_text(sweeps: dict[str, dict[str, Any]]) -> str:
    """One sentence per SciPy sweep: rtol, error and time of each trial (one run each)."""
    parts = []
    for label, s in sweeps.items():
        trials = ", ".join(f"{t['rtol']:.0e}: {t['max_error']:.1e} in {rc.fmt(t['ms'])} ms"
                           for t in s["trials"])
        parts.append(f"{label} (rtol: max error in one run) {trials}")
        if s["matched"] is None:
            parts[-1] += " (none within the target: the most accurate is timed)"
    return "SciPy's sweeps, loose to tight until the error is within the target: " + \
        "; ".join(parts) + "."


def _route_table(rows: list[dict[str, Any]], key: str, targets: dict[str, float],
                 digits: int = 2) -> list[str]:
    """Table of a simulation entry: times, error, ratio, target (if any), what differs."""
    header = ["route", "min ms", "median ms", "max error", "ratio (min / median)",
              *(["target"] if targets else []), "what differs"]
    out = []
    for r in rows:
        cells = [r["label"], f"{r['ms']['min']:.{digits}f}", f"{r['ms']['median']:.{digits}f}",
                 f"{r['max_error']:.1e}", rc.x(r[key])]
        if targets:
            goal = targets.get(r["label"])
            met = goal is not None and r[key]["min"] >= goal
            cells.append("" if goal is None else f">= {goal:g}x: {'met' if met else 'not met'}")
        out.append([*cells, r["settings"]])
    return rc.table(header, out)


def render_simulation(data: dict[str, Any]) -> str:
    """Markdown of the ``simulation`` entry: trolley, PUMA kernels, generation time."""
    e = data["benchmarks"]["simulation"]
    t = e["trolley"]
    lines = rc.wrap(rc.run(data, e, (
        f"The thesis' trolley double pendulum, {t['steps'] * t['dt']:g} s of motion, ms per run, "
        f"min / median of {t['repeats']} rounds in which the rows take turns")) + (
        f" Max error: over the whole state and every 1 ms against {t['reference']} (which "
        f"differs from RK4 at 0.05 ms by {t['reference_vs_rk4_dt_over_20']:.1e}); the motion "
        f"is chaotic, so errors grow with time. Each SciPy route runs at the loosest tolerance "
        f"whose error is within {t['match_factor']:g}x robodyn's ({t['robodyn_error']:.1e}). "
        "Ratio = the row's time / `rd.rollout`'s; targets judged on the minima."))
    lines += [""] + _route_table(t["rows"], "vs_rollout", t["targets"], 3)
    lines += [""] + rc.wrap(_sweeps_text(t["sweeps"]))
    p = e["puma"]
    lines += [""] + rc.wrap(
        f"PUMA 560 kernels against Pinocchio's wheel called from Python ({p['states']:,} states, "
        f"ns per state, minima of {p['repeats']} rounds; ratios of minima; the Python loop "
        f"alone costs {rc.fmt(p['python_loop_ns']['min'])} ns per call). {p['settings']}.")
    th = p["threads"]
    rows = []
    for r in p["rows"]:
        cells = [r["kernel"], rc.fmt(r["robodyn"]["min"]), rc.fmt(r["pinocchio_loop"]["min"]),
                 f"{r['loop_ratio']['min']:.1f}x", f"{r['minus_loop_ratio']['min']:.1f}x"]
        for key in ("one_thread", "all_threads"):
            cells += ([rc.fmt(r[key]["min"]), f"{r[key + '_ratio']['min']:.1f}x"] if key in r
                      else ["", ""])
        rows.append(cells)
    lines += [""] + rc.table(["kernel", "robodyn", "Pinocchio loop", "ratio", "minus the loop",
                            "*InParallel 1 thread", "ratio", f"{th} threads", "ratio"], rows,
                           text_last=False)
    c = e["compile"]
    lines += [""] + rc.wrap(
        f"Generating and compiling the PUMA 560 model in a fresh process with an empty cache "
        f"(one run): {c['first_s']:.2f} s; from the cache: {c['cached_s']:.2f} s.")
    return "\n".join(lines) + "\n"


def render_hydro(data: dict[str, Any]) -> str:
    """Markdown of the ``hydro`` entry: wet/dry cost, drag against strip sums, simulation."""
    e = data["benchmarks"]["hydro"]
    lines = rc.wrap(rc.run(data, e, "The underwater two-link arm `underwater_2r`"))
    if "wet_dry" in e:
        w = e["wet_dry"]
        ns, r = w["ns_per_state"], w["ratio"]
        lines += [""] + rc.wrap(
            f"Compiled inverse dynamics with every hydrodynamic term against the same arm dry "
            f"({w['states']:,} states, min / median of {w['repeats']} rounds): "
            f"{rc.fmt(ns['ID wet']['min'])} against {rc.fmt(ns['ID dry']['min'])} ns per state, "
            f"{rc.x(r['ID'], 2)} the cost (target at most {w['target']:g}x: "
            f"{'met' if r['ID']['min'] <= w['target'] else 'not met'}); forward dynamics "
            f"{rc.x(r['FD'], 2)}.")
    if "drag" in e:
        d = e["drag"]
        lines += [""] + rc.wrap(
            f"Drag with a {d['current_m_s']:g} m/s current, {d['states']:,} states, min / median "
            f"of {d['repeats']} rounds: {d['settings']}.")
        rows = [[r["label"], *rc.mm(r["ns_per_state"]), f"{r['max_error']:.1e}", rc.x(r["vs_robodyn"])]
                for r in d["rows"]]
        lines += [""] + rc.table(["drag by", "min ns", "median ns", "max error", "time / robodyn"],
                               rows, text_last=False)
    s = e["simulation"]
    lines += [""] + rc.wrap(
        f"{s['steps'] * s['dt']:g} s released from rest, every effect on, min / median of "
        f"{s['repeats']} rounds in which the rows take turns; max error over the whole state "
        f"against {s['reference']} (which differs from SciPy DOP853 at rtol 1e-12 by "
        f"{s['reference_vs_dop853_1e-12']:.1e}); each SciPy route at the loosest tolerance "
        f"whose error is within 2x robodyn's ({s['robodyn_error']:.1e}). Ratio = the row's "
        "time / `rd.simulate`'s.")
    lines += [""] + _route_table(s["rows"], "vs_simulate", {})
    lines += [""] + rc.wrap(_sweeps_text(s["sweeps"]))
    return "\n".join(lines) + "\n"


def render_roofline(data: dict[str, Any]) -> str:
    """Markdown of the ``roofline`` entry: peak, bandwidth, inverse dynamics against its floors."""
    e = data["benchmarks"]["roofline"]
    p, b, i, r = e["peak"], e["triad"], e["inverse_dynamics"], e["roofline"]
    met = "met" if r["times_compute_floor"] <= r["target_times_floor"] else "not met"
    text = (
        f"{rc.run(data, e, 'The roofline of one core')} Peak FP64 rate measured by "
        f"{p['chains']} fused multiply-add chains on {p['vector_doubles']}-double vectors with "
        f"robodyn's compiler flags: {rc.sig(p['gflops'])} GFLOP/s (median {rc.sig(p['median_gflops'])}); "
        f"STREAM triad over 3 x {b['array_mib']} MiB: {rc.sig(b['gbs'])} GB/s (median "
        f"{rc.sig(b['median_gbs'])}). PUMA 560 inverse dynamics with its friction, "
        f"{i['states']:,} states on one thread, into a reused array: "
        f"{rc.sig(i['ns_per_state']['min'])} ns per state, the least disturbed of "
        f"{p['repeats']} rounds (median {rc.sig(i['ns_per_state']['median'])}: "
        f"{i['ns_per_state']['median'] / r['compute_floor_ns']:.1f}x the floor) for "
        f"{r['flops_per_state']} flops: the "
        f"generated program's {i['multiplications']} multiplications and {i['additions']} "
        f"additions, and {i['sincos_flops_per_angle']} for the sine and cosine of each of its "
        f"{i['sincos_angles']} angles; {rc.sig(r['achieved_gflops'])} GFLOP/s = "
        f"{100 * r['fraction_of_peak']:.0f} % of the peak: {r['times_compute_floor']:.2f}x the "
        f"floor of {rc.sig(r['compute_floor_ns'])} ns that its op count sets at the peak rate "
        f"(target at most {r['target_times_floor']:g}x: {met}). A streaming batch moves "
        f"{i['bytes_per_state']} bytes per state, {rc.sig(r['memory_floor_ns'])} ns at the triad "
        f"rate: by its two floors the kernel is "
        f"{'compute' if r['compute_floor_ns'] >= r['memory_floor_ns'] else 'memory'}-bound.")
    return "\n".join(rc.wrap(text)) + "\n"


def render_block_width(data: dict[str, Any]) -> str:
    """Markdown of the ``block_width`` entry: ID and FD at each width, for both flag sets."""
    e = data["benchmarks"]["block_width"]
    lines = rc.wrap(rc.run(data, e, (
        f"Block width of the generated kernels: PUMA 560 inverse and forward dynamics with its "
        f"friction, {e['states']:,} random states, one thread, ns per state, min / median of "
        f"{e['passes'] * e['calls_per_pass']} calls in {e['passes']} passes in which the "
        "builds take turns")) + (
        " Each width is generated and compiled in its own process; every width's results equal "
        f"scalar code's to {e['max_deviation_from_scalar']:.1e} (relative)."))
    chosen = {isa: v["ID"]["chosen_width"] for isa, v in e["verdict"].items()}
    rows = [[r["isa"], str(r["width"]), *rc.mm(r["ID"]), *rc.mm(r["FD"]),
             "robodyn's choice" if chosen[r["isa"]] == r["width"] else ""] for r in e["rows"]]
    lines += [""] + rc.table(["code", "width", "ID min", "ID median", "FD min", "FD median", ""],
                             rows)
    verdicts = "; ".join(
        f"{isa} {kernel}: fastest at width {v['best_width']}, robodyn's {v['chosen_width']} "
        f"takes {v['chosen_over_best']:.2f}x its time"
        for isa, kernels in e["verdict"].items() for kernel, v in kernels.items())
    added: dict[str, set[int]] = {}
    for r in e["rows"]:
        if r.get("added_flags"):
            added.setdefault(" ".join(r["added_flags"]), set()).add(r["width"])
    groups = [(sorted(ws), f) for f, ws in sorted(added.items(), key=lambda kv: min(kv[1]))]
    extra = "".join(
        f" {'Width' if len(ws) == 1 else 'Widths'} {rc.and_list([str(w) for w in ws])} builds also "
        f"get {f} (robodyn.codegen.build.compiler_flags)." for ws, f in groups)
    lines += [""] + rc.wrap(f"Code: {'; '.join(f'{k}: {v}' for k, v in e['isas'].items())}.{extra} "
                            f"By the minima: {verdicts}.")
    return "\n".join(lines) + "\n"


RENDERERS: dict[str, Callable[[dict[str, Any]], str]] = {
    "kernels": render_kernels, "casadi": render_casadi, "ensemble": render_ensemble,
    "simulation": render_simulation, "hydro": render_hydro, "roofline": render_roofline,
    "block_width": render_block_width}

#: Modules beside this script whose ``RENDERERS`` (section name -> function) are added to the
#: ones above: one module per group of benchmarks, each importing :mod:`render_common`.
RENDERER_MODULES = ("render_dynamics", "render_design", "render_workflows", "render_quality")
for _module in RENDERER_MODULES:
    RENDERERS.update(importlib.import_module(_module).RENDERERS)


def render(text: str, root: Path = ROOT, results: str | None = None) -> str:
    """The README text with every marked section rendered from the file it names.

    Parameters
    ----------
    text : str
        README contents.
    root : Path
        Folder the results paths are relative to.
    results : str, optional
        Results path (relative to ``root``) to put into every marker first.

    Returns
    -------
    str
        The new README contents.

    Raises
    ------
    ValueError
        No marked section, or one for a benchmark without a renderer.
    """
    def section(match: re.Match[str]) -> str:
        name, path = match["name"], results or match["path"]
        if name not in RENDERERS:
            raise ValueError(f"no renderer for results:{name}")
        data = json.loads((root / path).read_text())
        return f"<!-- results:{name} {path} -->\n{RENDERERS[name](data)}<!-- /results:{name} -->"

    new, count = MARKER.subn(section, text)
    if not count:
        raise ValueError("no <!-- results:NAME PATH --> section in the README")
    return new


def main(argv: list[str] | None = None) -> int:
    """Command line: render (or ``--check``) README.md; returns the exit status."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--results", help="results file (relative to the repository) to render from")
    parser.add_argument("--check", action="store_true", help="exit 1 if README.md is not rendered")
    parser.add_argument("--readme", type=Path, default=None,
                        help="render this file only (default: README.md and DOCUMENTS)")
    args = parser.parse_args(argv)
    results = args.results
    if results is not None and Path(results).is_absolute():
        results = str(Path(results).resolve().relative_to(ROOT))
    status = 0
    for path in [args.readme] if args.readme is not None else [README, *DOCUMENTS]:
        text = path.read_text()
        new = render(text, ROOT, results)
        if args.check:
            if new != text:
                print(f"{path} differs from its rendering: run benchmarks/render_readme.py")
                status = 1
            else:
                print(f"{path} matches its results file(s)")
            continue
        if new != text:
            path.write_text(new)
        print(f"{path}: benchmark section(s) rendered")
    return status


if __name__ == "__main__":
    sys.exit(main())
