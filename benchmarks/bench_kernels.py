"""Kernel speed: vectorised, threaded and ensemble robodyn against peers measured in the same run.

Prints (PUMA 560, 100,000 random states, ns per state):
  0. Against Pinocchio (issue 22; ``kernel_peers.py``): inverse dynamics, forward dynamics and
     forward-dynamics derivatives on one thread, min and median of 20 rounds (the libraries take
     turns in each round, so that load from other processes hits all alike), robodyn (without
     friction, like for like, and with the PUMA's friction) against Pinocchio's templates
     compiled natively with robodyn's compiler and flags (``native_peer.py``,
     ``native/pinocchio_bench.cpp``, a C++ loop over the same states) and against the pip
     wheel as users get it (``rneaInParallel``/``abaInParallel`` on 1 thread, derivatives from
     a Python loop); every library's error against robodyn; the issue's targets against the
     native build (ID >= 25x, FD >= 25x, FD derivatives >= 15x) printed as met or not. Full
     runs merge these figures into ``benchmarks/results/<machine>.json`` (``results.py``),
     from which ``render_readme.py`` renders the README's table.
  1. ``--only kernels``, single thread (``casadi_peer.py``, issue 22 item 1c): robodyn's
     inverse dynamics (the PUMA with its joint friction) against CasADi-generated C of the same
     program (robodyn's recorded Newton-Euler program evaluated on CasADi SX symbols,
     ``CodeGenerator`` C compiled with robodyn's flags ``-O3 ... -march=native``) evaluated
     per state, by CasADi's batched ``map`` (serial; 16 states expanded into one SX function),
     with ``sin q``/``cos q`` as precomputed inputs (the generated arithmetic only, not libm),
     and by ``map(N, "thread", 2)`` against robodyn on 2 threads; then robodyn's ``threads=2``
     against itself (scaling efficiency) and Pinocchio's ``rneaInParallel``/``abaInParallel``
     on 1 and 2 threads, and the mass matrix against ``crba`` called from Python (the no-op
     loop's own cost is measured). Results entries ``casadi`` and ``threads``.
  2. ``--only ensemble``: 1000 trolley double-pendulum trajectories of 5 s, RK4 at 1 ms: one
     ``rd.rollout`` call with x0 (1000, 6) on 1 and 2 threads, against 1000
     one-at-a-time calls, against the same ensemble with one parameter set per trajectory
     (``compile_model(robot, runtime_parameters=True)``, ``rollout(..., parameters=(1000,
     6))``), and against MuJoCo's ``rollout`` from the same 1000 initial states (its own RK4 at
     1 ms, contacts disabled) on 1 thread and on its 2-thread pool. Results entry ``ensemble``.

Every section times its rows in turns (``timing.interleaved``: each round runs every row once,
so that load from other processes hits all alike) and records min and median over the rounds.
The machine may be shared: the ratios of one run are comparable, absolute times less so. Full
runs merge the figures into ``benchmarks/results/<machine>.json`` (``results.py``); ``--quick``
(10,000 states, 3 rounds, 100 trajectories) writes only with ``--results PATH``, and its
command line, recorded with the figures, says so.

Run: ``.venv/bin/python benchmarks/bench_kernels.py [--quick] [--only pinocchio|kernels|ensemble]
[--results PATH | --no-results]``.
"""

from __future__ import annotations

import argparse
import sys
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

import robodyn as rd

sys.path.insert(0, str(Path(__file__).parent))
import casadi_peer  # noqa: E402
import kernel_peers  # noqa: E402
import results  # noqa: E402
import timing  # noqa: E402
from bench_simulation import pinocchio_puma, trolley_mjcf  # noqa: E402
from peers import pinocchio_loop  # noqa: E402


