"""``robodyn`` command line: parse, call the public API, print.

Subcommands: ``list``, ``show``, ``derive``, ``check`` and ``demo`` (``robodyn --help``).
Exit codes: 0 success, 1 the formulations disagree, 2 bad input (unknown robot, invalid
description, unwritable output), 130 interrupted.
"""

from __future__ import annotations

import argparse
import csv
import html
import io
import sys
import textwrap
import time
import warnings
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path

import numpy as np
import sympy as sp

import robodyn as rd
from robodyn.robot.errors import DescriptionError
from robodyn.symbolic.eom import METHODS
from robodyn.symbolic.render import render_json, render_latex, render_mathml, render_text

#: Relative difference above which two formulations are reported as disagreeing.
TOLERANCE = 1e-9

_QUANTITIES = ("M", "g", "tau")
_RENDERERS = {"text": render_text, "latex": render_latex, "json": render_json}


# ----------------------------------------------------------------------------------------------
# small helpers
# ----------------------------------------------------------------------------------------------


def _err(*args: object) -> None:
    print(*args, file=sys.stderr, flush=True)


@contextmanager
def _progress(label: str) -> Iterator[None]:
    """``label... 2.1 s`` on stderr around a long step."""
    print(f"{label}...", end=" ", file=sys.stderr, flush=True)
    start = time.perf_counter()
    try:
        yield
    finally:
        print(f"{time.perf_counter() - start:.1f} s", file=sys.stderr, flush=True)


def _table(headers: Sequence[str], rows: Sequence[Sequence[object]]) -> str:
    """Plain aligned text table; numbers right-aligned, text left-aligned."""
    cells = [[str(c) for c in headers]] + [[str(c) for c in row] for row in rows]
    numeric = [bool(rows) and all(_is_number(r[k]) for r in rows) for k in range(len(headers))]
    widths = [max(len(r[k]) for r in cells) for k in range(len(headers))]

    def line(row: list[str]) -> str:
        return "  ".join(c.rjust(w) if num else c.ljust(w)
                         for c, w, num in zip(row, widths, numeric, strict=True)).rstrip()

    rule = "  ".join("-" * w for w in widths)
    return "\n".join([line(cells[0]), rule] + [line(r) for r in cells[1:]])


def _is_number(value: object) -> bool:
    """A number, or the text of one (right-aligned in tables)."""
    if isinstance(value, bool):
        return False
    if isinstance(value, int | float | np.floating):
        return True
    try:
        float(str(value))
    except ValueError:
        return False
    return True


def _fmt(expr: object) -> str:
    """Short text of a number or SymPy expression."""
    if expr is None:
        return "-"
    return sp.sstr(sp.sympify(expr), full_prec=False)


def _vec(values: Sequence[object]) -> str:
    return "(" + ", ".join(_fmt(v) for v in values) + ")"


def _types(robot: rd.Robot) -> str:
    return "".join("P" if j.type == "prismatic" else "R" for j in robot.joints)


def _transform(mat: sp.MatrixBase) -> str:
    if sp.Matrix(mat) == sp.eye(4):
        return "identity"
    return "; ".join(" ".join(_fmt(mat[r, c]) for c in range(4)) for r in range(3))


def _write(text: str, target: str | None) -> None:
    if target is None or target == "-":
        sys.stdout.write(text)
    else:
        Path(target).write_text(text, encoding="utf-8")
        _err(f"wrote {target}")


# ----------------------------------------------------------------------------------------------
# agreement of the formulations
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Agreement:
    """Largest relative difference of M, g and tau between two formulations.

    Attributes
    ----------
    first, second : str
        Method names.
    relative : dict[str, float]
        ``max over states of max|a - b| / max(max|a|, max|b|)`` per quantity ("M", "g", "tau").
    symbolic : bool or None
        Whether every simplified difference is zero (None: not checked).
    """

    first: str
    second: str
    relative: dict[str, float]
    symbolic: bool | None = None

    @property
    def ok(self) -> bool:
        """Within :data:`TOLERANCE` (and symbolically equal where checked)."""
        return max(self.relative.values()) <= TOLERANCE and self.symbolic is not False


