"""Statement order and input transposition of the generated kernels, on this machine (issue 22).

robodyn prints each core's statements in an order that keeps few values live
(``robodyn.codegen.schedule``) and transposes a block's inputs by AVX shuffles
(``robodyn.codegen.c_transpose``). This benchmark generates the same models four ways (the
statements in CSE's order or scheduled; the transposition one double at a time or by shuffles)
and times each in one process, the builds taking turns:

* robots: the PUMA 560 (6 joints) and the Kinova Gen3 (7), as described (friction included),
  numeric parameters;
* kernels: inverse and forward dynamics, 50,000 random states, one thread, raw batch calls
  (no Python checks), each result checked against the first build to 1e-12 relative;
* builds: each source compiled with robodyn's model flags (OpenMP included, as every model) and
  with two alignment flags added (``-falign-functions=64``, ``-falign-jumps=64``): code layout
  alone moved some of these kernels by 10-25 % in the experiments behind the choices, so each
  row gives every layout's best time and their median.

Run: ``.venv/bin/python benchmarks/bench_schedule.py [--quick] [--results PATH | --no-results]``.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import warnings
from pathlib import Path

import numpy as np

import robodyn as rd
import robodyn.codegen.c as c_module
import robodyn.codegen.c_transpose as transpose
from robodyn.codegen.build import compile_library
from robodyn.numeric.model import openmp_flags
from robodyn.numeric.model_cache import _kernels_cached

sys.path.insert(0, str(Path(__file__).parent))
import results  # noqa: E402
import timing  # noqa: E402

ROBOTS = ("puma560", "kinova_gen3")
#: (label, statement order, vector transposition)
VARIANTS = (("CSE order, scalar transposition", "source", False),
            ("CSE order, AVX transposition", "source", True),
            ("scheduled, scalar transposition", "pressure", False),
            ("scheduled, AVX transposition (robodyn)", "pressure", True))
LAYOUTS = ((), ("-falign-functions=64",), ("-falign-jumps=64",))
KERNELS = {"ID": "inverse_dynamics", "FD": "forward_dynamics"}


def _source(robot: rd.Robot, order: str, vector: bool) -> tuple[str, str]:
    """The model's C source and declarations generated with the given choices."""
    saved = c_module.SCHEDULE, transpose.VECTOR
    c_module.SCHEDULE, transpose.VECTOR = order, vector
    try:
        kset = _kernels_cached(robot, {}, ())
        printer = c_module.CPrinter("rd_")
        return printer.source(kset), printer.declarations(kset)
    finally:
        c_module.SCHEDULE, transpose.VECTOR = saved


def run_robot(name: str, count: int, repeat: int) -> list[dict]:
    """Rows of one robot: per variant and kernel, each layout's min and the median of those."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = rd.load(name)
    rng = np.random.default_rng(0)
    q, qd, qdd = (rng.uniform(-1, 1, (count, robot.dof)) for _ in range(3))
    builds = {}
    for label, order, vector in VARIANTS:
        source, decl = _source(robot, order, vector)
        for k, extra in enumerate(LAYOUTS):
            builds[(label, k)] = compile_library(source, decl, flags=(*openmp_flags(), *extra))
    fns, outputs = {}, {}
    for key, lib in builds.items():
        for short, kernel in KERNELS.items():
            out = np.empty_like(q)
            ptrs = [lib.ffi.from_buffer("double[]", a) for a in (q, qd, qdd, out)]
            fn = getattr(lib.lib, f"rd_{kernel}_batch")
            fns[(*key, short)] = (lambda f=fn, p=ptrs: f(count, *p))
            outputs[(*key, short)] = out
    calls = {str(k): f for k, f in fns.items()}
    for f in calls.values():
        f()
    times = timing.interleaved(calls, repeat)
    rows = []
    for short in KERNELS:
        reference = outputs[(VARIANTS[0][0], 0, short)]
        for label, _, _ in VARIANTS:
            by_layout = [results.summary(times[str((label, k, short))], 1e9 / count)
                         for k in range(len(LAYOUTS))]
            best = [s["min"] for s in by_layout]
            worst_error = max(float(np.max(np.abs(outputs[(label, k, short)] - reference))
                                    / np.max(np.abs(reference))) for k in range(len(LAYOUTS)))
            rows.append({"robot": name, "kernel": short, "variant": label,
                         "ns_per_state_by_layout": by_layout,
                         "median_of_layout_minima": round(statistics.median(best), 1),
                         "max_rel_difference": worst_error})
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="fewer states and repeats")
    results.add_options(parser)
    args = parser.parse_args()
    count, repeat = (10_000, 3) if args.quick else (50_000, 9)
    load_at_start = results.load_average()
    rows = [row for name in ROBOTS for row in run_robot(name, count, repeat)]
    layouts = ", ".join("robodyn's flags" + (f" + {' '.join(x)}" if x else "") for x in LAYOUTS)
    print(f"ns per state, {count:,} states, 1 thread, min of {repeat} calls per build (and the "
          f"median of the builds' minima); builds: {layouts}")
    for row in rows:
        assert row["max_rel_difference"] < 1e-12, row
        per = " / ".join(f"{x['min']:6.1f}" for x in row["ns_per_state_by_layout"])
        print(f"{row['robot']:12s} {row['kernel']}  {row['variant']:40s} {per}   "
              f"median {row['median_of_layout_minima']:6.1f}")
    path = results.target(args)
    if path is not None:
        command = " ".join(["python", "benchmarks/bench_schedule.py", *sys.argv[1:]])
        results.merge(path, "schedule", {
            "command": command, "load_average_at_start": load_at_start, "states": count,
            "repeats": repeat, "layouts": [list(x) for x in LAYOUTS], "rows": rows,
            "load_average_at_end": results.load_average()})
        print(f"results: {path}")


if __name__ == "__main__":
    main()
