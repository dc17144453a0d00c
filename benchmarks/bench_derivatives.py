"""Analytic derivatives of the PUMA 560 dynamics against Pinocchio's wheel, measured in the same run.

robodyn: ``model.inverse_dynamics_derivatives`` (d tau/dq, d tau/dqd) and
``model.forward_dynamics_derivatives`` (d qdd/dq, d qdd/dqd, d qdd/dtau) on a batch of states,
one C call each, one thread. Pinocchio (the pip wheel as users get it):
``computeRNEADerivatives`` / ``computeABADerivatives`` called once per state from a Python loop
(the wheel has no batched ``*InParallel`` variant of its derivatives; the installed version's
names are checked and printed). The inverse and forward dynamics themselves (``rnea``, ``aba``
in the same loop) are timed beside them for scale.

A looped Pinocchio call costs more than its computation: the Python loop, and the binding's
own work (overload resolution, converting three NumPy vectors, building the returned tuple).
Three figures are measured in the same rounds to take them out:

* the Python loop alone: the same loop calling a Python no-op with the same arguments;
* the binding floor: the same loop calling ``pinocchio.forwardKinematics(model, data, q, v, a)``,
  the cheapest Pinocchio algorithm taking the same arguments, then reading ``data.ddq_dq``,
  ``data.ddq_dv`` and ``data.Minv`` (three NumPy views of ``Data``'s matrices, as the derivative
  functions return). Its time is the loop, the binding's argument handling, three views made
  and a forward kinematics pass with velocities and accelerations, which both derivative
  functions also perform; the views are read from Python (attribute lookups on top of what
  returning them from C++ costs). Subtracting it takes out more than the overhead, so the
  ratio "minus the binding floor" is a conservative figure (a lower bound) of robodyn's speed-up
  over Pinocchio's computation alone, as "minus the loop" is an upper bound (for the
  derivatives only: whole ``rnea`` and ``aba`` calls, timed for scale, cost about as much as
  the floor);
* the returned matrices: the binding returns views of ``Data``'s matrices (checked each run with
  ``np.shares_memory``), so no copy happens in the timed loop. Keeping each state's three
  matrices, as robodyn's batch output does, would cost three ``ndarray.copy()`` per call; that
  cost is measured and printed, not added to Pinocchio's time.

Not identical work, said in the output: robodyn's tau includes the PUMA description's joint
friction (viscous in d tau/dqd; the Coulomb step's derivative is 0 away from qd = 0, but its
value enters qdd = FD(q, qd, tau) where the forward derivatives are evaluated); Pinocchio has
none (more work on robodyn's side). Both include the reflected rotor inertia (Pinocchio's
armature). Agreement: d tau/dq equal, d tau/dqd equal once robodyn's viscous friction is taken
off its diagonal; the forward derivatives equal Pinocchio's at the rigid torque that gives the
same qdd (d qdd/dqd less M^-1 Fv). Against natively compiled Pinocchio (no Python, no binding)
the FD derivatives are timed by ``bench_kernels.py`` (issue 22's target), not here.

All rows take turns in each of the rounds (``timing.interleaved``); min and median over the
rounds. Target (issue 15): forward-dynamics derivatives at least 5x faster than
``computeABADerivatives``, judged on the lower bound (minus the binding floor). Full runs merge
the figures into ``benchmarks/results/<machine>.json`` (benchmark ``derivatives``).
Run: ``.venv/bin/python benchmarks/bench_derivatives.py [--quick] [--results PATH | --no-results]``.
"""

from __future__ import annotations

import argparse
import functools
import sys
import time
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

import robodyn as rd
from robodyn.codegen.build import applied_flags
from robodyn.numeric.model_cache import openmp_flags

sys.path.insert(0, str(Path(__file__).resolve().parent))
import results  # noqa: E402
import timing  # noqa: E402
from bench_simulation import pinocchio_puma  # noqa: E402 - sibling benchmark module
from peers import pinocchio_loop  # noqa: E402

#: Rows: robodyn's method and Pinocchio's function, per kernel.
KERNELS = {"RNEA derivatives": ("inverse_dynamics_derivatives", "computeRNEADerivatives"),
           "ABA derivatives": ("forward_dynamics_derivatives", "computeABADerivatives"),
           "inverse dynamics": ("inverse_dynamics", "rnea"),
           "forward dynamics": ("forward_dynamics", "aba")}
