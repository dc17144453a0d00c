"""Kernel speed: vectorised, threaded and ensemble robodyn against peers measured in the same run.

Prints (PUMA 560, 100,000 random states, ns per state):
  0. Against Pinocchio (issue 22; ``kernel_peers.py``): inverse dynamics, forward dynamics and
     forward-dynamics derivatives on one thread, min and median of 7 rounds (the libraries take
     turns in each round, so that load from other processes hits all alike), robodyn (without
     friction, like for like, and with the PUMA's friction) against Pinocchio's templates
     compiled natively with robodyn's compiler and flags (``native_peer.py``,
     ``native/pinocchio_bench.cpp``, a C++ loop over the same states) and against the pip
     wheel as users get it (``rneaInParallel``/``abaInParallel`` on 1 thread, derivatives from
     a Python loop); every library's error against robodyn; the issue's targets against the
     native build (ID >= 25x, FD >= 25x, FD derivatives >= 15x) printed as met or not. Full
     runs merge these figures into ``benchmarks/results/<machine>.json`` (``results.py``),
     from which ``render_readme.py`` renders the README's table.
  1. Single thread: robodyn inverse dynamics (with the PUMA's joint friction, and a copy of the
     robot without friction) against CasADi-generated C of the same inverse dynamics
     (robodyn's recorded Newton-Euler program evaluated on CasADi SX symbols, ``CodeGenerator``
     C, compiled with robodyn's flags ``-O3 -march=native ...`` and driven by a C loop over the
     states, one state per call); mass matrix against ``crba`` called from Python (the no-op
     loop's own cost is measured and printed).
  2. Two threads: robodyn's ``threads=2`` against itself (scaling efficiency) and against
     ``rneaInParallel``/``abaInParallel`` on 2 threads. The machine may be shared: the ratios
     of one run are comparable, absolute times are not.
  3. Ensemble RK4: 1000 trolley double-pendulum trajectories of 5 s at 1 ms: one
     ``model.integrate`` call with x0 (1000, 6) against 1000 one-at-a-time calls and against
     MuJoCo's ``rollout`` with 1000 initial states (its own RK4 at 1 ms, one thread); and the
     same ensemble with one parameter set per trajectory (``compile_model(robot,
     runtime_parameters=True)``, ``integrate(..., parameters=(1000, 6))``) against the ensemble
     with the parameters compiled in (the cost of keeping them runtime inputs).

Run: ``.venv/bin/python benchmarks/bench_kernels.py [--quick] [--only pinocchio|kernels|ensemble]
[--results PATH | --no-results]``.
"""

from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path

import numpy as np
import sympy as sp

import robodyn as rd
from robodyn.codegen.build import CFLAGS, compile_library
from robodyn.numeric.model import _kernels_cached

sys.path.insert(0, str(Path(__file__).parent))
import kernel_peers  # noqa: E402
import results  # noqa: E402
from bench_simulation import pinocchio_puma, trolley_mjcf  # noqa: E402
from kernel_peers import without_friction  # noqa: E402
from timing import best_of  # noqa: E402


