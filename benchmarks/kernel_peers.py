"""PUMA 560 kernels against Pinocchio natively compiled and as the wheel, in one run (issue 22).

Three kernels, one thread, the same random states for every library:

* ID: inverse dynamics ``tau(q, qd, qdd)``;
* FD: forward dynamics ``qdd(q, qd, tau)`` at ``tau`` = robodyn's frictionless ID;
* FD derivatives: ``d qdd/dq``, ``d qdd/dqd``, ``d qdd/dtau = M^-1`` at those states.

Libraries (every row says what differs):

* robodyn on a copy of the PUMA without friction (the reference of the ratios), and on the PUMA
  as described (viscous and Coulomb friction: more work, no peer has it);
* Pinocchio natively compiled (``native_peer.py``): its templates built with robodyn's compiler
  and optimisation flags, a C++ loop of one call per state, no friction;
* Pinocchio's wheel as pip installs it: ``rneaInParallel``/``abaInParallel`` with 1 thread (one
  call for the batch), and ``computeABADerivatives`` from a Python loop (it has no batched
  derivatives; the loop's own cost is measured and stated).

The libraries take turns: each of the ``repeats`` rounds times robodyn, then the native peer
(one process per round), then the wheel, each over all states, so that load from other
processes on a shared machine hits all of them alike; min and median are over the rounds.

Each library's outputs are checked against robodyn's frictionless model (max |difference| over
max |value|, all states for ID and FD, the first states for the derivatives). Run by
``bench_kernels.py``; nothing here is a unit test.
"""

from __future__ import annotations

import dataclasses
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

import robodyn as rd
from robodyn.codegen.build import applied_flags
from robodyn.numeric.model_cache import openmp_flags

sys.path.insert(0, str(Path(__file__).resolve().parent))
import native_peer  # noqa: E402
from peers import pinocchio_loop  # noqa: E402
from results import load_average, summary  # noqa: E402
from timing import interleaved  # noqa: E402

#: Issue 22's targets: robodyn (no friction) at least this many times faster than native Pinocchio.
TARGETS = {"ID": 25.0, "FD": 25.0, "FD derivatives": 15.0}
KERNELS = tuple(TARGETS)
#: Agreement required of every library with robodyn's frictionless model (relative).
TOLERANCE = 1e-9


@dataclasses.dataclass
class Row:
    """One library's timing of one kernel.

    Attributes
    ----------
    kernel : str
        ``"ID"``, ``"FD"`` or ``"FD derivatives"``.
    library : str
        Short name: ``robodyn``, ``robodyn (friction)``, ``pinocchio native``,
        ``pinocchio wheel``.
    seconds : list of float
        Wall time of each repeat.
    count : int
        States per timed repeat.
    error : float or None
        Max |output - robodyn frictionless| / max |robodyn|; None for the reference itself.
    note : str
        What differs for this kernel beyond the library's general description.
    """

    kernel: str
    library: str
    seconds: list[float]
    count: int
    error: float | None = None
    note: str = ""

    def ns(self) -> dict[str, float]:
        """Min and median ns per state."""
        return summary(self.seconds, 1e9 / self.count)


def relative_error(theirs: np.ndarray, ours: np.ndarray) -> float:
    """``max |theirs - ours| / max |ours|``."""
    return float(np.max(np.abs(theirs - ours)) / np.max(np.abs(ours)))


def without_friction(robot: rd.Robot) -> rd.Robot:
    """The same robot with every joint's friction removed (rigid body + rotor inertia only)."""
    joints = tuple(dataclasses.replace(j, friction=type(j.friction)()) for j in robot.joints)
    # the copy gets its own description_hash (the compiled-model cache key)
    return dataclasses.replace(robot, joints=joints, name=robot.name + "_nofriction")