#: Issue 15: forward-dynamics derivatives at least this many times faster than Pinocchio's.
TARGET = 5.0
#: The binding floor: the cheapest Pinocchio algorithm called with (model, data, q, v, a), and
#: the three views of Data's matrices that computeABADerivatives returns, read from Python.
FLOOR_CALL = ("pinocchio.forwardKinematics(model, data, q, v, a); data.ddq_dq, data.ddq_dv, "
              "data.Minv")


def relative_error(theirs: np.ndarray, ours: np.ndarray) -> float:
    """``max |theirs - ours| / max |ours|``."""
    return float(np.max(np.abs(theirs - ours)) / np.max(np.abs(ours)))


def agreement(model: Any, pin: Any, pmodel: Any, pdata: Any, states: tuple[np.ndarray, ...],
              count: int = 20) -> dict[str, Any]:
    """robodyn's derivatives against Pinocchio's on the first ``count`` states (relative errors).

    robodyn has viscous friction Fv (estimated from d tau/dqd at qd = +-1e-3) and Coulomb
    friction: d tau/dqd - diag(Fv) is compared; the forward derivatives are compared with
    Pinocchio's at the rigid torque ``rnea(q, qd, qdd)`` that gives robodyn's qdd, d qdd/dqd
    with M^-1 diag(Fv) added back.
    """
    q, qd, qdd, tau = (a[:count] for a in states)
    n = q.shape[1]
    fv = np.diag(model.inverse_dynamics_derivatives(q[0], np.full(n, 1e-3), qdd[0])[1]
                 + model.inverse_dynamics_derivatives(q[0], np.full(n, -1e-3), qdd[0])[1]) / 2
    dq, dqd = model.inverse_dynamics_derivatives(q, qd, qdd)
    fq, fqd, ftau = model.forward_dynamics_derivatives(q, qd, tau)
    theirs: dict[str, list[np.ndarray]] = {k: [] for k in ("dq", "dqd", "fq", "fqd", "ftau")}
    for k in range(count):
        rq, rv, _ = (np.array(m) for m in pin.computeRNEADerivatives(pmodel, pdata, q[k], qd[k], qdd[k]))
        rigid = np.array(pin.rnea(pmodel, pdata, q[k], qd[k], qdd[k]))
        aq, av, minv = (np.array(m) for m in pin.computeABADerivatives(pmodel, pdata, q[k], qd[k], rigid))
        minv = np.triu(minv) + np.triu(minv, 1).T  # Pinocchio fills the upper triangle
        for key, value in zip(theirs, (rq, rv + np.diag(fv), aq, av - minv @ np.diag(fv), minv),
                              strict=True):
            theirs[key].append(value)
    mine = {"dq": dq, "dqd": dqd, "fq": fq, "fqd": fqd, "ftau": ftau}
    errors = {k: relative_error(np.array(theirs[k]), mine[k]) for k in mine}
    return {"states": count, "viscous_friction": [round(float(f), 4) for f in fv],
            "d_tau_d_q": errors["dq"], "d_tau_d_qd": errors["dqd"],
            "d_qdd_d_q": errors["fq"], "d_qdd_d_qd": errors["fqd"], "d_qdd_d_tau": errors["ftau"]}


def returns_views(pin: Any, pmodel: Any, pdata: Any, states: tuple[np.ndarray, ...]) -> dict[str, bool]:
    """Whether each derivative binding returns views of ``Data``'s matrices (no copies)."""
    q, qd, qdd, tau = (a[0] for a in states)
    rnea = pin.computeRNEADerivatives(pmodel, pdata, q, qd, qdd)
    rnea_views = all(np.shares_memory(a, b) for a, b in zip(
        rnea, (pdata.dtau_dq, pdata.dtau_dv, pdata.M), strict=True))
    aba = pin.computeABADerivatives(pmodel, pdata, q, qd, tau)
    aba_views = all(np.shares_memory(a, b) for a, b in zip(
        aba, (pdata.ddq_dq, pdata.ddq_dv, pdata.Minv), strict=True))
    return {"computeRNEADerivatives": bool(rnea_views), "computeABADerivatives": bool(aba_views)}