def _evaluator(eom: rd.EquationsOfMotion) -> Callable[..., dict[str, np.ndarray]]:
    """``f(q, qd, qdd) -> {"M": (n, n), "g": (n,), "tau": (n,)}`` at the default parameters.

    One ``sympy.cse`` (which walks shared subtrees once) runs before ``lambdify``, which is
    handed only the reduced expressions: its own passes walk every expression as a tree, which
    takes minutes on the (heavily shared) Lagrange expressions of a 6-joint arm.
    """
    n = eom.dof
    values = eom.numeric()
    params = list(values)
    exprs = list(eom.M) + list(eom.g) + list(eom.tau)
    replacements, reduced = sp.cse(exprs, symbols=sp.numbered_symbols("_x"), order="none")
    fn = sp.lambdify([eom.q, eom.qd, eom.qdd, params], reduced, modules="numpy",
                     cse=lambda _: (replacements, reduced))
    args = [values[p] for p in params]

    def call(q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> dict[str, np.ndarray]:
        out = np.asarray(fn(q, qd, qdd, args), dtype=float)
        return {"M": out[: n * n].reshape(n, n), "g": out[n * n: n * n + n],
                "tau": out[n * n + n:]}

    return call


def _states(n: int, count: int, seed: int) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    rng = np.random.default_rng(seed)
    return [(rng.uniform(-np.pi, np.pi, n), rng.uniform(-2, 2, n), rng.uniform(-3, 3, n))
            for _ in range(count)]


def _symbolically_equal(a: rd.EquationsOfMotion, b: rd.EquationsOfMotion) -> bool:
    for name in _QUANTITIES:
        diff = sp.Matrix(getattr(a, name)) - sp.Matrix(getattr(b, name))
        if any(sp.simplify(sp.expand(e)) != 0 for e in diff):
            return False
    return True


def agreement(eoms: Sequence[rd.EquationsOfMotion], samples: int = 20, seed: int = 0,
              symbolic: bool = False) -> list[Agreement]:
    """Compare every pair of formulations on random states (and symbolically if asked).

    Parameters
    ----------
    eoms : sequence of EquationsOfMotion
        Equations of one robot by different methods.
    samples : int
        Number of random states (q in [-pi, pi], qd in [-2, 2], qdd in [-3, 3]).
    seed : int
        Seed of the random states.
    symbolic : bool
        Also check that the simplified differences are zero (small arms only: slow).

    Returns
    -------
    list of Agreement
        One per pair, in the order of ``eoms``.
    """
    n = eoms[0].dof
    states = _states(n, samples, seed)
    values: dict[str, dict[str, list[np.ndarray]]] = {}
    for eom in eoms:
        with _progress(f"evaluating {eom.method} on {samples} states"):
            func = _evaluator(eom)
            results = [func(*s) for s in states]
            values[eom.method] = {k: [r[k] for r in results] for k in _QUANTITIES}
    out = []
    for i, a in enumerate(eoms):
        for b in eoms[i + 1:]:
            rel = {}
            for k in _QUANTITIES:
                worst = 0.0
                for va, vb in zip(values[a.method][k], values[b.method][k], strict=True):
                    scale = max(np.max(np.abs(va)), np.max(np.abs(vb)))
                    diff = np.max(np.abs(va - vb))
                    worst = max(worst, diff / scale if scale > 0 else diff)
                rel[k] = float(worst)
            same = None
            if symbolic:
                with _progress(f"simplifying {a.method} - {b.method}"):
                    same = _symbolically_equal(a, b)
            out.append(Agreement(a.method, b.method, rel, same))
    return out


def _derive_all(robot: rd.Robot) -> list[rd.EquationsOfMotion]:
    eoms = []
    for method in METHODS:
        with _progress(f"deriving {method}"):
            eoms.append(rd.derive(robot, method))
    for eom in eoms:
        with _progress(f"counting operations of {eom.method} (after CSE)"):
            eom.op_counts()
    return eoms


_COUNT_HEADERS = ("method", "derive [s]", "tau +", "tau *", "tau fn", "M +", "M *", "M fn",
                  "g +", "g *", "g fn")


def _count_rows(eoms: Sequence[rd.EquationsOfMotion]) -> list[list[object]]:
    rows = []
    for eom in eoms:
        counts = eom.op_counts()
        row: list[object] = [eom.method, f"{eom.derivation_time:.3f}"]
        for key in ("tau", "M", "g"):
            ops = counts[key]
            row += [ops.additions, ops.multiplications, ops.functions]
        rows.append(row)
    return rows


def _agreement_rows(results: Sequence[Agreement]) -> list[list[object]]:
    rows = []
    for r in results:
        sym = {None: "-", True: "yes", False: "NO"}[r.symbolic]
        rows.append([f"{r.first} vs {r.second}"] + [f"{r.relative[k]:.1e}" for k in _QUANTITIES]
                    + [sym, "ok" if r.ok else "DISAGREE"])
    return rows


_AGREEMENT_HEADERS = ("pair", "M", "g", "tau", "symbolic", "result")


# ----------------------------------------------------------------------------------------------
# subcommands
# ----------------------------------------------------------------------------------------------


def _cmd_list(args: argparse.Namespace) -> int:
    rows = []
    for name in rd.builtin_names():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # plausibility notes belong to 'show', not here
            robot = rd.load(name)
        rows.append([name, robot.dof, _types(robot), ", ".join(robot.parameters) or "-"])
    print(_table(["name", "dof", "joints", "named parameters"], rows))
    return 0


def _cmd_show(args: argparse.Namespace) -> int:
    robot = rd.load(args.robot)
    print(f"robot {robot.name}: {robot.dof} joints ({_types(robot)})")
    print(f"source: {robot.source}")
    print(f"description sha256: {robot.description_hash}\n")
    joint_rows = []
    for k, j in enumerate(robot.joints, 1):
        placement = " ".join(f"{key}={_fmt(v)}" for key, v in j.source_params.items()) or "-"
        limits = "-"
        if j.lower is not None or j.upper is not None:
            limits = f"[{_fmt(j.lower)}, {_fmt(j.upper)}]"
        fr = j.friction
        friction = "-" if fr.is_zero else (f"v={_fmt(fr.viscous)} c+={_fmt(fr.coulomb_positive)} "
                                          f"c-={_fmt(fr.coulomb_negative)} o={_fmt(fr.offset)}")
        joint_rows.append([k, j.name, j.type, j.convention, placement, limits,
                           _fmt(j.drive.gear_ratio), _fmt(j.drive.rotor_inertia), friction])
    print("joints")
    print(_table(["#", "name", "type", "convention", "placement", "limits", "gear ratio",
                  "rotor inertia", "friction (joint side)"], joint_rows))
    link_rows = []
    for k, link in enumerate(robot.links, 1):
        inertia = link.inertia
        link_rows.append([k, link.name, _fmt(link.mass), _vec(link.com),
                          _vec([inertia[0, 0], inertia[1, 1], inertia[2, 2]]),
                          _vec([inertia[0, 1], inertia[0, 2], inertia[1, 2]])])
    print("\nlinks (inertia about the centre of mass, link frame)")
    print(_table(["#", "name", "mass", "com", "ixx iyy izz", "ixy ixz iyz"], link_rows))
    print(f"\nbase: {_transform(robot.base)}")
    print(f"tool: {_transform(robot.tool)}")
    print(f"gravity: {_vec(robot.gravity)}")
    if robot.parameters:
        print("\nnamed parameters (defaults)")
        print(_table(["name", "default"], [[k, v] for k, v in robot.parameters.items()]))
    else:
        print("named parameters: none")
    return 0


def _cmd_derive(args: argparse.Namespace) -> int:
    robot = rd.load(args.robot)
    with _progress(f"deriving {args.method}"):
        eom = rd.derive(robot, args.method)
    with _progress(f"rendering {args.format}"):
        text = _RENDERERS[args.format](eom)
    _write(text, args.output)
    return 0


def _cmd_check(args: argparse.Namespace) -> int:
    robot = rd.load(args.robot)
    print(f"{robot.name}: {robot.dof} joints ({_types(robot)}), {robot.source}")
    eoms = _derive_all(robot)
    results = agreement(eoms, args.samples, args.seed, symbolic=robot.dof <= 2)
    print("\nderivation time and operations after common-subexpression elimination")
    print(_table(_COUNT_HEADERS, _count_rows(eoms)))
    print(f"\nagreement: max relative difference over {args.samples} random states "
          f"(tolerance {TOLERANCE:g})")
    print(_table(_AGREEMENT_HEADERS, _agreement_rows(results)))
    ok = all(r.ok for r in results)
    print("\nresult: " + ("the three formulations agree" if ok else "the formulations DISAGREE"))
    return 0 if ok else 1


def _cmd_demo(args: argparse.Namespace) -> int:
    out = Path(args.output)
    out.mkdir(parents=True, exist_ok=True)
    robot = rd.load("puma560")
    eoms = _derive_all(robot)
    results = agreement(eoms, args.samples, args.seed)
    by_method = {e.method: e for e in eoms}
    with _progress("writing puma560_newton_euler.txt"):
        (out / "puma560_newton_euler.txt").write_text(render_text(by_method["newton_euler"]))
    for eom in eoms:
        with _progress(f"writing puma560_{eom.method}.json"):
            (out / f"puma560_{eom.method}.json").write_text(render_json(eom))
    with _progress("writing puma560_equations.tex"):
        (out / "puma560_equations.tex").write_text(render_latex(by_method["newton_euler"]))
    trolley = rd.load("trolley_pendulum")
    with _progress("deriving trolley_pendulum (kane) and checking eqs. 2.46-2.47"):
        teom = rd.derive(trolley, "kane")
        closed = _trolley_closed_form_ok(teom)
        (out / "trolley_pendulum.tex").write_text(render_latex(teom))
    counts = _count_rows(eoms)
    csv_text = io.StringIO()
    writer = csv.writer(csv_text, lineterminator="\n")
    writer.writerow(["method", "derivation_time_s"] + [
        f"{k}_{op}" for k in ("tau", "M", "g")
        for op in ("additions", "multiplications", "functions")])
    writer.writerows(counts)
    (out / "comparison.csv").write_text(csv_text.getvalue())
    (out / "comparison.md").write_text(_markdown(robot, counts, results, args.samples))
    page = _html_page(robot, counts, results, args.samples, teom, closed,
                                 render_mathml(teom), render_latex(teom), render_text(teom))
    (out / "report.html").write_text(page, encoding="utf-8")
    print(_table(_COUNT_HEADERS, counts))
    print()
    print(_table(_AGREEMENT_HEADERS, _agreement_rows(results)))
    print("\ntrolley pendulum (kane) equals the seed's eqs. 2.46-2.47: "
          + ("yes" if closed else "NO"))
    print(f"wrote {', '.join(sorted(p.name for p in out.iterdir()))} in {out}")
    print(f"report: {(out / 'report.html').resolve()}")
    return 0 if all(r.ok for r in results) and closed else 1


# ----------------------------------------------------------------------------------------------
# demo outputs
# ----------------------------------------------------------------------------------------------


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
    def md_table(headers: Sequence[str], rows: Sequence[Sequence[object]]) -> list[str]:
        out = ["| " + " | ".join(headers) + " |", "|" + "---|" * len(headers)]
        return out + ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]

    lines = [f"# Efficiency of the formulations: {robot.name}", "",
             f"robodyn {rd.__version__}; description sha256 `{robot.description_hash}`.", "",
             f"Derivation time (s) and {_CSV_NOTE}.", ""]
    lines += md_table(_COUNT_HEADERS, counts)
    lines += ["", f"## Agreement (max relative difference over {samples} random states, "
              f"tolerance {TOLERANCE:g})", ""]
    lines += md_table(_AGREEMENT_HEADERS, _agreement_rows(results))
    return "\n".join(lines) + "\n"


