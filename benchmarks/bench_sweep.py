"""AA300 sizing sweep: Dask (1 and 2 workers) vs a serial loop vs ProcessPoolExecutor, same batches.

    .venv/bin/python benchmarks/bench_sweep.py              # 600 cases, ~1-2 min on 2 cores
    .venv/bin/python benchmarks/bench_sweep.py --cases 20000 --batch 500   # the issue's size

Every case simulates the AA300 pick-and-place cycle (9.1 s at dt = 1 ms, RK4 in C) under PD +
gravity for a payload and PD bandwidth from a Latin hypercube. Workers are warmed up first (model
compiled/loaded, plan made), so the figures compare steady-state throughput. Printed: cases/s of
each, the 2-worker scaling ratio, and the Dask per-case overhead against a case's compute time
(1-worker Dask wall time vs the serial loop on the same cases; target < 5 %).
"""

from __future__ import annotations

import argparse
import time
from concurrent.futures import ProcessPoolExecutor

from robodyn.studies import LatinHypercube, expand_cases, run_batch, sweep
from robodyn.studies.models import RobotSource
from robodyn.studies.sizing import ActuatorSizing
from robodyn.studies.sweeps import batches, local_cluster


def _task() -> ActuatorSizing:
    return ActuatorSizing(RobotSource.of("aa300"), dt=1e-3)


def _warm(_: int) -> int:
    _task()({"payload": 0.0})
    return 0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", type=int, default=600)
    ap.add_argument("--batch", type=int, default=50)
    args = ap.parse_args()
    from distributed import Client

    task = _task()
    # one payload: the model is compiled once per worker; the bandwidth changes every case
    design = LatinHypercube({"bandwidth_hz": (2.0, 8.0), "zeta": (0.7, 1.0)}, n=args.cases, seed=0,
                            fixed={"payload": 50.0})
    cases = expand_cases(design, seed=0)
    parts = [[(i, cases[i]) for i in r] for r in batches(len(cases), args.batch)]
    print(f"{len(cases)} AA300 sizing cases, batches of {args.batch} ({len(parts)} tasks)")
    _warm(0)
    t0 = time.perf_counter()
    serial = [row for part in parts for row in run_batch(task, part)]
    t_serial = time.perf_counter() - t0
    per_case = t_serial / len(cases)
    print(f"serial loop           {t_serial:8.2f} s  {len(cases) / t_serial:8.1f} cases/s  "
          f"({per_case * 1e3:.2f} ms per case)")
    with ProcessPoolExecutor(2) as pool:
        list(pool.map(_warm, range(4)))
        t0 = time.perf_counter()
        pooled = [row for out in pool.map(run_batch, [task] * len(parts), parts) for row in out]
        t_pool = time.perf_counter() - t0
    assert pooled == serial
    print(f"ProcessPool, 2 procs  {t_pool:8.2f} s  {len(cases) / t_pool:8.1f} cases/s  "
          f"speed-up {t_serial / t_pool:.2f}x")
    walls = {}
    for n in (1, 2):
        with local_cluster(n) as cluster, Client(cluster, set_as_default=False) as client:
            client.run(_warm, 0)
            t0 = time.perf_counter()
            table = sweep(task, cases, client=client, batch=args.batch, seed=None)
            walls[n] = time.perf_counter() - t0
        assert table["error"].isna().all() and len(table) == len(cases)
        print(f"Dask, {n} worker{'s' if n > 1 else ' '}       {walls[n]:8.2f} s  "
              f"{len(cases) / walls[n]:8.1f} cases/s  speed-up {t_serial / walls[n]:.2f}x")
    print(f"scaling 2 vs 1 Dask workers: {walls[1] / walls[2]:.2f}x; Dask 2 workers vs ProcessPool: "
          f"{t_pool / walls[2]:.2f}x")
    overhead = (walls[1] - t_serial) / len(cases)
    print(f"Dask overhead per case (1 worker vs serial): {overhead * 1e3:+.3f} ms = "
          f"{100 * overhead / per_case:+.2f} % of a case's compute time (target < 5 %)")


if __name__ == "__main__":
    main()