def timed_rows(model: Any, pin: Any, pmodel: Any, pdata: Any, states: tuple[np.ndarray, ...],
               loops: int) -> dict[str, Callable[[], Any]]:
    """Every row to time: robodyn's four kernels over all states, Pinocchio's over ``loops``
    states from Python, the no-op loop, the binding floor and the copies of returned matrices."""
    q, qd, qdd, tau = states
    args = {"RNEA derivatives": (q, qd, qdd), "ABA derivatives": (q, qd, tau),
            "inverse dynamics": (q, qd, qdd), "forward dynamics": (q, qd, tau)}

    def nothing(_model: Any, _data: Any, *_states: Any) -> None:
        return None

    views = pin.computeABADerivatives(pmodel, pdata, q[0], qd[0], tau[0])

    def copies() -> None:
        a, b, c = views
        for _ in range(loops):
            a.copy()
            b.copy()
            c.copy()

    def floor() -> None:  # as pinocchio_loop's body, then the three views made
        fk, arrays = pin.forwardKinematics, (q, qd, qdd)
        for k in range(loops):
            fk(pmodel, pdata, *(a[k] for a in arrays))
            (pdata.ddq_dq, pdata.ddq_dv, pdata.Minv)  # noqa: B018 - the views are the point

    fns: dict[str, Callable[[], Any]] = {}
    for kernel, (ours, theirs) in KERNELS.items():
        fns["robodyn " + kernel] = functools.partial(getattr(model, ours), *args[kernel])
        fns["pinocchio " + kernel] = pinocchio_loop(getattr(pin, theirs), pmodel, pdata, loops,
                                                    *args[kernel])
    fns["python loop"] = pinocchio_loop(nothing, pmodel, pdata, loops, q, qd, qdd)
    fns["binding floor"] = floor
    fns["three copies"] = copies
    return fns


def rows_of(times: dict[str, list[float]], count: int, loops: int) -> list[dict[str, Any]]:
    """One row per kernel: ns per state of both sides, Pinocchio's less the loop (the minimum of
    the no-op row taken off every round) and its ratio; for the derivatives also less the
    binding floor. Not for ``rnea``/``aba``: their whole calls cost about as much as the floor,
    so that difference says nothing."""
    loop, floor = min(times["python loop"]), min(times["binding floor"])
    out = []
    for kernel in KERNELS:
        ours = [t / count for t in times["robodyn " + kernel]]
        theirs = times["pinocchio " + kernel]
        less_loop = [(t - loop) / loops for t in theirs]
        row = {"kernel": kernel, "robodyn_ns": results.summary(ours, 1e9),
               "pinocchio_loop_ns": results.summary(theirs, 1e9 / loops),
               "minus_loop_ns": results.summary(less_loop, 1e9),
               "ratio": results.ratio([t / loops for t in theirs], ours, 1),
               "minus_loop_ratio": results.ratio(less_loop, ours, 1)}
        if kernel.endswith("derivatives"):
            less_floor = [(t - floor) / loops for t in theirs]
            row.update(minus_binding_floor_ns=results.summary(less_floor, 1e9),
                       minus_binding_floor_ratio=results.ratio(less_floor, ours, 1))
        out.append(row)
    return out


def peer_descriptions(pin_version: str, loops: int, source: str) -> dict[str, str]:
    """What each side is and how it differs from the other."""
    flags = " ".join(applied_flags(openmp_flags()))
    return {
        "robodyn": f"robodyn {rd.__version__}: generated C ({flags}), one call for "
                   "all states, 1 thread, the PUMA as described: rigid body, rotor inertia and "
                   "joint friction (viscous and Coulomb: more work than the peer)",
        "Pinocchio": f"Pinocchio {pin_version}, the pip wheel as users get it (generic build), "
                     f"1 thread, one call per state from a Python loop over {loops:,} states "
                     "(no batched derivatives in the wheel), rigid body and rotor inertia "
                     f"(armature), no friction; model from {source}"}