def robodyn_setup(robot: rd.Robot, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray,
                  ) -> tuple[dict[tuple[str, str], Callable[[], Any]], dict[str, np.ndarray]]:
    """robodyn's three kernels with and without the PUMA's friction, ready to time.

    Returns
    -------
    fns : dict
        ``(kernel, library)`` to a callable over all states.
    reference : dict
        Frictionless ``tau``, ``qdd`` (FD at ``tau``) and ``d`` (N, n, 3n) derivatives.
    """
    rigid = rd.compile_model(without_friction(robot))
    model = rd.compile_model(robot)
    tau_r, tau_f = rigid.inverse_dynamics(q, qd, qdd), model.inverse_dynamics(q, qd, qdd)
    for m, t in ((rigid, tau_r), (model, tau_f)):  # generated and compiled on first use
        m.forward_dynamics_derivatives(q[:1], qd[:1], t[:1])
    # results into reused arrays (out=), as every peer writes into memory allocated once
    o_id, o_fd = np.empty_like(q), np.empty_like(q)
    o_d = np.empty(q.shape + (3 * q.shape[1],))
    fns = {
        ("ID", "robodyn"): lambda: rigid.inverse_dynamics(q, qd, qdd, out=o_id),
        ("FD", "robodyn"): lambda: rigid.forward_dynamics(q, qd, tau_r, out=o_fd),
        ("FD derivatives", "robodyn"):
            lambda: rigid.forward_dynamics_derivatives(q, qd, tau_r, out=o_d),
        ("ID", "robodyn (friction)"): lambda: model.inverse_dynamics(q, qd, qdd, out=o_id),
        ("FD", "robodyn (friction)"): lambda: model.forward_dynamics(q, qd, tau_f, out=o_fd),
        ("FD derivatives", "robodyn (friction)"):
            lambda: model.forward_dynamics_derivatives(q, qd, tau_f, out=o_d),
    }
    d = np.concatenate(rigid.forward_dynamics_derivatives(q, qd, tau_r), axis=-1)
    return fns, {"tau": tau_r, "qdd": rigid.forward_dynamics(q, qd, tau_r), "d": d}


def native_rows(seconds: dict[str, list[float]], out: native_peer.NativeRun,
                native: native_peer.NativeBuild, reference: dict[str, np.ndarray],
                ) -> tuple[list[Row], dict[str, Any]]:
    """Rows of natively compiled Pinocchio from its timings and its last run's outputs.

    Returns
    -------
    rows : list of Row
    info : dict
        Compiler, flags, header versions, and the WORLD-convention ``aba`` figure.
    """
    count, n = out.tau.shape
    ncheck = len(out.minv)
    d = reference["d"][:ncheck]
    d_err = max(relative_error(mine, d[..., k * n:(k + 1) * n])
                for k, mine in enumerate((out.ddq_dq, out.ddq_dv, out.minv)))
    world = summary(seconds["aba_world"], 1e9 / count)
    rows = [Row("ID", "pinocchio native", seconds["rnea"], count,
                relative_error(out.tau, reference["tau"]), "pinocchio::rnea"),
            Row("FD", "pinocchio native", seconds["aba"], count,
                relative_error(out.qdd, reference["qdd"]),
                f"pinocchio::aba, LOCAL convention (its default; WORLD: {world['min']:.0f} ns min)"),
            Row("FD derivatives", "pinocchio native", seconds["aba_derivatives"], count, d_err,
                f"pinocchio::computeABADerivatives, results left in Data; error on {ncheck} states")]
    info = {"compiler": f"{native.compiler} ({native.version})", "flags": list(native.flags),
            "headers": f"pin wheel's Pinocchio {out.versions['pinocchio']}, cmeel-eigen's "
                       f"Eigen {out.versions['eigen']}",
            "linked": "header-only (no libpinocchio*.so)", "cached_binary": native.cached,
            "aba_world_convention_ns": world}
    return rows, info


class WheelPeer:
    """The pip wheel as users call it: batch ``*InParallel`` on 1 thread, derivatives looped.

    Parameters
    ----------
    pmodel : pinocchio.Model
    states : tuple of ndarray (N, n)
        ``q, qd, qdd, tau``.
    loops : int
        States of the Python loop over ``computeABADerivatives``.
    """

    def __init__(self, pmodel: Any, states: tuple[np.ndarray, ...], loops: int) -> None:
        import pinocchio as pin

        self.pin, self.pmodel, self.states, self.loops = pin, pmodel, states, loops
        q, qd, _, tau = states
        qt, qdt, qddt, taut = (np.asfortranarray(a.T) for a in states)
        self.out_id, self.out_fd = (np.empty((q.shape[1], len(q)), order="F") for _ in range(2))
        pool = pin.ModelPool(pmodel, 1)
        self.pdata = pmodel.createData()

        def nothing(*_args: Any) -> None:
            return None

        self.fns = {
            "rnea": lambda: pin.rneaInParallel(1, pool, qt, qdt, qddt, self.out_id),
            "aba": lambda: pin.abaInParallel(1, pool, qt, qdt, taut, self.out_fd),
            "derivatives": pinocchio_loop(pin.computeABADerivatives, pmodel, self.pdata, loops,
                                          q, qd, tau),
            "loop": pinocchio_loop(nothing, pmodel, self.pdata, loops, q, qd, tau)}

    def rows(self, times: dict[str, list[float]], reference: dict[str, np.ndarray],
             ) -> tuple[list[Row], dict[str, Any]]:
        """Rows from the timings of :attr:`fns`, errors from the last outputs.

        Returns
        -------
        rows : list of Row
        info : dict
            The Python loop's own cost per call (ns) and the derivative figure without it.
        """
        q, qd, _, tau = self.states
        count, n, loops = len(q), q.shape[1], self.loops
        check = min(loops, 200)
        # the binding returns views of pdata's matrices, overwritten by the next call: copies
        derivs = np.array([[np.array(m) for m in self.pin.computeABADerivatives(
            self.pmodel, self.pdata, q[k], qd[k], tau[k])] for k in range(check)])
        derivs[:, 2] = np.triu(derivs[:, 2]) + np.swapaxes(np.triu(derivs[:, 2], 1), 1, 2)
        d_err = max(relative_error(derivs[:, i], reference["d"][:check, :, i * n:(i + 1) * n])
                    for i in range(3))
        loop_ns = summary(times["loop"], 1e9 / loops)
        bare = [t - min(times["loop"]) for t in times["derivatives"]]
        rows = [Row("ID", "pinocchio wheel", times["rnea"], count,
                    relative_error(self.out_id.T, reference["tau"]), "rneaInParallel(1 thread, batch)"),
                Row("FD", "pinocchio wheel", times["aba"], count,
                    relative_error(self.out_fd.T, reference["qdd"]), "abaInParallel(1 thread, batch)"),
                Row("FD derivatives", "pinocchio wheel", times["derivatives"], loops, d_err,
                    f"computeABADerivatives in a Python loop over {loops:,} states (no batched "
                    f"form; the loop alone {loop_ns['min']:.0f} ns per call, included)")]
        return rows, {"python_loop_ns": loop_ns,
                      "derivatives_minus_loop_ns": summary(bare, 1e9 / loops)}


