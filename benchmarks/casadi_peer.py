"""CasADi-generated C of robodyn's PUMA 560 inverse dynamics, at its best (issue 22, item 1c).

The peer is robodyn's own recorded Newton-Euler program (the straight-line program robodyn
compiles, PUMA friction included: Coulomb steps become CasADi's ``if_else``) evaluated on
CasADi ``SX`` symbols, so that both sides compute the same arithmetic. CasADi's
``CodeGenerator`` writes C, which is compiled with robodyn's own compiler and flags
(``CFLAGS`` of robodyn's build module, ``-O3 ... -march=native``) and driven by a small C loop.

Evaluation strategies, each a row that says what differs from robodyn (one call for all states,
16-state blocks, polynomial sin/cos vectorised across states):

* ``per state``: a C loop calling CasADi's one-state function per state (libm ``sin``/``cos``);
* ``map serial``: ``f.map(N, "serial")``, CasADi's own batched evaluation, one call for all
  states (its generated loop around the one-state function);
* ``map 16 expanded``: ``f.map(16)`` expanded to one ``SX`` function of 16 states (the unrolled
  map as straight-line code the compiler may vectorise across states, like robodyn's blocks),
  called by a C loop over blocks of 16 states;
* ``sincos ...``: the same strategies with ``sin q`` and ``cos q`` as inputs, computed outside
  the timed call (NumPy, not timed): only the generated arithmetic is compared, not libm;
* ``map thread``: ``f.map(N, "thread", 2)`` on 2 threads (pthreads in the generated C),
  against robodyn with ``threads=2``.

Nothing here is a unit test; ``bench_kernels.py --only kernels`` runs it.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import sympy as sp

import robodyn as rd
from robodyn.codegen.build import CFLAGS, compile_library
from robodyn.numeric.model_cache import _kernels_cached

sys.path.insert(0, str(Path(__file__).resolve().parent))
from results import load_average, summary  # noqa: E402
from timing import interleaved  # noqa: E402

#: States per block of the expanded map (robodyn's kernels use 16-state blocks too).
BLOCK = 16


def compiler_flags() -> tuple[str, ...]:
    """robodyn's C compiler flags (without the OpenMP flag its threaded models add)."""
    return tuple(CFLAGS)


def casadi_function(robot: rd.Robot, sincos: bool = False) -> Any:
    """robodyn's inverse-dynamics program of ``robot`` as a one-state CasADi ``SX`` function.

    Parameters
    ----------
    robot : Robot
        Revolute joints only when ``sincos`` (every ``q`` must appear in ``sin``/``cos``).
    sincos : bool
        Inputs ``(sin q, cos q, qd, qdd)`` instead of ``(q, qd, qdd)``: ``sin(q_i)`` and
        ``cos(q_i)`` of the program are replaced by the inputs.

    Returns
    -------
    casadi.Function
        ``cs_id(...) -> tau``, each input and the output a column of ``robot.dof``.

    Raises
    ------
    ValueError
        With ``sincos``, a joint angle that the program uses outside ``sin(q_i)``/``cos(q_i)``.
    """
    import casadi as ca

    kernel = _kernels_cached(robot, robot.parameters)["inverse_dynamics"]
    n = robot.dof
    names = ("s", "c", "qd", "qdd") if sincos else ("q", "qd", "qdd")
    syms = [ca.SX.sym(s, n) for s in names]
    env: dict[sp.Symbol, Any] = {}
    trig: dict[sp.Expr, sp.Symbol] = {}
    q_entries = kernel.inputs[0].entries
    if sincos:
        for k, e in enumerate(q_entries):
            s_k, c_k = sp.Symbol(f"_sin_{k}"), sp.Symbol(f"_cos_{k}")
            trig[sp.sin(e)], trig[sp.cos(e)] = s_k, c_k
            env[s_k], env[c_k] = syms[0][k], syms[1][k]
        rest = zip(kernel.inputs[1:], syms[2:], strict=True)
    else:
        rest = zip(kernel.inputs, syms, strict=True)
    for arg, sym in rest:
        env.update({e: sym[k] for k, e in enumerate(arg.entries)})
    modules = [{"sin": ca.sin, "cos": ca.cos, "sqrt": ca.sqrt, "ifelse": ca.if_else}, "math"]
    ifelse = sp.Function("ifelse")

    def value(expr: sp.Expr) -> Any:
        # Coulomb friction's steps: CasADi's if_else (a select in the generated C)
        expr = expr.replace(lambda e: isinstance(e, sp.Piecewise),
                            lambda e: ifelse(e.args[0].cond, e.args[0].expr, e.args[1].expr))
        expr = expr.xreplace(trig)
        free = sorted(expr.free_symbols, key=lambda s: s.name)
        if sincos and any(s in q_entries for s in free):
            raise ValueError(f"a joint angle outside sin/cos in {expr}: no sin/cos-input variant")
        return sp.lambdify(free, expr, modules=modules)(*(env[s] for s in free))

    for sym, expr in kernel.body:
        env[sym] = value(sp.sympify(expr))
    tau = ca.vertcat(*[value(sp.sympify(e)) for e in kernel.outputs[0].entries])
    return ca.Function("cs_id", syms, [tau])