_CSS = """
body { font-family: system-ui, sans-serif; max-width: 70rem; margin: 2rem auto; padding: 0 1rem;
       color: #222; line-height: 1.45; }
h1 { font-size: 1.6rem; border-bottom: 2px solid #345; padding-bottom: .3rem; }
h2 { font-size: 1.25rem; margin-top: 2rem; color: #234; }
h4 { margin: 1rem 0 .2rem; }
table { border-collapse: collapse; margin: .5rem 0; font-variant-numeric: tabular-nums; }
th, td { border: 1px solid #bbc; padding: .25rem .6rem; }
th { background: #e8edf3; }
td.num { text-align: right; }
.ok { color: #176117; font-weight: 600; }
.bad { color: #a01010; font-weight: 600; }
pre { background: #f5f6f8; padding: .6rem; overflow-x: auto; font-size: .85rem; }
math { font-size: 1.1rem; }
.meta { color: #555; font-size: .9rem; }
"""


def _html_table(headers: Sequence[str], rows: Sequence[Sequence[object]]) -> str:
    head = "".join(f"<th>{html.escape(str(h))}</th>" for h in headers)
    body = []
    for row in rows:
        cells = []
        for c in row:
            text = html.escape(str(c))
            if text in ("ok", "yes"):
                cells.append(f'<td class="ok">{text}</td>')
            elif text in ("DISAGREE", "NO"):
                cells.append(f'<td class="bad">{text}</td>')
            else:
                cells.append(f'<td class="num">{text}</td>' if _is_number(c)
                             else f"<td>{text}</td>")
        body.append("<tr>" + "".join(cells) + "</tr>")
    return f"<table><thead><tr>{head}</tr></thead><tbody>{''.join(body)}</tbody></table>"


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
{_html_table(_COUNT_HEADERS, counts)}