def _puma() -> rd.Robot:
    """The built-in PUMA 560 (its load-time warnings silenced)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return rd.load("puma560")


def threads_and_crba(robot: rd.Robot, count: int, repeats: int) -> dict[str, Any]:
    """Two-thread scaling (robodyn and Pinocchio's wheel) and the mass matrix against ``crba``.

    Returns
    -------
    dict
        The ``threads`` results entry: ``efficiency`` per kernel and library (t1 / (2 t2) of the
        minima), ns per state min/median for every timing, the Python loop's own cost.
    """
    import pinocchio as pin

    start_load = results.load_average()
    model = rd.compile_model(robot)
    rng = np.random.default_rng(0)
    q, qd, qdd = rng.uniform(-np.pi, np.pi, (3, count, 6))
    tau = model.inverse_dynamics(q, qd, qdd)
    pmodel, _ = pinocchio_puma(robot)
    pdata = pmodel.createData()
    qt, qdt, qddt, taut = (np.asfortranarray(a.T) for a in (q, qd, qdd, tau))
    out = np.empty((6, count), order="F")
    fns: dict[str, Callable[[], Any]] = {}
    for k in (1, 2):
        fns[f"robodyn ID {k}"] = lambda k=k: model.inverse_dynamics(q, qd, qdd, threads=k)
        fns[f"robodyn FD {k}"] = lambda k=k: model.forward_dynamics(q, qd, tau, threads=k)
        fns[f"robodyn M {k}"] = lambda k=k: model.mass_matrix(q, threads=k)
        pool = pin.ModelPool(pmodel, k)
        fns[f"pinocchio wheel ID {k}"] = (
            lambda k=k, pool=pool: pin.rneaInParallel(k, pool, qt, qdt, qddt, out))
        fns[f"pinocchio wheel FD {k}"] = (
            lambda k=k, pool=pool: pin.abaInParallel(k, pool, qt, qdt, taut, out))
    loops = min(count, 20_000)
    loop_fns = {"crba loop": pinocchio_loop(pin.crba, pmodel, pdata, loops, q),
                "python loop": pinocchio_loop(lambda *_: None, pmodel, pdata, loops, q)}
    t = timing.interleaved(fns, repeats)
    t.update(timing.interleaved(loop_fns, repeats))
    ns = {k: results.summary(v, 1e9 / (loops if "loop" in k else count)) for k, v in t.items()}
    bare = [a - min(t["python loop"]) for a in t["crba loop"]]
    ns["crba minus loop"] = results.summary(bare, 1e9 / loops)
    eff = {f"{lib} {kern}": round(ns[f"{lib} {kern} 1"]["min"] / (2 * ns[f"{lib} {kern} 2"]["min"]), 2)
           for lib in ("robodyn", "pinocchio wheel") for kern in ("ID", "FD", "M")
           if f"{lib} {kern} 1" in ns}
    return {"states": count, "repeats": repeats, "load_average_at_start": start_load,
            "ns_per_state": ns, "efficiency": eff, "loop_states": loops,
            "mass_matrix_vs_crba": {
                "with_loop": round(ns["crba loop"]["min"] / ns["robodyn M 1"]["min"], 2),
                "minus_loop": round(ns["crba minus loop"]["min"] / ns["robodyn M 1"]["min"], 2)},
            "peers": {"robodyn": "Model methods with threads=1 and threads=2 (OpenMP), PUMA "
                                 "friction included in ID and FD",
                      "pinocchio wheel": f"pinocchio {pin.__version__} wheel: rneaInParallel / "
                                         "abaInParallel with 1 and 2 threads (no friction); crba "
                                         f"called per state from a Python loop over {loops:,} "
                                         "states (no batched form), the loop's own cost measured "
                                         "around a no-op"}}


def print_threads(entry: dict[str, Any]) -> None:
    """Print the two-thread efficiencies and the mass matrix against ``crba``."""
    ns = entry["ns_per_state"]
    print(f"== two threads (efficiency t1 / (2 t2) of the minima; machine shared) and M vs crba, "
          f"{entry['states']:,} states ==")
    for name, eff in entry["efficiency"].items():
        print(f"  {name:22s} 1 thread {ns[name + ' 1']['min']:8.1f}  2 threads "
              f"{ns[name + ' 2']['min']:8.1f} ns/state  efficiency {eff:.2f}")
    m = entry["mass_matrix_vs_crba"]
    print(f"  M {ns['robodyn M 1']['min']:.1f} ns/state; crba from a Python loop "
          f"{ns['crba loop']['min']:.0f} ({m['with_loop']:.1f}x), minus the loop's own "
          f"{ns['python loop']['min']:.0f} ns: {m['minus_loop']:.1f}x")
    print()


def bench_kernels(quick: bool, results_path: Path | None, command: str) -> None:
    """CasADi peers of the inverse dynamics, two-thread scaling and M against ``crba``.

    Parameters
    ----------
    quick : bool
        10,000 states and 3 rounds instead of 100,000 and 7.
    results_path : Path or None
        Results file (benchmark names ``casadi`` and ``threads``); None: not written.
    command : str
        The command line, recorded with the figures.
    """
    robot = _puma()
    count, repeats = (10_000, 3) if quick else (100_000, 7)
    entry = casadi_peer.measure(robot, count, repeats)
    casadi_peer.print_entry(entry)
    threads = threads_and_crba(robot, count, repeats)
    print_threads(threads)
    if results_path is not None:
        for name, e in (("casadi", entry), ("threads", threads)):
            print(f"figures written to {results.merge(results_path, name, {**e, 'command': command})}")


def _mujoco_states(mj: Any, x0: np.ndarray) -> np.ndarray:
    """MuJoCo full-physics initial states with ``qpos`` = the first half of each row of ``x0``."""
    import mujoco

    data = mujoco.MjData(mj)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    states = np.zeros((len(x0), mujoco.mj_stateSize(mj, spec)))
    n = x0.shape[1] // 2
    for i, x in enumerate(x0):
        mujoco.mj_resetData(mj, data)
        data.qpos[:], data.qvel[:] = x[:n], x[n:]
        mujoco.mj_getState(mj, data, states[i], spec)
    return states


def bench_ensemble(quick: bool, results_path: Path | None, command: str) -> None:
    """Ensemble RK4 against one-at-a-time runs and MuJoCo's rollout; with parameter sets too.

    Parameters
    ----------
    quick : bool
        100 trajectories instead of 1000.
    results_path : Path or None
        Results file (benchmark name ``ensemble``); None: not written.
    command : str
        The command line, recorded with the figures.
    """
    import mujoco
    from mujoco import rollout

    start_load = results.load_average()
    robot = rd.load("trolley_double_pendulum")
    model = rd.compile_model(robot)
    count, steps, dt, repeats = (100 if quick else 1000), 5000, 1e-3, 3
    rng = np.random.default_rng(1)
    x0 = np.hstack([rng.uniform(-0.3, 0.3, (count, 3)), np.zeros((count, 3))])
    runtime = rd.compile_model(robot, runtime_parameters=True)
    base = np.array([robot.parameters[k] for k in runtime.runtime_parameters])
    sets = base * rng.uniform(0.8, 1.2, (count, base.size))
    xml, source = trolley_mjcf(robot)
    mj = mujoco.MjModel.from_xml_string(xml)
    states = _mujoco_states(mj, x0)
    datas = [mujoco.MjData(mj) for _ in range(2)]
    mj_states, _ = rollout.rollout(mj, datas[0], states, nstep=steps)
    opts, opts2 = rd.RolloutOptions(steps, dt), rd.RolloutOptions(steps, dt, threads=2)
    xs, _ = rd.rollout(model, x0, opts)
    agree = float(np.max(np.abs(mj_states[:, :, 1:4] - xs[:, 1:, :3])))

    def one_at_a_time() -> None:
        for x in x0:
            rd.rollout(model, x, opts)

    fns = {"robodyn ensemble": lambda: rd.rollout(model, x0, opts),
           "robodyn ensemble 2 threads": lambda: rd.rollout(model, x0, opts2),
           "robodyn one call each": one_at_a_time,
           "robodyn parameter sets": lambda: rd.rollout(runtime, x0, opts, parameters=sets),
           "MuJoCo rollout": lambda: rollout.rollout(mj, datas[0], states, nstep=steps),
           "MuJoCo rollout 2 threads": lambda: rollout.rollout(mj, datas, states, nstep=steps)}
    times = timing.interleaved(fns, repeats)
    rows = [{"library": k, "ms_per_trajectory": results.summary(v, 1e3 / count, 3),
             "threads": 2 if "2 threads" in k else 1} for k, v in times.items()]
    by = {r["library"]: r["ms_per_trajectory"] for r in rows}
    for r in rows:
        ref = by["robodyn ensemble 2 threads" if r["threads"] == 2 else "robodyn ensemble"]
        r["vs_ensemble"] = {"min": round(r["ms_per_trajectory"]["min"] / ref["min"], 2),
                            "median": round(r["ms_per_trajectory"]["median"] / ref["median"], 2)}
    entry = {
        "trajectories": count, "steps": steps, "dt": dt, "repeats": repeats,
        "load_average_at_start": start_load, "rows": rows,
        "mujoco_agreement_rad": agree, "mujoco_model": source, "command": command,
        "peers": {
            "robodyn": "rd.rollout: RK4 at 1 ms in generated C, x0 (N, 6), one call for the "
                       "ensemble (threads=1, or threads=2 with OpenMP); 'one call each': N calls "
                       "with one x0; 'parameter sets': compile_model(runtime_parameters=True), "
                       "one set of the 6 parameters per trajectory (x0.8-1.2)",
            "MuJoCo": f"MuJoCo {mujoco.__version__} mujoco.rollout.rollout from the same initial "
                      "states: its RK4 at the same 1 ms, contacts disabled, no friction (none "
                      "modelled), the full mj_step pipeline per stage, full-physics state "
                      "recorded every step; 1 MjData (1 thread) or a list of 2 (its thread "
                      "pool, 2 threads)"}}
    print(f"== Ensemble RK4: {count} trolley double-pendulum trajectories, 5 s at 1 ms, "
          f"ms per trajectory, min / median of {repeats} rounds ==")
    for r in rows:
        t, x = r["ms_per_trajectory"], r["vs_ensemble"]
        print(f"  {r['library']:28s}{t['min']:9.3f}{t['median']:9.3f}  {x['min']:6.2f}x "
              f"({x['median']:.2f}x) the robodyn ensemble on {r['threads']} thread(s)")
    print(f"  |q_MuJoCo - q_robodyn| over all trajectories and steps: {agree:.1e} (model: {source})")
    print()
    if results_path is not None:
        print(f"figures written to {results.merge(results_path, 'ensemble', entry)}")


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
    # many rounds: on a shared machine the minimum is the least disturbed one
    count, repeats = (10_000, 3) if quick else (100_000, 20)
    entry = kernel_peers.measure(robot, pmodel, count, repeats)
    entry["pinocchio_model"] = f"{source}, with the PUMA's rotor inertia as armature"
    entry["command"] = command
    kernel_peers.print_entry(entry)
    if results_path is not None:
        print(f"figures written to {results.merge(results_path, 'kernels', entry)}")


def main() -> None:
    """Command line: run the chosen sections, merge their figures into the results file."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer states and trajectories")
    parser.add_argument("--only", choices=("pinocchio", "kernels", "ensemble"), action="append",
                        help="run only these sections (repeatable; default: all)")
    results.add_options(parser)
    args = parser.parse_args()
    sections = set(args.only or ("pinocchio", "kernels", "ensemble"))
    path = results.target(args)
    command = " ".join(["python benchmarks/bench_kernels.py", *(["--quick"] if args.quick else []),
                        *(f"--only {x}" for x in args.only or ())])
    if "pinocchio" in sections:
        bench_pinocchio(args.quick, path, command)
    if "kernels" in sections:
        bench_kernels(args.quick, path, command)
    if "ensemble" in sections:
        bench_ensemble(args.quick, path, command)

if __name__ == "__main__":
    main()