def ratios(rows: list[Row]) -> list[dict[str, Any]]:
    """robodyn's speed-up over each peer, per kernel: peer time / robodyn time.

    The reference is robodyn without friction (like for like); the target of the issue applies
    to native Pinocchio and is judged on the minima (the least disturbed of the repeats).
    """
    out = []
    by = {(r.kernel, r.library): r.ns() for r in rows}
    for kernel in KERNELS:
        for ours in ("robodyn", "robodyn (friction)"):
            for peer in ("pinocchio native", "pinocchio wheel"):
                if (kernel, peer) not in by or (ours != "robodyn" and peer != "pinocchio native"):
                    continue
                a, b = by[kernel, ours], by[kernel, peer]
                entry = {"kernel": kernel, "robodyn": ours, "peer": peer,
                         "min": round(b["min"] / a["min"], 2),
                         "median": round(b["median"] / a["median"], 2)}
                if ours == "robodyn" and peer == "pinocchio native":
                    entry["target"] = TARGETS[kernel]
                    entry["met"] = entry["min"] >= TARGETS[kernel]
                out.append(entry)
    return out


def peer_descriptions(version: str, wheel_version: str) -> dict[str, str]:
    """What each library row is and how it differs from the others."""
    flags = " ".join(applied_flags(openmp_flags()))
    return {
        "robodyn": f"robodyn {version}: generated C ({flags}), one call for all "
                   "states into arrays allocated once (out=, as the peers' outputs), 1 thread, "
                   "friction: none (a copy of the PUMA without friction)",
        "robodyn (friction)": "the same with the PUMA's viscous and Coulomb joint friction "
                              "(more work than the peers, which have none)",
        "pinocchio native": "pinocchio native -O3 -march=native, same flags, 1 thread, friction: "
                            "none; its templates compiled here with robodyn's compiler and flags "
                            "(+ -std=c++17 -DNDEBUG), a C++ loop of one call per state",
        "pinocchio wheel": f"pinocchio wheel {wheel_version} as pip installs it (generic "
                           "build, libpinocchio_default.so), 1 thread, friction: none; called "
                           "from Python",
    }


def _rounds(fns: dict[Any, Callable[[], Any]], wheel: WheelPeer,
            runner: native_peer.NativeRunner | None, repeats: int, ncheck: int,
            ) -> tuple[dict[Any, list[float]], dict[str, list[float]], dict[str, list[float]],
                       native_peer.NativeRun | None]:
    """``repeats`` rounds, each library in turn (robodyn, native, wheel) over all states, so
    that a burst of load from other processes hits all of them alike.

    Returns
    -------
    robodyn, wheel, native : dict
        Wall seconds of each round per kernel.
    last : NativeRun or None
        The native peer's last run (outputs for the error check).
    """
    ours: dict[Any, list[float]] = {k: [] for k in fns}
    theirs: dict[str, list[float]] = {k: [] for k in wheel.fns}
    native: dict[str, list[float]] = {}
    last = None
    for _ in range(repeats):
        for k, t in interleaved(fns, 1).items():
            ours[k] += t
        if runner is not None:
            last = runner.run(1, ncheck)
            for k, t in last.seconds.items():
                native.setdefault(k, []).extend(t)
        for k, t in interleaved(wheel.fns, 1).items():
            theirs[k] += t
    return ours, theirs, native, last