<h2>Agreement</h2>
<p>Largest relative difference of M(q), g(q) and the full inverse dynamics tau between each pair
of formulations over {samples} random states (q in [&minus;&pi;, &pi;], qd in [&minus;2, 2],
qdd in [&minus;3, 3]); tolerance {TOLERANCE:g}. Result: {verdict}.</p>
{_html_table(_AGREEMENT_HEADERS, _agreement_rows(results))}

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


# ----------------------------------------------------------------------------------------------
# argument parsing
# ----------------------------------------------------------------------------------------------

_ROBOT_HELP = "built-in robot name (see 'robodyn list') or path to a .yaml/.yml/.urdf description"


def _parser() -> argparse.ArgumentParser:
    fmt = argparse.RawDescriptionHelpFormatter
    parser = argparse.ArgumentParser(
        prog="robodyn", formatter_class=fmt,
        description="Symbolic equations of motion of serial robot manipulators: derive them by "
                    "Newton-Euler, Lagrange or Kane, print them, and check the formulations "
                    "against each other.",
        epilog="examples:\n"
               "  robodyn list\n"
               "  robodyn show puma560\n"
               "  robodyn derive trolley_pendulum --method kane --format latex -o trolley.tex\n"
               "  robodyn check planar_2r --samples 50\n"
               "  robodyn demo -o out\n\n"
               "Run 'robodyn COMMAND --help' for the options of a command.")
    parser.add_argument("--version", action="version", version=f"robodyn {rd.__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)

    p = sub.add_parser("list", help="list the built-in robots", formatter_class=fmt,
                       description="List the built-in robots: name, number of joints, joint "
                                   "types (R revolute, P prismatic) and named parameters.",
                       epilog="example:\n  robodyn list")
    p.set_defaults(func=_cmd_list)

    p = sub.add_parser("show", help="show a robot's joints, links and parameters",
                       formatter_class=fmt,
                       description="Print a robot description as tables: joints (placement as "
                                   "given, limits, drive, friction), links (mass, centre of "
                                   "mass, inertia), base, tool, gravity and named parameters.",
                       epilog="examples:\n  robodyn show puma560\n  robodyn show my_arm.yaml")
    p.add_argument("robot", metavar="ROBOT", help=_ROBOT_HELP)
    p.set_defaults(func=_cmd_show)

    p = sub.add_parser("derive", help="derive and print the equations of motion",
                       formatter_class=fmt,
                       description="Derive M(q), C(q, qd), g(q) and tau and print them. Arms "
                                   "with up to 3 joints print in simplified textbook form; "
                                   "larger arms in recursive Newton-Euler form with M and g "
                                   "after common-subexpression elimination.",
                       epilog="examples:\n"
                              "  robodyn derive planar_2r\n"
                              "  robodyn derive trolley_pendulum --method kane --format latex "
                              "-o trolley.tex\n"
                              "  robodyn derive puma560 --format json -o puma560.json")
    p.add_argument("robot", metavar="ROBOT", help=_ROBOT_HELP)
    p.add_argument("--method", choices=METHODS, default="newton_euler",
                   help="formulation (default: %(default)s)")
    p.add_argument("--format", choices=tuple(_RENDERERS), default="text",
                   help="output format (default: %(default)s)")
    p.add_argument("-o", "--output", metavar="FILE", help="write to FILE instead of stdout")
    p.set_defaults(func=_cmd_derive)

    p = sub.add_parser("check", help="derive three ways and check that they agree",
                       formatter_class=fmt,
                       description="Derive the equations of motion by Newton-Euler, Lagrange "
                                   "and Kane; print the derivation times and operation counts, "
                                   "and the largest relative difference of M, g and tau between "
                                   "each pair on random states (symbolically too for arms with "
                                   f"up to 2 joints). Exit code 1 if they differ by more than "
                                   f"{TOLERANCE:g}.",
                       epilog="examples:\n  robodyn check planar_2r\n"
                              "  robodyn check puma560 --samples 50 --seed 1")
    p.add_argument("robot", metavar="ROBOT", help=_ROBOT_HELP)
    p.add_argument("--samples", type=_positive, default=20, metavar="N",
                   help="number of random states (default: %(default)s)")
    p.add_argument("--seed", type=int, default=0, help="random seed (default: %(default)s)")
    p.set_defaults(func=_cmd_check)

    p = sub.add_parser("demo", help="PUMA 560 three ways: files, comparison and HTML report",
                       formatter_class=fmt,
                       description="Derive the PUMA 560 by the three formulations, check that "
                                   "they agree, and write to the output folder: the recursive "
                                   "Newton-Euler listing (puma560_newton_euler.txt), JSON per "
                                   "formulation, LaTeX documents (puma560_equations.tex, "
                                   "trolley_pendulum.tex), the efficiency comparison "
                                   "(comparison.md, comparison.csv) and report.html.",
                       epilog="example:\n  robodyn demo -o out   # then open out/report.html")
    p.add_argument("-o", "--output", metavar="DIR", default="out",
                   help="output folder, created if missing (default: %(default)s)")
    p.add_argument("--samples", type=_positive, default=20, metavar="N",
                   help="number of random states for the agreement check (default: %(default)s)")
    p.add_argument("--seed", type=int, default=0, help="random seed (default: %(default)s)")
    p.set_defaults(func=_cmd_demo)
    for each in (parser, *sub.choices.values()):
        each.description = textwrap.fill(each.description or "", width=88)
    return parser


def _positive(text: str) -> int:
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {text}")
    return value


def _show_warning(message: Warning | str, category: type[Warning], filename: str, lineno: int,
                  file: object = None, line: str | None = None) -> None:
    """Warnings as one line each on stderr (no source line)."""
    _err(f"robodyn: warning: {message}")


def main(argv: Sequence[str] | None = None) -> int:
    """Run the ``robodyn`` command line.

    Parameters
    ----------
    argv : sequence of str, optional
        Arguments without the program name; ``sys.argv[1:]`` when None.

    Returns
    -------
    int
        Exit code: 0 success, 1 the formulations disagree, 2 bad input, 130 interrupted.
    """
    args = _parser().parse_args(argv)
    with warnings.catch_warnings():
        warnings.simplefilter("default")
        warnings.showwarning = _show_warning
        try:
            return args.func(args)
        except (DescriptionError, FileNotFoundError, ValueError, OSError) as exc:
            _err(f"robodyn: error: {' '.join(str(exc).split())}")
            return 2
        except KeyboardInterrupt:
            _err("robodyn: interrupted")
            return 130


if __name__ == "__main__":
    sys.exit(main())
