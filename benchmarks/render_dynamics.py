"""README sections of the dynamics suites: ``derivatives`` (``bench_derivatives.py``),
``identify`` (``bench_identify.py``) and ``schedule`` (``bench_schedule.py``), rendered from their
entries in the results file.

Registered in ``render_readme.py`` through :data:`RENDERERS`; each renderer takes the whole results
file (machine record and benchmarks) and returns Markdown lines ending in a newline. Standard
library only; nothing here times anything.
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


def render_derivatives(data: dict[str, Any]) -> str:
    """Markdown of the ``derivatives`` entry: the table with the loop and the binding taken out,
    what each side is, the agreement and the target.
    """
    e = data["benchmarks"]["derivatives"]
    loop, floor, copies = e["python_loop_ns"], e["binding_floor_ns"], e["three_copies_ns"]
    views = all(e["returns_views"].values())
    rnea = next(r for r in e["rows"] if r["kernel"] == "inverse dynamics")["pinocchio_loop_ns"]
    lines = rc.wrap(rc.run(data, e, (
        f"PUMA 560 analytic derivatives against Pinocchio's wheel called from Python, "
        f"{e['states']:,} random states for robodyn and the first {e['loops']:,} of them for "
        f"Pinocchio's loop, ns per state, min / median of {e['repeats']} rounds in which the rows "
        "take turns")) + (
        f" A looped Pinocchio call costs more than its computation. Measured in the same rounds: "
        f"the Python loop alone (a no-op with the same arguments) {rc.sig(loop['min'])} ns per call "
        f"(median {rc.sig(loop['median'])}), and the binding floor, `{e['binding_floor_call']}` "
        f"in the same loop, {rc.sig(floor['min'])} ns (median {rc.sig(floor['median'])}; a "
        f"whole `rnea` call in the same loop takes {rc.sig(rnea['min'])} ns): the "
        "loop, the binding's argument handling (overload resolution, three vectors converted), "
        "three NumPy views of Pinocchio's `Data` made, as the derivative functions return, and a "
        "forward kinematics pass with velocities and accelerations, which both derivative "
        "functions also do. \"Minus the loop\" takes the first off every round (an upper bound "
        "of robodyn's speed-up over Pinocchio's computation alone), \"minus the binding\" the "
        "second (more than the overhead: a conservative figure, a lower bound; the views are "
        "read from Python, which adds attribute lookups; not applied to `rnea` and `aba`, timed "
        "for scale, whose whole calls cost about as much as the floor). Ratio = Pinocchio's time "
        "/ robodyn's, min / median."))
    rows = []
    for r in e["rows"]:
        floor_cells = (["", ""] if "minus_binding_floor_ns" not in r else
                       [rc.sig(r["minus_binding_floor_ns"]["min"]),
                        rc.x(r["minus_binding_floor_ratio"])])
        rows.append([r["kernel"], rc.sig(r["robodyn_ns"]["min"]),
                     rc.sig(r["pinocchio_loop_ns"]["min"]), rc.x(r["ratio"]),
                     rc.sig(r["minus_loop_ns"]["min"]), rc.x(r["minus_loop_ratio"]), *floor_cells])
    lines += [""] + rc.table(["kernel", "robodyn min", "Pinocchio loop min", "ratio",
                            "minus the loop", "ratio", "minus the binding", "ratio"], rows,
                           text_last=False)
    a = e["agreement"]
    bullets = [f"{k}: {v}." for k, v in e["peers"].items()]
    bullets.append(
        f"The wheel's batched functions: {', '.join(e['pinocchio_batched']) or 'none'}; no "
        "derivatives among them, hence the loop.")
    bullets.append(
        "The derivative bindings return views of Pinocchio's `Data` matrices (checked in the "
        "run): no copy is in Pinocchio's times. Keeping each state's three matrices, as "
        "robodyn's batch output does, would take three copies per call, "
        f"{rc.sig(copies['min'])} ns (measured, not added)." if views else
        "The derivative bindings did NOT return views of `Data` in this run: their copies are "
        f"in Pinocchio's times. Three more copies per call cost {rc.sig(copies['min'])} ns "
        "(measured, not added).")
    bullets.append(
        f"Agreement on the first {a['states']} states, max |difference| / max |value|: d tau/dq "
        f"{a['d_tau_d_q']:.1e}, d tau/dqd {a['d_tau_d_qd']:.1e} once robodyn's viscous friction "
        f"is taken off its diagonal; forward derivatives against Pinocchio's at the rigid torque "
        f"that gives robodyn's qdd: d qdd/dq {a['d_qdd_d_q']:.1e}, d qdd/dqd {a['d_qdd_d_qd']:.1e} "
        f"(with M^-1 Fv), d qdd/dtau {a['d_qdd_d_tau']:.1e}.")
    lines += ["", "What each side is and differs in:", ""]
    for b in bullets:
        lines += rc.wrap(b, bullet=True)
    t = e["target"]
    lines += [""] + rc.wrap(
        f"Target (issue 15): forward-dynamics derivatives at least {t['target']:g}x faster than "
        f"`computeABADerivatives`, judged on the lower bound (minus the binding, min): "
        f"{t['value']:.1f}x: {_met(t['met'])}. Issue 22's FD-derivatives target (at least 15x "
        "against Pinocchio's templates compiled natively with robodyn's flags and called from "
        "C++, no Python and no binding) is judged in the kernels table (`bench_kernels.py`), "
        "not here.")
    return "\n".join(lines) + "\n"


def _identify_rows(s: dict[str, Any]) -> list[list[str]]:
    """Table rows of the stacking entry: each timed row with its ratio and target cells."""
    by_row = {r["row"]: r for r in s["ratios"]}
    out = []
    for r in s["rows"]:
        ratio, target = "", ""
        if r["label"] in by_row:
            x = by_row[r["label"]]
            ratio = rc.x(x)
            if "target" in x:
                target = f">= {x['target']:g}x: {_met(x['met'])}"
            elif r["label"].startswith("robodyn"):
                ratio += f" ({x['row_threads']} threads vs {x['peer_threads']})"
                target = "not judged: threads differ"
            else:
                target = "zero compute"
        out.append([r["label"], str(r["threads"]), *rc.mm(r["ns_per_sample"]), ratio, target])
    return out


def _stacking_path(e: dict[str, Any]) -> str:
    """The sentence on how ``rd.identify`` stacks, from the call the run watched."""
    text = ("`rd.identify` stacks each recording's regressor for the fit through "
            "`regressor_rows_of`, which calls `identification_matrix(model, q, qd, qdd)`: every "
            "column, one thread, a fresh matrix (the first row); the model's own effort (the terms "
            "fitted after the linear step, the predictions) goes through the same call a chunk of "
            "samples at a time into one reused buffer (`out=`, the reused rows' case).")
    if "identifications" not in e:
        return text + " Not watched in this run (`--stacking-only`)."
    c = e["identifications"]["stacking_calls"]
    if not c["count"]:
        return ("In this run an untimed `rd.identify` made no call to `identification_matrix`: "
                "the rows below do not time its stacking path.")
    if "fresh" not in c:  # an entry written before the calls were told apart
        return text + (
            f" Watched in this run during an untimed `rd.identify`: {c['count']} calls, threads "
            f"{', '.join(map(str, c['threads']))}, `out=` {'used' if c['out'] else 'never used'}, "
            f"a column selection {'used' if c['columns'] else 'never used'}.")
    f, r = c["fresh"], c["reused"]
    return text + (
        f" Watched in this run during an untimed `rd.identify`: {c['count']} calls, threads "
        f"{', '.join(map(str, c['threads']))}: {f['count']} into a fresh matrix "
        f"({f['samples']:,} samples in all), {r['count']} into a reused buffer ({r['samples']:,} "
        f"samples in all); a column selection {'used' if c['columns'] else 'never used'}.")


def render_identify(data: dict[str, Any]) -> str:
    """Markdown of the ``identify`` entry: stacking against Pinocchio's loop (threads said),
    the memory floors, the agreement, and the whole identifications when present."""
    e = data["benchmarks"]["identify"]
    s = e["stacking"]
    ratio = {(r["case"], r["row"]): r for r in s["ratios"]}
    fresh, reused = ratio["fresh", "robodyn fresh"], ratio["reused", "robodyn reused"]
    lines = rc.wrap(rc.run(data, e, (
        f"Stacking the identification matrix of {s['samples']:,} Kinova Gen3 samples "
        f"({s['samples'] * s['joints']:,} x {s['columns']}, {s['megabytes']} MB), robodyn's "
        f"batched compiled regressor against a Python loop over Pinocchio {s['pinocchio_version']}'s "
        f"`computeJointTorqueRegressor` on the manufacturer's URDF, ns per sample, min / median of "
        f"{s['repeats']} rounds in which the rows take turns")) + (
        f" {_stacking_path(e)} Pinocchio's loop runs on one thread, one Python call per sample, and "
        f"writes {s['pinocchio_columns']} columns per row (no friction or drive columns: less "
        "memory than robodyn's), into a fresh matrix and into one already written, like "
        "robodyn's fresh and reused (`out=`) cases; NumPy writing robodyn's matrix alone "
        "(`np.full`, `fill`) is the time zero compute would take. Ratio = Pinocchio's loop in "
        "the same case / the row, min / median; the target is judged on the 1-thread rows."))
    lines += [""] + rc.table(["row", "threads", "min", "median", "Pinocchio loop / row",
                            "target (issue 10)"], _identify_rows(s))
    w = s["writing_alone"]
    lines += [""] + rc.wrap(
        f"Pinocchio's loop / robodyn, like for like on one thread each: `rd.identify`'s path "
        f"(fresh matrix) {rc.x(fresh)} ({_met(fresh['met'])} against at least "
        f"{fresh['target']:g}x), into a reused matrix {rc.x(reused)} ({_met(reused['met'])}). "
        f"The 2-thread rows are robodyn on 2 threads against the same 1-thread loop, not judged. "
        f"On one thread robodyn takes {rc.x(w['fresh'], 2)} the time of NumPy's `np.full` of its "
        f"matrix into fresh memory and {rc.x(w['reused'], 2)} the time of `fill` into the reused "
        f"one; Pinocchio's fresh loop takes {rc.x(ratio['fresh', 'NumPy np.full'])} the time of "
        "`np.full` alone, the most any 1-thread kernel writing this matrix into fresh memory "
        f"could show. The rigid-body columns agree to {s['rigid_body_agreement']:.1e} "
        "(max |difference| / max |value|).")
    if "identifications" in e:
        i = e["identifications"]
        m = i["methods"]
        lines += [""] + rc.wrap(
            f"Whole identifications of the three Kinova whole-arm runs ({i['samples']:,} samples, "
            f"motor current, defaults), one timed run each after an untimed one (single figures, "
            f"not min / median): OLS {m['ols']['seconds']:.2f} s, WLS {m['wls']['seconds']:.2f} s, "
            f"physically consistent (SDP) {m['consistent']['seconds']:.2f} s.")
    return "\n".join(lines) + "\n"


def render_schedule(data: dict[str, Any]) -> str:
    """Markdown of the ``schedule`` entry: ID and FD per statement order and transposition."""
    e = data["benchmarks"]["schedule"]
    layouts = ", ".join("robodyn's model flags" + (f" + `{' '.join(x)}`" if x else "")
                        for x in e["layouts"])
    lines = rc.wrap(rc.run(data, e, (
        f"Statement order and input transposition of the generated kernels, {e['states']:,} random "
        f"states, one thread, raw batch calls, ns per state, the best of {e['repeats']} calls "
        "per build, the builds taking turns")) + (
        f" Each source is compiled three ways that differ only in code layout ({layouts}); the "
        "table gives each build's minimum and the median of those three minima. Every build's "
        f"results equal the first one's to {max(r['max_rel_difference'] for r in e['rows']):.1e} "
        "(relative)."))
    rows = [[r["variant"], r["robot"], r["kernel"],
             " / ".join(f"{x['min']:.1f}" for x in r["ns_per_state_by_layout"]),
             f"{r['median_of_layout_minima']:.1f}"] for r in e["rows"]]
    lines += [""] + rc.table(["statements, transposition", "robot", "kernel", "min by layout",
                              "median of the minima"], rows, text_last=False)
    return "\n".join(lines) + "\n"


RENDERERS: dict[str, Callable[[dict[str, Any]], str]] = {
    "derivatives": render_derivatives, "identify": render_identify, "schedule": render_schedule}