def measure(count: int, repeats: int) -> dict[str, Any]:
    """Run every row in ``repeats`` rounds on ``count`` random PUMA states; the results entry."""
    import pinocchio as pin

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = rd.load("puma560")
    model = rd.compile_model(robot)
    rng = np.random.default_rng(0)
    q, qd, qdd = rng.uniform(-np.pi, np.pi, (3, count, robot.dof))
    t0 = time.perf_counter()
    model.forward_dynamics_derivatives(q[:1], qd[:1], qdd[:1])  # generates/compiles on first use
    model.inverse_dynamics_derivatives(q[:1], qd[:1], qdd[:1])
    print(f"derivative kernels ready in {time.perf_counter() - t0:.1f} s (generated and compiled "
          "on first use, then cached)")
    states = (q, qd, qdd, model.inverse_dynamics(q, qd, qdd))
    pmodel, source = pinocchio_puma(robot)
    pdata = pmodel.createData()
    loops = min(count, 20_000)
    times = timing.interleaved(timed_rows(model, pin, pmodel, pdata, states, loops), repeats)
    rows = rows_of(times, count, loops)
    aba = next(r for r in rows if r["kernel"] == "ABA derivatives")
    value = aba["minus_binding_floor_ratio"]["min"]
    return {
        "states": count, "loops": loops, "repeats": repeats, "rows": rows,
        "python_loop_ns": results.summary(times["python loop"], 1e9 / loops),
        "binding_floor_ns": results.summary(times["binding floor"], 1e9 / loops),
        "binding_floor_call": FLOOR_CALL,
        "three_copies_ns": results.summary(times["three copies"], 1e9 / loops),
        "returns_views": returns_views(pin, pmodel, pdata, states),
        "agreement": agreement(model, pin, pmodel, pdata, states),
        "target": {"kernel": "ABA derivatives", "target": TARGET, "judged_on":
                   "minus_binding_floor_ratio", "value": value, "met": value >= TARGET},
        "pinocchio_batched": sorted(n for n in dir(pin) if n.endswith("InParallel")),
        "peers": peer_descriptions(pin.__version__, loops, source)}


def print_entry(e: dict[str, Any]) -> None:
    """The table, the overheads, the agreement and the target, for a person at the terminal."""
    for name, text in e["peers"].items():
        print(f"{name}: {text}")
    print(f"Pinocchio batched functions available: {', '.join(e['pinocchio_batched']) or 'none'} "
          "(no derivatives among them: the derivatives are looped from Python)")
    print(f"per call, min (median) of {e['repeats']} rounds: Python loop alone "
          f"{e['python_loop_ns']['min']:.0f} ({e['python_loop_ns']['median']:.0f}) ns; binding "
          f"floor {FLOOR_CALL} {e['binding_floor_ns']['min']:.0f} "
          f"({e['binding_floor_ns']['median']:.0f}) ns; three copies of the returned matrices "
          f"{e['three_copies_ns']['min']:.0f} ns (not added: the binding returns views: "
          f"{e['returns_views']})")
    print(f"{'kernel':18s}{'robodyn ns':>11s}{'pin loop ns':>12s}{'ratio':>8s}{'-loop ns':>10s}"
          f"{'ratio':>8s}{'-floor ns':>10s}{'ratio':>8s}   (min; ratios min / median)")
    for r in e["rows"]:
        line = (f"{r['kernel']:18s}{r['robodyn_ns']['min']:11.0f}{r['pinocchio_loop_ns']['min']:12.0f}"
                f"{r['ratio']['min']:7.1f}x{r['minus_loop_ns']['min']:10.0f}"
                f"{r['minus_loop_ratio']['min']:7.1f}x")
        if "minus_binding_floor_ns" in r:
            line += (f"{r['minus_binding_floor_ns']['min']:10.0f}"
                     f"{r['minus_binding_floor_ratio']['min']:7.1f}x   "
                     f"({r['minus_binding_floor_ratio']['median']:.1f}x median)")
        print(line)
    a = e["agreement"]
    print(f"agreement on {a['states']} states (relative): d tau/dq {a['d_tau_d_q']:.1e}, d tau/dqd "
          f"- diag(Fv) {a['d_tau_d_qd']:.1e}, d qdd/dq {a['d_qdd_d_q']:.1e}, d qdd/dqd "
          f"{a['d_qdd_d_qd']:.1e}, d qdd/dtau {a['d_qdd_d_tau']:.1e}")
    t = e["target"]
    print(f"forward-dynamics derivatives vs computeABADerivatives minus the binding floor (a lower "
          f"bound): {t['value']:.1f}x (target >= {t['target']:g}x): "
          f"{'met' if t['met'] else 'NOT met'}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="10,000 states and 3 rounds "
                        "instead of 100,000 and 7")
    results.add_options(parser)
    args = parser.parse_args()
    load_at_start = results.load_average()
    entry = measure(10_000 if args.quick else 100_000, 3 if args.quick else 7)
    print_entry(entry)
    path = results.target(args)
    if path is not None:
        command = " ".join(["python", "benchmarks/bench_derivatives.py", *sys.argv[1:]])
        results.merge(path, "derivatives", {"command": command,
                                            "load_average_at_start": load_at_start, **entry})
        print(f"results: {path}")


if __name__ == "__main__":
    main()