def measure(robot: rd.Robot, pmodel: Any, count: int, repeats: int,
            log: Callable[[str], None] = print) -> dict[str, Any]:
    """Run every library on ``count`` random PUMA states; the results-file entry.

    Returns
    -------
    dict
        ``rows`` (kernel, library, ns min/median, error, note), ``ratios``, ``peers`` (what
        differs), ``native`` and ``wheel`` details, ``skipped`` (why the native peer is absent).
    """
    import pinocchio as pin

    start_load = load_average()
    rng = np.random.default_rng(0)
    q, qd, qdd = rng.uniform(-np.pi, np.pi, (3, count, 6))
    t0 = time.perf_counter()
    fns, reference = robodyn_setup(robot, q, qd, qdd)
    states = (q, qd, qdd, reference["tau"])
    entry: dict[str, Any] = {"states": count, "repeats": repeats,
                             "load_average_at_start": start_load, "skipped": None}
    wheel = WheelPeer(pmodel, states, min(count, 20_000))
    native = runner = None
    try:
        native = native_peer.build(log)
        runner = native_peer.NativeRunner(native, pmodel, states)
    except native_peer.NativeUnavailable as exc:
        entry["skipped"] = f"native Pinocchio peer skipped: {exc}"
        log(entry["skipped"])
    try:
        ours, theirs, native_times, last = _rounds(fns, wheel, runner, repeats, min(count, 1000))
    finally:
        if runner is not None:
            runner.__exit__()
    rows = [Row(kernel, lib, ours[kernel, lib], count) for kernel, lib in fns]
    if native is not None and last is not None:
        native_list, entry["native"] = native_rows(native_times, last, native, reference)
        rows += native_list
    wheel_list, entry["wheel"] = wheel.rows(theirs, reference)
    rows += wheel_list
    rows.sort(key=lambda r: KERNELS.index(r.kernel))  # stable: libraries keep their order
    entry["rows"] = [{"kernel": r.kernel, "library": r.library, "ns_per_state": r.ns(),
                      "states_timed": r.count, "max_rel_error": r.error, "note": r.note}
                     for r in rows]
    entry.update(ratios=ratios(rows), peers=peer_descriptions(rd.__version__, pin.__version__),
                 robodyn_flags=list(applied_flags(openmp_flags())), tolerance=TOLERANCE,
                 wall_s=round(time.perf_counter() - t0, 1))
    return entry


def print_entry(entry: dict[str, Any]) -> None:
    """Print the table, the ratios with the targets met or not, and what each peer differs in."""
    print(f"== PUMA 560 vs Pinocchio: {entry['states']:,} states, 1 thread, ns per state, "
          f"min / median of {entry['repeats']} rounds (load average at start "
          f"{' '.join(map(str, entry['load_average_at_start']))}) ==")
    print(f"{'kernel':16s}{'library':20s}{'min':>9s}{'median':>9s}  max rel. error vs robodyn")
    for r in entry["rows"]:
        err = "(reference)" if r["library"] == "robodyn" else (
            "(friction)" if r["max_rel_error"] is None else f"{r['max_rel_error']:.1e}")
        if r["max_rel_error"] is not None and r["max_rel_error"] > TOLERANCE:
            err += f" ABOVE {TOLERANCE:g}"
        print(f"{r['kernel']:16s}{r['library']:20s}{r['ns_per_state']['min']:9.1f}"
              f"{r['ns_per_state']['median']:9.1f}  {err}  {r['note']}")
    if entry["skipped"]:
        print(entry["skipped"])
    print("robodyn's speed-up, peer / robodyn, ratio of minima (of medians):")
    for x in entry["ratios"]:
        line = f"  {x['kernel']:16s}{x['robodyn']:20s}vs {x['peer']:18s}{x['min']:6.1f}x ({x['median']:.1f}x)"
        if "target" in x:
            line += f"  target >= {x['target']:g}x: {'met' if x['met'] else 'NOT met'}"
        print(line)
    wheel = entry["wheel"]
    print(f"  (wheel's derivative loop without the Python loop's own cost: "
          f"{wheel['derivatives_minus_loop_ns']['min']:.0f} ns per state)")
    for name, text in entry["peers"].items():
        print(f"  {name}: {text}")
    if entry.get("native"):
        print(f"  pinocchio native built by {entry['native']['compiler']}: "
              f"{' '.join(entry['native']['flags'])}; {entry['native']['headers']}, "
              f"{entry['native']['linked']}")
    print()