def casadi_inverse_dynamics(robot: rd.Robot):
    """CasADi C of robodyn's PUMA inverse-dynamics program, compiled with robodyn's flags.

    Returns ``run(q, qd, qdd, tau)``: a C loop calling CasADi's one-state function per state.
    """
    import casadi as ca

    kernel = _kernels_cached(robot, robot.parameters)["inverse_dynamics"]
    n = robot.dof
    q, qd, qdd = (ca.SX.sym(s, n) for s in ("q", "qd", "qdd"))
    env: dict[sp.Symbol, object] = {}
    for arg, sym in zip(kernel.inputs, (q, qd, qdd), strict=True):
        env.update({e: sym[k] for k, e in enumerate(arg.entries)})
    modules = [{"sin": ca.sin, "cos": ca.cos, "sqrt": ca.sqrt, "ifelse": ca.if_else}, "math"]
    ifelse = sp.Function("ifelse")

    def value(expr):
        # Coulomb friction's steps: CasADi's if_else (a select in the generated C)
        expr = expr.replace(lambda e: isinstance(e, sp.Piecewise),
                            lambda e: ifelse(e.args[0].cond, e.args[0].expr, e.args[1].expr))
        free = sorted(expr.free_symbols, key=lambda s: s.name)
        return sp.lambdify(free, expr, modules=modules)(*(env[s] for s in free))

    for sym, expr in kernel.body:
        env[sym] = value(expr)
    tau = ca.vertcat(*[value(sp.sympify(e)) for e in kernel.outputs[0].entries])
    f = ca.Function("cs_id", [q, qd, qdd], [tau])
    gen = ca.CodeGenerator("cs_id.c", {"with_header": False})
    gen.add(f)
    driver = f"""
void cs_id_batch(long count, const double *q, const double *qd, const double *qdd, double *tau) {{
    casadi_int iw[1]; casadi_real w[{f.sz_w()}];
    for (long k = 0; k < count; ++k) {{
        const casadi_real *arg[3] = {{q + {n} * k, qd + {n} * k, qdd + {n} * k}};
        casadi_real *res[1] = {{tau + {n} * k}};
        cs_id(arg, res, iw, w, 0);
    }}
}}
"""
    lib = compile_library(gen.dump() + driver,
                          "void cs_id_batch(long, const double *, const double *, const double *, double *);",
                          flags=CFLAGS)
    ffi = lib.ffi

    def run(qa, qda, qdda, out):
        lib.lib.cs_id_batch(len(qa), *(ffi.from_buffer("double[]", a) for a in (qa, qda, qdda, out)))

    return run, f.n_instructions()