_DRIVER = """
#include <stdlib.h>
int cs_batch(long count, const double **in, double *out) {{
    const casadi_real *arg[{sz_arg}]; casadi_real *res[{sz_res}];
    casadi_int iw[{sz_iw}];
    casadi_real *w = (casadi_real *)malloc(sizeof(casadi_real) * {sz_w});
    int ret = 0;
    if (!w) return -1;
    for (long k = 0; k + {block} <= count && !ret; k += {block}) {{
        for (int i = 0; i < {n_in}; ++i) arg[i] = in[i] + {n} * k;
        res[0] = out + {n} * k;
        ret = {name}(arg, res, iw, w, 0);
    }}
    free(w);
    return ret;
}}
"""


@dataclass
class Strategy:
    """One compiled evaluation strategy of the CasADi function.

    Attributes
    ----------
    name : str
        Row label, e.g. ``"CasADi map serial"``.
    run : callable
        ``run(inputs, out)``: evaluates all states (``inputs``: arrays (N, n), C order).
    instructions : int
        ``n_instructions()`` of the one-state function (CasADi's count of SX operations).
    note : str
        What differs from robodyn's call.
    threads : int
        Threads the strategy uses.
    """

    name: str
    run: Callable[[Sequence[np.ndarray], np.ndarray], None]
    instructions: int
    note: str
    threads: int = 1


def compile_strategy(f: Any, mode: str, count: int, threads: int = 1) -> Callable[..., None]:
    """Generate C for ``f`` evaluated by ``mode`` and compile it with robodyn's flags.

    Parameters
    ----------
    f : casadi.Function
        The one-state function.
    mode : {"per state", "map serial", "map 16 expanded", "map thread"}
        See the module's docstring.
    count : int
        States per call (fixed in the generated map; a multiple of :data:`BLOCK`).
    threads : int
        Threads of ``"map thread"``.

    Returns
    -------
    callable
        ``run(inputs, out)``.
    """
    import casadi as ca

    if count % BLOCK:
        raise ValueError(f"count must be a multiple of {BLOCK}, got {count}")
    g, block = {
        "per state": (lambda: f, 1),
        "map serial": (lambda: f.map(count, "serial"), count),
        "map 16 expanded": (lambda: f.map(BLOCK, "serial").expand(), BLOCK),
        "map thread": (lambda: f.map(count, "thread", threads), count),
    }[mode]
    fn = g()
    gen = ca.CodeGenerator("cs_peer.c", {"with_header": False})
    gen.add(fn)
    n = f.size1_out(0)
    driver = _DRIVER.format(sz_arg=max(fn.sz_arg(), 1), sz_res=max(fn.sz_res(), 1),
                            sz_iw=max(fn.sz_iw(), 1), sz_w=max(fn.sz_w(), 1), block=block,
                            n_in=f.n_in(), n=n, name=fn.name())
    lib = compile_library(gen.dump() + driver,
                                    "int cs_batch(long, const double **, double *);",
                                    flags=compiler_flags())
    ffi = lib.ffi

    def run(inputs: Sequence[np.ndarray], out: np.ndarray) -> None:
        bufs = [ffi.from_buffer("double[]", a) for a in inputs]
        ptrs = ffi.new("const double *[]", [ffi.cast("const double *", b) for b in bufs])
        if lib.lib.cs_batch(len(out), ptrs, ffi.from_buffer("double[]", out)):
            raise RuntimeError(f"CasADi {mode} evaluation failed")

    return run


def strategies(robot: rd.Robot, count: int, threads: int = 2) -> list[Strategy]:
    """Every CasADi row of the benchmark, compiled (cached by robodyn's build cache).

    Parameters
    ----------
    robot : Robot
        The PUMA 560 as described (with friction).
    count : int
        States per call.
    threads : int
        Threads of the ``map thread`` row.

    Returns
    -------
    list of Strategy
    """
    f, f_sc = casadi_function(robot), casadi_function(robot, sincos=True)
    libm = "libm sin/cos per state"
    outside = "sin q, cos q computed by NumPy outside the timed call (not timed): arithmetic only"
    rows = [
        ("CasADi per state", f, "per state", f"C loop, one call per state (no batching), {libm}"),
        ("CasADi map serial", f, "map serial",
         f'f.map(N, "serial"): CasADi\'s batched call, its loop over states, {libm}'),
        ("CasADi map 16 expanded", f, "map 16 expanded",
         f'f.map(16).expand(): 16 states as straight-line SX code, a C loop over blocks, {libm}'),
        ("CasADi sincos map serial", f_sc, "map serial", f'f.map(N, "serial"); {outside}'),
        ("CasADi sincos map 16 expanded", f_sc, "map 16 expanded",
         f"f.map(16).expand(), C loop over blocks; {outside}"),
    ]
    out = [Strategy(name, compile_strategy(fn, mode, count), fn.n_instructions(), note)
           for name, fn, mode, note in rows]
    out.append(Strategy("CasADi map thread", compile_strategy(f, "map thread", count, threads),
                        f.n_instructions(),
                        f'f.map(N, "thread", {threads}): {threads} pthreads in the generated C, '
                        f"{libm}; against robodyn threads={threads}", threads))
    return out


