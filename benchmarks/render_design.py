"""README sections of the design suites: derivation, excitation design, reading measured data.

``RENDERERS`` maps the section names ``derivation``, ``excitation`` and ``measure`` to functions
of the whole results file (``results.py``) that return the Markdown of the section; they are
registered by ``render_readme.py``. Figures not measured in the run are rendered as quoted, with
their source. Standard library only; nothing here times anything.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))
import render_common as rc  # noqa: E402 - sibling module of a script folder

#: Names of robodyn's derivation methods in the text.
METHODS = {"newton_euler": "Newton-Euler", "kane": "Kane", "lagrange": "Lagrange"}


def _met(ok: bool) -> str:
    return "met" if ok else "not met"


def _s(summary: dict[str, float]) -> str:
    """``"min / median s"`` of a timing in seconds."""
    return f"{rc.sig(summary['min'])} / {rc.sig(summary['median'])} s"


def _ops(cell: dict[str, int] | None) -> list[str]:
    return ["", ""] if cell is None else [str(cell["mul"]), str(cell["add"])]


def _op_table(o: dict[str, Any], quoted: dict[str, Any]) -> list[str]:
    """Table of op counts: every measured side by both methods, then the quoted figures."""
    rows = []
    for r in o["rows"]:
        what = {"robodyn Newton-Euler": "robodyn's recursive program, rigid body",
                "robodyn Newton-Euler with rotor and friction": "the same plus reflected rotor "
                "inertia and viscous and Coulomb friction (robodyn's `tau`)",
                "CasADi textbook RNEA": f"textbook recursion on CasADi SX, {r.get('form', '')} "
                "form, CasADi's cse on; agrees with robodyn to "
                f"{r.get('max_rel_error', 0):.0e}"}[r["label"]]
        rows.append([r["label"], r["parameters"], *_ops(r.get("robodyn counter")),
                     *_ops(r.get("CasADi count")), what])
    for name, q in quoted.items():
        if "mul" in q:
            rows.append([f"{name}, quoted", q["parameters"], "", "", "", "",
                         f"{q['mul']} mul / {q['add']} add, {q['source']}"])
    return rc.table(["inverse dynamics", "parameters", "robodyn counter mul", "add",
                     "CasADi count mul", "add", "what it is"], rows)


def _derivation_ops(o: dict[str, Any], quoted: dict[str, Any]) -> list[str]:
    """Op-count paragraph, table and targets."""
    c = o["counting"]
    lines = [""] + rc.wrap(
        "PUMA 560 inverse dynamics, operations per evaluation. Every side measured in this run "
        f"is counted by both methods, each applied alike to every side: robodyn's counter "
        f"({c['robodyn counter']}) and CasADi's ({c['CasADi count']}; CasADi "
        f"{o['casadi_version']}). The CasADi peer is a textbook recursive Newton-Euler (Luh, "
        "Walker and Paul: velocities and accelerations of each frame origin outwards, forces and "
        "moments inwards) written in the benchmark on CasADi SX symbols from the same "
        "description; with numeric parameters the cheaper of its centre-of-mass and barycentric "
        "forms is kept. Quoted rows were not measured in this run.")
    lines += [""] + _op_table(o, quoted)
    sb = quoted["SymPyBotics"]
    peers: dict[str, list[str]] = {}
    for t in o["targets"]:
        peers.setdefault(t["peer"], []).append(
            f"{t['parameters']} parameters, {t['method']}: {_met(t['met'])}")
    bullets = [
        "What differs: both measured sides are the rigid-body inverse dynamics of the same "
        "description (no rotor inertia, no friction), one state, sin and cos of each angle "
        "counted as functions; robodyn records named intermediates, folds zeros and ones and "
        "picks per link the cheaper of the two forms, the textbook peer multiplies the full 3x3 "
        "rotations and lets CasADi fold the zero entries and share common subexpressions.",
        f"SymPyBotics: {sb['counting']}.",
        *(f"Target (issue 2, fewer multiplications and fewer additions) against {peer}: "
          f"{'; '.join(v)}." for peer, v in peers.items())]
    lines += [""]
    for b in bullets:
        lines += rc.wrap(b, bullet=True)
    return lines


def _derivation_chains(ch: dict[str, Any]) -> list[str]:
    """Chain table and the linear-growth judgement."""
    rows = []
    for r in ch["rows"]:
        n, t = r["joints"], r["seconds"]
        rows.append([str(n), *rc.mm(t), rc.sig(1e3 * t["min"] / n), str(r["ops"]["mul"]),
                     f"{r['ops']['mul'] / n:.1f}", str(r["ops"]["add"]),
                     *rc.mm(r["whole_model_seconds"])])
    lines = [""] + rc.table(["joints", "ID min s", "ID median s", "ms per joint", "mul",
                             "mul per joint", "add", "whole model min s", "median s"], rows,
                            text_last=False)
    marg = "; ".join(f"joints {m['joints'][0]}-{m['joints'][1]}: {rc.sig(m['ms_per_joint'])} ms, "
                     f"{m['mul_per_joint']:.1f} mul and {m['add_per_joint']:.1f} add per added "
                     "joint" for m in ch["marginal"])
    text = (f"Marginal cost (from the minima): {marg}.")
    if "growth" in ch:
        g = ch["growth"]
        first, last = ch["rows"][0]["joints"], ch["rows"][-1]["joints"]
        text += (f" Growth: the last step's marginal multiplications are {g['mul']:.2f}x the "
                 f"first step's, and the time per joint at {last} joints is {g['time']:.2f}x that "
                 f"at {first} (issue 2's linear growth of time and op count, judged here as both "
                 f"at most {ch['target_growth']:g}x: {_met(ch['met'])}).")
    return lines + [""] + rc.wrap(text)


def render_derivation(data: dict[str, Any]) -> str:
    """Markdown of the ``derivation`` entry."""
    e = data["benchmarks"]["derivation"]
    sym, quoted = e["symbolic"], e["quoted"]
    sec, sb = sym["seconds"], quoted["SymPyBotics"]
    lines = rc.wrap(rc.run(data, e, (
        f"Symbolic derivation, times in s, min / median of {e['repeats']} rounds in which the "
        "rows take turns, each call from a cold SymPy cache")) + (
        " PUMA 560 by Newton-Euler with symbolic inertial parameters: tau, M and g "
        f"{_s(sec['tau, M, g'])}, the regressor {_s(sec['regressor'])}, C (Christoffel) "
        f"{_s(sec['C'])}; tau, M, g and regressor {_s(sec['tau, M, g, regressor'])}; the "
        f"complete model {_s(sec['complete'])} (target under {sym['target_s']:g} s: "
        f"{_met(sym['met'])}). SymPyBotics: {sb['seconds']:g} s for the same models plus "
        f"{sb['base_parameters_seconds']:g} s for base parameters, {sb['source']}."))
    lines += _derivation_ops(e["ops"], quoted)
    m = e["methods"]
    lines += [""] + rc.wrap(
        "PUMA 560 with numeric parameters, M, g and tau: " + "; ".join(
            f"{METHODS.get(k, k)} {_s(v)}" for k, v in m["seconds"].items())
        + f" (target for Lagrange and Kane: under {m['target_s']:g} s each: {_met(m['met'])}).")
    lines += [""] + rc.wrap(
        "Newton-Euler inverse dynamics of spatial chains (axes cycling z, y, x, numeric inertia): "
        "the recursive program alone, and the whole model (tau, M by composite rigid bodies, "
        "g) for reference: M has n(n+1)/2 entries, so that part cannot grow linearly.")
    lines += _derivation_chains(e["chains"])
    k = e["kanes_method"]
    ks, kr = k["seconds"], k["sympy_over"]
    lines += [""] + rc.wrap(
        f"A {k['joints']}-link spatial chain with symbolic inertia: "
        f"`sympy.physics.mechanics.KanesMethod` {_s(ks['sympy KanesMethod'])}, robodyn's Kane "
        f"{_s(ks['robodyn kane'])} ({rc.x(kr['robodyn kane'])} faster) and Newton-Euler "
        f"{_s(ks['robodyn newton_euler'])} ({rc.x(kr['robodyn newton_euler'])}), in the same "
        "run. SymPy's side is `kanes_equations` (Kane's equations Fr + Fr* = 0, from which its "
        "mass matrix and forcing follow), its frames, points and bodies built beforehand and not "
        "timed; robodyn's sides go from the description to M, g and tau.")
    r = e["rendering"]["seconds"]
    lines += [""] + rc.wrap(
        f"Rendering the PUMA 560 equations just derived (numeric parameters, {_s(r['derive'])}): "
        f"as text {_s(r['text'])}, as LaTeX {_s(r['latex'])} "
        f"({e['rendering']['render_over_derive_median']:.1f}x the derivation, medians).")
    return "\n".join(lines) + "\n"


def render_excitation(data: dict[str, Any]) -> str:
    """Markdown of the ``excitation`` entry (design one run; gradient timing min / median)."""
    e = data["benchmarks"]["excitation"]
    d, r, g, t = e["design"], e["random"], e["gradient"], e["targets"]
    q = e["quoted"]["7-joint designs"]
    ms, ratio = g["ms"], g["ratio"]
    text = (
        f"{rc.run(data, e, 'PUMA 560 excitation design')} {d['joints']} joints x "
        f"{d['harmonics']} harmonics, {d['columns']} base columns, {d['samples']} samples per "
        f"period, {d['starts']} start{'s' if d['starts'] != 1 else ''} ({d['settings']}), one "
        "run: condition number "
        f"{d['condition_number']:.1f} (target under {t['condition_number']:g}: "
        f"{_met(e['met']['condition_number'])}) in {d['wall_s']:.1f} s wall (target under "
        f"{t['design_s']:g} s: {_met(e['met']['design_s'])}), {d['cpu_s']:.1f} s CPU"
        f"{' (more than one thread at work)' if d['cpu_s'] > 1.1 * d['wall_s'] else ''}. The best of "
        f"{r['designs']} random rest-to-rest Fourier designs of the same size and limits, in the "
        f"same run: {r['best']:.1f} (median {r['median']:.0f}; {r['best_over_optimised']:.2f}x "
        f"the optimised one; {r['seconds']:.2f} s for all). For scale only: about "
        f"{q['low']}-{q['high']} for optimised 7-joint designs, {q['source']}. One criterion and "
        f"gradient ({g['samples']} samples; min / median of {g['repeats']} rounds in which the two "
        f"take turns, each the mean of {g['calls_per_repeat']} calls): the compiled regressor "
        f"derivatives {rc.sig(ms['analytic']['min'])} / {rc.sig(ms['analytic']['median'])} ms "
        f"against {rc.sig(ms['central differences']['min'])} / "
        f"{rc.sig(ms['central differences']['median'])} ms by central differences of the "
        f"regressor ({rc.x(ratio, 2)}), the gradients agreeing to "
        f"{g['max_rel_difference']:.1e} relative.")
    return "\n".join(rc.wrap(text)) + "\n"


def render_measure(data: dict[str, Any]) -> str:
    """Markdown of the ``measure`` entry."""
    e = data["benchmarks"]["measure"]
    sec, err, er = e["seconds"], e["velocity_error"], e["error_ratio"]
    names = list(sec)
    rows = [[k, *rc.mm(sec[k]), f"{min(err[k]):.3f}-{max(err[k]):.3f}", e["pipelines"][k]]
            for k in names]
    lines = rc.wrap(rc.run(data, e, (
        f"Reading and differentiating the {e['files']} Kinova Gen3 files ({e['rows']:,} rows x "
        f"{e['columns']} columns), s, min / median of {e['repeats']} rounds in which the "
        "pipelines take turns")) + (
        f" robodyn takes {rc.x(e['ratio'], 2)} the plain pipeline's time. Velocity error: "
        "RMS(velocity from positions - the file's measured velocity) / RMS(measured), joints "
        f"that move, range over the files; the plain pipeline's is {min(er):.1f}-{max(er):.1f}x "
        "robodyn's, file by file."))
    lines += [""] + rc.table(["pipeline", "min s", "median s", "velocity error", "what it does"],
                             rows)
    return "\n".join(lines) + "\n"


RENDERERS: dict[str, Callable[[dict[str, Any]], str]] = {
    "derivation": render_derivation, "excitation": render_excitation, "measure": render_measure}
