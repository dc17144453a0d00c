"""Sweep fault drill: 10,000 cases on a local cluster, one worker killed, one case crashing its worker.

    .venv/bin/python benchmarks/bench_sweep_faults.py                      # 10,000 cases, 3 workers
    .venv/bin/python benchmarks/bench_sweep_faults.py --cases 2000 --workers 2 --no-serial

Each case sizes the actuators of the planar 2R arm (``robodyn.studies.ActuatorSizing``: a trapezoidal
move, PD + gravity compensation, RK4 in C at 1 ms, about 1 ms per case) for a payload on a grid and
a bandwidth and damping from a Latin hypercube. One case (the middle one) dereferences a null
pointer through ctypes every time it runs: a segfault in compiled code, which kills its worker
process. When a quarter of the cases have finished, one worker process is killed with SIGKILL by
its PID. The sweep runs with the default batching (``robodyn.studies.sweeps.default_batch``) and
ships the compiled models to the workers.

Printed: the cases finished, failed (with the crashing case's message), duplicated (delivered by
more than one finished batch, or twice in the table), missing; the worker processes that ran
cases; the wall time of the sweep; and whether every finished case equals a serial loop in this
process bit for bit (``--no-serial`` skips that loop).
"""

from __future__ import annotations

import argparse
import ctypes
import os
import signal
import time
from collections import Counter
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from robodyn.studies import LatinHypercube, case_seed, expand_cases, run_serial, sweep
from robodyn.studies.models import ModelSpec, RobotSource
from robodyn.studies.sizing import ActuatorSizing
from robodyn.studies.sweeps import default_batch, local_cluster


@dataclass(frozen=True)
class Crashing:
    """``task`` with the worker's PID added; the case whose seed is ``crash_seed`` segfaults."""

    task: ActuatorSizing
    crash_seed: int

    def __call__(self, case: Mapping[str, Any]) -> dict[str, Any]:
        if case["seed"] == self.crash_seed:
            ctypes.string_at(0)  # SIGSEGV: reads address 0
        return {**self.task(case), "pid": os.getpid()}

    def compiled_models(self, cases: Sequence[Mapping[str, Any]]) -> list[ModelSpec]:
        """The sizing task's models (shipped to the workers)."""
        return self.task.compiled_models(cases)


def _task() -> ActuatorSizing:
    return ActuatorSizing(RobotSource.of("planar_2r"), trajectory="trapezoid", q_start=(0.0, 0.0),
                          q_goal=(0.5, -0.3), vmax=(1.0, 1.0), amax=(2.0, 2.0), dt=1e-3, settle=0.3)


class Killer:
    """``on_batch``: counts deliveries per case; SIGKILLs one worker once ``after`` cases finished."""

    def __init__(self, client: Any, after: int) -> None:
        self.client, self.after = client, after
        self.seen: Counter[int] = Counter()
        self.killed: list[int] = []

    def __call__(self, rows: list[tuple[int, dict[str, Any], str | None]]) -> None:
        self.seen.update(index for index, _, _ in rows)
        if not self.killed and len(self.seen) >= self.after:
            pids = sorted(self.client.run(os.getpid, on_error="ignore").values())
            os.kill(pids[0], signal.SIGKILL)
            self.killed.append(pids[0])
            print(f"  killed worker PID {pids[0]} (SIGKILL) after {len(self.seen)} finished cases")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", type=int, default=10_000)
    ap.add_argument("--workers", type=int, default=3)
    ap.add_argument("--no-serial", action="store_true", help="skip the serial comparison")
    args = ap.parse_args()
    from distributed import Client

    design = LatinHypercube({"bandwidth_hz": (1.0, 3.0), "zeta": (0.7, 1.0)}, n=args.cases // 2, seed=0,
                            grid={"payload": [0.0, 0.5]})
    cases = expand_cases(design, seed=0)
    crash = len(cases) // 2
    task = Crashing(_task(), case_seed(0, crash))
    with local_cluster(args.workers) as cluster, Client(cluster, set_as_default=False) as client:
        batch = default_batch(len(cases), sum(client.nthreads().values()))
        print(f"{len(cases)} planar 2R sizing cases, {args.workers} worker processes, batches of "
              f"{batch} ({-(-len(cases) // batch)} tasks); case {crash} segfaults its worker")
        killer = Killer(client, len(cases) // 4)
        t0 = time.perf_counter()
        table = sweep(task, design, client=client, seed=0, on_batch=killer)
        wall = time.perf_counter() - t0
    failed = table[table["error"].notna()]
    twice = sum(1 for n in killer.seen.values() if n > 1) + int(table.index.duplicated().sum())
    missing = len(cases) - len(set(table.index))
    print(f"finished {int(table['error'].isna().sum())}, failed {len(failed)}, duplicated {twice}, "
          f"missing {missing}; wall time {wall:.1f} s ({len(cases) / wall:.0f} cases/s)")
    for index, message in failed["error"].items():
        print(f"  failed case {index}: {str(message)[:160]}")
    print(f"worker processes that ran cases: {table['pid'].dropna().nunique()} (killed: {killer.killed})")
    if not args.no_serial:
        t0 = time.perf_counter()
        serial = run_serial(task.task, [c for i, c in enumerate(cases) if i != crash], seed=None)
        serial.index = [i for i in range(len(cases)) if i != crash]
        ok = table.drop(index=crash).drop(columns=["pid", "error"])
        same = ok.equals(serial.rename_axis("case")[ok.columns]) and serial["error"].isna().all()
        print(f"serial loop {time.perf_counter() - t0:.1f} s; finished cases equal it bit for bit: {same}")


if __name__ == "__main__":
    main()