def inputs_for(strategy: Strategy, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray,
               ) -> list[np.ndarray]:
    """The arrays a strategy takes: ``(q, qd, qdd)`` or ``(sin q, cos q, qd, qdd)``."""
    if "sincos" in strategy.name:
        return [np.ascontiguousarray(np.sin(q)), np.ascontiguousarray(np.cos(q)), qd, qdd]
    return [q, qd, qdd]


def measure(robot: rd.Robot, count: int, repeats: int) -> dict[str, Any]:
    """Time robodyn's inverse dynamics and every CasADi strategy in turns; the results entry.

    Parameters
    ----------
    robot : Robot
        The PUMA 560 as described (with its joint friction: the same program on both sides).
    count : int
        Random states (uniform in [-pi, pi]); a multiple of :data:`BLOCK`.
    repeats : int
        Rounds; in each, every row is timed once over all states (turns spread load alike).

    Returns
    -------
    dict
        ``rows`` (library, threads, ns per state min/median, max relative error against
        robodyn, note), ``ratios`` (row / robodyn on the same number of threads), ``peers``,
        ``states``, ``repeats``, ``flags``, ``casadi_version``, ``instructions``.
    """
    import casadi as ca

    start_load = load_average()
    model = rd.compile_model(robot)
    rng = np.random.default_rng(0)
    q, qd, qdd = rng.uniform(-np.pi, np.pi, (3, count, robot.dof))
    reference = model.inverse_dynamics(q, qd, qdd)
    fns: dict[str, Callable[[], Any]] = {
        "robodyn": lambda: model.inverse_dynamics(q, qd, qdd),
        "robodyn 2 threads": lambda: model.inverse_dynamics(q, qd, qdd, threads=2)}
    errors: dict[str, float | None] = {"robodyn": None, "robodyn 2 threads": None}
    found = strategies(robot, count)
    for s in found:
        out, args = np.empty_like(reference), inputs_for(s, q, qd, qdd)
        s.run(args, out)
        errors[s.name] = float(np.max(np.abs(out - reference)) / np.max(np.abs(reference)))
        fns[s.name] = lambda s=s, args=args, out=out: s.run(args, out)
    times = interleaved(fns, repeats)
    notes = {"robodyn": "Model.inverse_dynamics: one call for all states, 16-state blocks, "
                        "vectorised polynomial sin/cos of q inside the timed call, 1 thread",
             "robodyn 2 threads": "the same with threads=2 (OpenMP)"}
    threads = {"robodyn": 1, "robodyn 2 threads": 2}
    for s in found:
        notes[s.name], threads[s.name] = s.note, s.threads
    rows = [{"library": name, "threads": threads[name],
             "ns_per_state": summary(t, 1e9 / count), "max_rel_error": errors[name],
             "note": notes[name]} for name, t in times.items()]
    by = {r["library"]: r["ns_per_state"] for r in rows}
    ratios = []
    for r in rows:
        if r["library"].startswith("CasADi"):
            ours = by["robodyn" if r["threads"] == 1 else "robodyn 2 threads"]
            ratios.append({"peer": r["library"], "threads": r["threads"],
                           "min": round(r["ns_per_state"]["min"] / ours["min"], 2),
                           "median": round(r["ns_per_state"]["median"] / ours["median"], 2)})
    return {"states": count, "repeats": repeats, "load_average_at_start": start_load,
            "robot": "puma560 as described (viscous and Coulomb joint friction, both sides)",
            "flags": list(compiler_flags()), "casadi_version": ca.__version__,
            "instructions": {"one state": found[0].instructions,
                             "one state, sin/cos inputs": found[3].instructions},
            "rows": rows, "ratios": ratios}


def print_entry(entry: dict[str, Any]) -> None:
    """Print the CasADi table: ns per state, error, speed-up of robodyn and what differs."""
    print(f"== PUMA 560 inverse dynamics vs CasADi {entry['casadi_version']} C "
          f"({entry['states']:,} states, ns per state, min / median of {entry['repeats']} rounds; "
          f"C flags {' '.join(entry['flags'])}) ==")
    ratio = {r["peer"]: r for r in entry["ratios"]}
    for r in entry["rows"]:
        ns, err = r["ns_per_state"], r["max_rel_error"]
        x = ratio.get(r["library"])
        err_text = "reference" if err is None else f"err {err:.1e}"
        speed = f"{x['min']:5.1f}x ({x['median']:.1f}x)" if x else ""
        print(f"  {r['library']:30s}{ns['min']:9.1f}{ns['median']:9.1f}  {err_text:12s}"
              f"{speed:16s}{r['note']}")
    print()