def bench_kernels(quick: bool) -> None:
    import pinocchio as pin

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = rd.load("puma560")
    model = rd.compile_model(robot)
    rigid = rd.compile_model(without_friction(robot))
    count = 10_000 if quick else 100_000
    rng = np.random.default_rng(0)
    q, qd, qdd = rng.uniform(-np.pi, np.pi, (3, count, 6))
    tau = model.inverse_dynamics(q, qd, qdd)
    ns = 1e9 / count
    print(f"== PUMA 560, {count:,} states, ns per state (robodyn C: {' '.join(CFLAGS)}) ==")
    t = {
        "id": best_of(lambda: model.inverse_dynamics(q, qd, qdd), 7),
        "id_rigid": best_of(lambda: rigid.inverse_dynamics(q, qd, qdd), 7),
        "fd": best_of(lambda: model.forward_dynamics(q, qd, tau), 7),
        "fd_rigid": best_of(lambda: rigid.forward_dynamics(q, qd, tau), 7),
        "m": best_of(lambda: model.mass_matrix(q), 7),
        "id2": best_of(lambda: model.inverse_dynamics(q, qd, qdd, threads=2), 7),
        "fd2": best_of(lambda: model.forward_dynamics(q, qd, tau, threads=2), 7),
        "m2": best_of(lambda: model.mass_matrix(q, threads=2), 7),
    }
    pmodel, source = pinocchio_puma(robot)
    pdata = pmodel.createData()
    tau_rigid = rigid.inverse_dynamics(q, qd, qdd)
    d_id = max(np.max(np.abs(pin.rnea(pmodel, pdata, q[k], qd[k], qdd[k]) - tau_rigid[k])) for k in range(50))
    qt, qdt, qddt, taut = (np.asfortranarray(a.T) for a in (q, qd, qdd, tau_rigid))
    out = np.empty((6, count), order="F")
    for k in (1, 2):
        pool = pin.ModelPool(pmodel, k)
        t[f"pin_rnea{k}"] = best_of(lambda k=k, pool=pool: pin.rneaInParallel(k, pool, qt, qdt, qddt, out), 5)
        t[f"pin_aba{k}"] = best_of(lambda k=k, pool=pool: pin.abaInParallel(k, pool, qt, qdt, taut, out), 5)
    loops = min(count, 20_000)

    def crba_loop():
        for k in range(loops):
            pin.crba(pmodel, pdata, q[k])

    def noop_loop():
        for k in range(loops):
            _ = q[k]

    t["pin_crba"] = best_of(crba_loop, 3) * count / loops
    t["noop"] = best_of(noop_loop, 3) * count / loops
    run_cs, ops = casadi_inverse_dynamics(robot)
    run_cs_rigid, _ = casadi_inverse_dynamics(without_friction(robot))
    out_cs = np.empty((count, 6))
    run_cs(q, qd, qdd, out_cs)
    d_cs = np.max(np.abs(out_cs - model.inverse_dynamics(q, qd, qdd))) / np.max(np.abs(out_cs))
    t["cs"] = best_of(lambda: run_cs(q, qd, qdd, out_cs), 7)
    t["cs_rigid"] = best_of(lambda: run_cs_rigid(q, qd, qdd, out_cs), 7)
    print(f"Pinocchio {pin.__version__} ({source}) vs robodyn without friction: max |tau diff| = {d_id:.1e}")
    print(f"CasADi C of the same program: {ops} SX instructions, max rel. diff vs robodyn = {d_cs:.1e}")
    print(f"{'single thread':34s}{'robodyn':>9s}{'peer':>9s}{'ratio':>8s}  (target)")

    def row(label, ours, theirs, target=""):
        print(f"{label:34s}{ours * ns:9.1f}{theirs * ns:9.1f}{theirs / ours:7.1f}x  {target}")

    # robodyn against Pinocchio natively compiled and its wheel on one thread: bench_pinocchio
    row("ID (friction) / CasADi C", t["id"], t["cs"], ">= 3x")
    row("ID (no friction) / CasADi C", t["id_rigid"], t["cs_rigid"], "")
    row("M / crba from a Python loop", t["m"], t["pin_crba"],
        f"(the loop alone: {t['noop'] * ns:.0f} ns/state)")
    row("M / crba minus the loop", t["m"], t["pin_crba"] - t["noop"], "")
    print("two threads (machine shared: efficiency = t1 / (2 t2))")
    for name, pin_name in (("id", "pin_rnea"), ("fd", "pin_aba"), ("m", None)):
        eff = t[name] / (2 * t[name + "2"])
        line = f"  {name.upper():3s} robodyn {t[name + '2'] * ns:7.1f} ns/state, efficiency {eff:5.2f}"
        if pin_name:
            line += (f"; Pinocchio 2 threads {t[pin_name + '2'] * ns:7.1f} ns/state "
                     f"(efficiency {t[pin_name + '1'] / (2 * t[pin_name + '2']):.2f}), "
                     f"ratio {t[pin_name + '2'] / t[name + '2']:.1f}x")
        print(line)
    print()


