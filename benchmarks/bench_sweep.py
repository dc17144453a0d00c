"""AA300 sizing sweep: Dask (1 and 2 workers) vs a serial loop vs ProcessPoolExecutor, same batches.

    .venv/bin/python benchmarks/bench_sweep.py                    # 600 cases, about 1.5 min on 2 cores
    .venv/bin/python benchmarks/bench_sweep.py --cases 600 20000  # and the issue's size (25-40 min)

Every case simulates the AA300 pick-and-place cycle (9.1 s at dt = 1 ms, RK4 in C) under PD +
gravity for a payload and PD bandwidth from a Latin hypercube. The four runners take turns in
each round, each on the same batches: a serial loop in this process, ``ProcessPoolExecutor``
with 2 processes, and Dask (``robodyn.studies.sweep`` on the library's own ``local_cluster``:
single-threaded worker processes) with 1 and with 2 workers. The pool and both clusters are
started and warmed up (model compiled/loaded, plan made) before the first round and stay up,
idle while the others run, so the figures compare steady-state throughput. Printed per size:
wall time and cases/s of each (min / median over the rounds), the 2-worker scaling, Dask
against ProcessPoolExecutor, and the Dask per-case overhead against a case's compute time
(1-worker Dask wall time against the serial loop on the same cases; target < 5 %).

Full runs merge the figures of every size run into ``benchmarks/results/<machine>.json``
(benchmark ``sweep``). ``--quick``: 120 cases, 3 rounds, written only with ``--results``.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
import warnings
from concurrent.futures import ProcessPoolExecutor
from contextlib import ExitStack
from pathlib import Path
from typing import Any

from robodyn.studies import LatinHypercube, expand_cases, run_batch, sweep
from robodyn.studies.models import RobotSource
from robodyn.studies.sizing import ActuatorSizing
from robodyn.studies.sweeps import batches, local_cluster

sys.path.insert(0, str(Path(__file__).resolve().parent))
import results  # noqa: E402

#: Target of the Dask per-case overhead, % of a case's compute time.
TARGET_OVERHEAD_PERCENT = 5.0
#: The 20,000-case figure of an earlier run, quoted where this run did not measure that size.
QUOTED_20000 = {"cases": 20000, "scaling_2_vs_1": 1.86,
                "source": "README.md as of commit de9dc7f (2026-12-01), quoted by hand from an "
                          "earlier run on a quiet 2-core AVX-512 machine"}
RUNNERS = ("serial loop", "ProcessPool, 2 processes", "Dask, 1 worker", "Dask, 2 workers")
PEERS = {
    "serial loop": "`run_batch` over the batches in the benchmark's own process, no "
                   "scheduling at all: the compute time",
    "ProcessPool, 2 processes": "`concurrent.futures.ProcessPoolExecutor(2)` mapping `run_batch` "
                                "over the same batches (pickled task and cases, no retries, "
                                "no result table)",
    "Dask": "`robodyn.studies.sweep` on `local_cluster(n)` (single-threaded worker processes, "
            "glibc's malloc defaults) with the same batches: scheduling, retries of lost "
            "workers, and the result table (a pandas DataFrame) included; its scheduler runs "
            "in the benchmark's process, beside the workers on the same cores"}


def _task() -> ActuatorSizing:
    return ActuatorSizing(RobotSource.of("aa300"), dt=1e-3)


def _warm(_: int) -> int:
    _task()({"payload": 0.0})
    return 0


def _timed(fn: Any) -> tuple[float, Any]:
    """Wall time of ``fn()``, s, and its result."""
    t0 = time.perf_counter()
    out = fn()
    return time.perf_counter() - t0, out


def one_size(n: int, batch: int, rounds: int) -> dict[str, Any]:
    """The four runners on ``n`` cases, taking turns for ``rounds`` rounds; the size's entry.

    The pool and both clusters are started and warmed up once, before the first round, and
    stay up (idle) while the others run.
    """
    from distributed import Client

    task = _task()
    # one payload: the model is compiled once per worker; the bandwidth changes every case
    design = LatinHypercube({"bandwidth_hz": (2.0, 8.0), "zeta": (0.7, 1.0)}, n=n, seed=0,
                            fixed={"payload": 50.0})
    cases = expand_cases(design, seed=0)
    parts = [[(i, cases[i]) for i in r] for r in batches(len(cases), batch)]
    print(f"\n{len(cases)} AA300 sizing cases, batches of {batch} ({len(parts)} tasks), "
          f"{rounds} rounds")
    _warm(0)
    t: dict[str, list[float]] = {k: [] for k in RUNNERS}
    with ExitStack() as stack:
        pool = stack.enter_context(ProcessPoolExecutor(2))
        list(pool.map(_warm, range(4)))
        clients = {}
        for w in (1, 2):
            scratch = stack.enter_context(tempfile.TemporaryDirectory())
            with warnings.catch_warnings():  # another cluster's HTTP port: a line, no harm
                warnings.filterwarnings("ignore", "Port .* is already in use")
                cluster = stack.enter_context(local_cluster(w, scratch))
            clients[w] = stack.enter_context(Client(cluster, set_as_default=False))
            clients[w].run(_warm, 0)
        for _ in range(rounds):
            wall, serial = _timed(lambda: [row for part in parts for row in run_batch(task, part)])
            t["serial loop"].append(wall)
            wall, pooled = _timed(lambda: [row for out in pool.map(
                run_batch, [task] * len(parts), parts) for row in out])
            assert pooled == serial
            t["ProcessPool, 2 processes"].append(wall)
            for w, client in clients.items():
                wall, table = _timed(lambda c=client: sweep(task, cases, client=c, batch=batch,
                                                            seed=None))
                assert table["error"].isna().all() and len(table) == len(cases)
                t[f"Dask, {w} worker{'s' if w > 1 else ''}"].append(wall)
    return _size_entry(t, len(cases), batch, len(parts), rounds)


def _size_entry(t: dict[str, list[float]], n: int, batch: int, tasks: int, rounds: int,
                ) -> dict[str, Any]:
    """The entry of one size from its wall times; prints it."""
    serial, dask1 = t["serial loop"], t["Dask, 1 worker"]
    overhead = {"min": 100 * (min(dask1) / min(serial) - 1),
                "median": 100 * (statistics.median(dask1) / statistics.median(serial) - 1)}
    entry = {
        "cases": n, "batch": batch, "tasks": tasks, "rounds": rounds,
        "seconds": {k: results.summary(v, 1, 3) for k, v in t.items()},
        "ms_per_case_serial": results.summary(serial, 1e3 / n, 3),
        "speed_up_vs_serial": {k: results.ratio(serial, v) for k, v in t.items()},
        "scaling_2_vs_1": results.ratio(dask1, t["Dask, 2 workers"]),
        "dask2_vs_pool": results.ratio(t["ProcessPool, 2 processes"], t["Dask, 2 workers"]),
        "overhead_ms_per_case": {k: round(v / 100 * m, 4) for (k, v), m in zip(
            overhead.items(), (min(serial) * 1e3 / n, statistics.median(serial) * 1e3 / n),
            strict=True)},
        "overhead_percent": {k: round(v, 2) for k, v in overhead.items()},
        "target_overhead_percent": TARGET_OVERHEAD_PERCENT}
    for k, s in entry["seconds"].items():
        print(f"  {k:<26}{s['min']:8.2f} s (median {s['median']:7.2f})  {n / s['min']:8.1f} "
              f"cases/s  speed-up {entry['speed_up_vs_serial'][k]['min']:.2f}x")
    sc, dp, oh = entry["scaling_2_vs_1"], entry["dask2_vs_pool"], entry["overhead_percent"]
    print(f"  scaling 2 vs 1 Dask workers: {sc['min']:.2f}x (median {sc['median']:.2f}x); "
          f"Dask 2 workers vs ProcessPool: {dp['min']:.2f}x")
    print(f"  Dask overhead per case (1 worker vs serial, minima): "
          f"{entry['overhead_ms_per_case']['min']:+.3f} ms = {oh['min']:+.2f} % of a case's "
          f"compute time ({entry['ms_per_case_serial']['min']:.2f} ms; median {oh['median']:+.2f} "
          f"%; target < {TARGET_OVERHEAD_PERCENT:g} %: "
          f"{'met' if oh['min'] < TARGET_OVERHEAD_PERCENT else 'NOT met'})")
    return entry


def main() -> None:
    """Command line: every size asked for, then the results file."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", type=int, nargs="+", default=None,
                    help="sizes to run (default 600; 20000 is the issue's size: 25-40 min on 2 "
                         "cores)")
    ap.add_argument("--batch", type=int, default=None,
                    help="cases per task (default 50, 500 from 10,000 cases up)")
    ap.add_argument("--rounds", type=int, default=3, help="rounds (at least 3)")
    ap.add_argument("--quick", action="store_true", help="120 cases, 3 rounds")
    results.add_options(ap)
    args = ap.parse_args()
    sizes = args.cases or ([120] if args.quick else [600])
    rounds = 3 if args.quick else max(3, args.rounds)
    command = "python benchmarks/bench_sweep.py" + (" --quick" if args.quick else "")
    if args.cases:
        command += " --cases " + " ".join(map(str, sizes))
    if args.batch:
        command += f" --batch {args.batch}"
    if rounds != 3:
        command += f" --rounds {rounds}"
    entry: dict[str, Any] = {"command": command, "load_average_at_start": results.load_average(),
                             "task": "AA300 pick-and-place cycle, 9.1 s at dt = 1 ms, RK4 in "
                                     "robodyn's C, PD + gravity, 50 kg payload, PD bandwidth "
                                     "and damping from a Latin hypercube",
                             "peers": PEERS, "sizes": []}
    for n in sizes:
        batch = args.batch or (500 if n >= 10_000 else 50)
        entry["sizes"].append(one_size(n, batch, rounds))
    if all(s["cases"] != QUOTED_20000["cases"] for s in entry["sizes"]):
        # how long that size would take here: this run's median rates, as many rounds
        last = entry["sizes"][-1]
        per_round = sum(v["median"] for v in last["seconds"].values())
        entry["quoted"] = {**QUOTED_20000, "run_with": "--cases 600 20000",
                           "expected_minutes": round(per_round * QUOTED_20000["cases"]
                                                     / last["cases"] * rounds / 60)}
    path = results.target(args)
    if path is not None:
        print(f"figures written to {results.merge(path, 'sweep', entry)}")


if __name__ == "__main__":
    main()