def bench_ensemble(quick: bool) -> None:
    """Ensemble RK4 against one-at-a-time runs and MuJoCo's rollout; with parameter sets too."""
    import mujoco
    from mujoco import rollout

    robot = rd.load("trolley_double_pendulum")
    model = rd.compile_model(robot)
    count = 100 if quick else 1000
    steps, dt = 5000, 1e-3
    rng = np.random.default_rng(1)
    x0 = np.hstack([rng.uniform(-0.3, 0.3, (count, 3)), np.zeros((count, 3))])
    print(f"== Ensemble RK4: {count} trolley double-pendulum trajectories, 5 s at 1 ms ==")
    t_ens = best_of(lambda: model.integrate(x0, steps, dt), 3)
    t_ens2 = best_of(lambda: model.integrate(x0, steps, dt, threads=2), 3)

    def one_at_a_time():
        for x in x0:
            model.integrate(x, steps, dt)

    t_one = best_of(one_at_a_time, 2)
    # every trajectory with its own parameter set (masses, lengths, g): runtime parameters
    runtime = rd.compile_model(robot, runtime_parameters=True)
    base = np.array([robot.parameters[k] for k in runtime.runtime_parameters])
    sets = base * rng.uniform(0.8, 1.2, (count, base.size))
    t_par = best_of(lambda: runtime.integrate(x0, steps, dt, parameters=sets), 3)
    xml, source = trolley_mjcf(robot)
    mj = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(mj)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    states = np.zeros((count, mujoco.mj_stateSize(mj, spec)))
    for i in range(count):
        mujoco.mj_resetData(mj, data)
        data.qpos[:] = x0[i, :3]
        mujoco.mj_getState(mj, data, states[i], spec)
    rollout.rollout(mj, data, states[:2], nstep=10)
    t_mj = best_of(lambda: rollout.rollout(mj, data, states, nstep=steps), 2)
    per = 1e3 / count
    print(f"robodyn ensemble, one call, 1 thread   {t_ens * per:8.3f} ms per trajectory")
    print(f"robodyn ensemble, one call, 2 threads  {t_ens2 * per:8.3f} ms per trajectory "
          f"(efficiency {t_ens / (2 * t_ens2):.2f})")
    print(f"robodyn one integrate call each        {t_one * per:8.3f} ms per trajectory "
          f"({t_one / t_ens:.1f}x the ensemble)")
    print(f"robodyn ensemble, {count} parameter sets  {t_par * per:8.3f} ms per trajectory "
          f"({t_par / t_ens:.2f}x the ensemble with compiled-in parameters; runtime_parameters)")
    print(f"MuJoCo {mujoco.__version__} rollout, {count} initial states {t_mj * per:8.3f} ms per trajectory "
          f"({t_mj / t_ens:.1f}x the ensemble; model: {source})")
    print()


def bench_pinocchio(quick: bool, results_path: Path | None, command: str) -> None:
    """PUMA 560 ID, FD and FD derivatives against Pinocchio native and wheel (issue 22 targets).

    Parameters
    ----------
    quick : bool
        10,000 states and 3 rounds instead of 100,000 and 7.
    results_path : Path or None
        Results file to merge the figures into (benchmark name ``kernels``); None: not written.
    command : str
        The command line, recorded with the figures.
    """
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = rd.load("puma560")
    pmodel, source = pinocchio_puma(robot)
    count, repeats = (10_000, 3) if quick else (100_000, 7)
    entry = kernel_peers.measure(robot, pmodel, count, repeats)
    entry["pinocchio_model"] = f"{source}, with the PUMA's rotor inertia as armature"
    entry["command"] = command
    kernel_peers.print_entry(entry)
    if results_path is not None:
        print(f"figures written to {results.merge(results_path, 'kernels', entry)}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer states and trajectories")
    parser.add_argument("--only", choices=("pinocchio", "kernels", "ensemble"), action="append",
                        help="run only these sections (repeatable; default: all)")
    parser.add_argument("--results", type=Path, default=None,
                        help="results file for the Pinocchio figures (default: "
                             "benchmarks/results/<machine>.json on full runs, none with --quick)")
    parser.add_argument("--no-results", action="store_true", help="write no results file")
    args = parser.parse_args()
    sections = set(args.only or ("pinocchio", "kernels", "ensemble"))
    path = args.results or (None if args.quick else results.default_path())
    if "pinocchio" in sections:
        command = " ".join(["python benchmarks/bench_kernels.py", *(["--quick"] if args.quick else []),
                            *(f"--only {x}" for x in args.only or ())])
        bench_pinocchio(args.quick, None if args.no_results else path, command)
    if "kernels" in sections:
        bench_kernels(args.quick)
    if "ensemble" in sections:
        bench_ensemble(args.quick)


if __name__ == "__main__":
    main()
