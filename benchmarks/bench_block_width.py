"""Block width of the generated kernels on this machine, for AVX-512 and AVX2 code (issue 22 item 3).

robodyn's batch kernels evaluate a block of states at a time (``robodyn.codegen.cpu``): 16 where
the CPU has AVX-512, else 8; ``ROBODYN_BLOCK`` overrides it. This benchmark checks that choice
on the machine it runs on: the PUMA 560's inverse and forward dynamics (with its friction,
100,000 random states, one thread) generated at each block width and compiled

* with robodyn's own flags (``-march=native``: the code this CPU gets), and
* with ``-march=haswell`` added last (AVX2 and FMA, no AVX-512: the code an AVX2 CPU gets; run
  on this CPU, so the row shows AVX2 code on this core, not an AVX2 processor).

Each (flags, width) pair is a separate process (the width is fixed at generation, in the
source), compiled into a temporary cache; the processes run in several passes in which the
pairs take turns, each timing a few calls; min and median over all calls. Every width's
results are checked against scalar code (width 1) to 1e-12 relative.

Run: ``.venv/bin/python benchmarks/bench_block_width.py [--quick] [--results PATH | --no-results]``.
"""

from __future__ import annotations

import argparse
import json
import os
import shlex
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
import results  # noqa: E402

#: Widths tried (robodyn.codegen.cpu.WIDTHS but 2: between scalar and 4 it says nothing new).
WIDTHS = (1, 4, 8, 16, 32)

#: Flag sets: label -> flags appended to robodyn's (None: robodyn's own, -march=native).
ISAS = {"native": None, "avx2": ("-march=haswell", "-mtune=haswell")}

_WORKER = """
import json, sys, warnings
import numpy as np
sys.path.insert(0, sys.argv[1])
import timing
import robodyn as rd
with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    robot = rd.load("puma560")
model = rd.compile_model(robot)
count, repeat = int(sys.argv[2]), int(sys.argv[3])
rng = np.random.default_rng(0)
q, qd, qdd = (rng.uniform(-1, 1, (count, robot.dof)) for _ in range(3))
tau = model.inverse_dynamics(q, qd, qdd, threads=1)
model.forward_dynamics(q[:64], qd[:64], tau[:64], threads=1)
t = timing.interleaved({"ID": lambda: model.inverse_dynamics(q, qd, qdd, threads=1),
                        "FD": lambda: model.forward_dynamics(q, qd, tau, threads=1)}, repeat)
check = {"tau": tau[:200].tolist(), "qdd": model.forward_dynamics(q[:200], qd[:200], tau[:200]).tolist()}
import os
from robodyn.codegen.build import compiler_flags, find_compiler
from robodyn.codegen.cpu import BLOCK
print(json.dumps({"times": t, "check": check, "block": BLOCK,
                  "added": list(compiler_flags(os.environ.get("CC") or find_compiler(), BLOCK))}))
"""


def _compiler_wrapper(folder: Path, extra: tuple[str, ...]) -> str:
    """A ``CC`` script that runs the real compiler with ``extra`` flags after robodyn's (named
    ``...-gcc`` when that compiler is GCC, so that robodyn adds GCC's flags as for GCC itself:
    :func:`robodyn.codegen.build.compiler_flags`)."""
    from robodyn.codegen.build import compiler_flags, find_compiler

    real = find_compiler()
    gcc = "-gcc" if compiler_flags(real, 1) else ""
    script = folder / f"cc-{'-'.join(f.strip('-') for f in extra)}{gcc}"
    script.write_text(f'#!/bin/sh\nexec {shlex.quote(real)} "$@" {" ".join(extra)}\n')
    script.chmod(0o755)
    return str(script)


def _run_worker(width: int, cc: str | None, cache: Path, count: int, repeat: int) -> dict:
    """One process: generate, compile (or find in ``cache``) and time at ``width``."""
    env = {**os.environ, "ROBODYN_BLOCK": str(width), "ROBODYN_CACHE": str(cache)}
    if cc is not None:
        env["CC"] = cc
    out = subprocess.run([sys.executable, "-c", _WORKER, str(Path(__file__).parent), str(count),
                          str(repeat)], env=env, check=True, capture_output=True, text=True)
    got = json.loads(out.stdout.splitlines()[-1])
    if got["block"] != width:
        raise SystemExit(f"ROBODYN_BLOCK={width} gave kernels of width {got['block']}")
    return got


def sweep(count: int, passes: int, repeat: int) -> tuple[list[dict], float]:
    """Time every (flags, width) pair; rows and the largest deviation from scalar code."""
    times: dict[tuple[str, int], dict[str, list[float]]] = {}
    added: dict[tuple[str, int], list[str]] = {}
    reference, deviation = None, 0.0
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        ccs = {isa: None if extra is None else _compiler_wrapper(folder, extra)
               for isa, extra in ISAS.items()}
        for k in range(passes):
            pairs = [(isa, w) for isa in ISAS for w in WIDTHS]
            for isa, width in (pairs if k % 2 == 0 else pairs[::-1]):  # turns, both orders
                out = _run_worker(width, ccs[isa], folder / "cache", count, repeat)
                slot = times.setdefault((isa, width), {"ID": [], "FD": []})
                added[(isa, width)] = out["added"]
                for kernel in slot:
                    slot[kernel] += out["times"][kernel]
                got = {key: np.array(v) for key, v in out["check"].items()}
                if reference is None:
                    reference = got
                for key, ref in reference.items():
                    deviation = max(deviation, float(np.max(np.abs(got[key] - ref))
                                                     / np.max(np.abs(ref))))
    rows = [{"isa": isa, "width": w, "added_flags": added[(isa, w)],
             **{kernel: results.summary(t, 1e9 / count, 1) for kernel, t in slot.items()}}
            for (isa, w), slot in sorted(times.items(), key=lambda kv: (list(ISAS).index(kv[0][0]),
                                                                        kv[0][1]))]
    return rows, deviation


def _best(rows: list[dict], isa: str, kernel: str) -> int:
    """Width with the smallest minimum time for ``isa`` and ``kernel``."""
    return min((r for r in rows if r["isa"] == isa), key=lambda r: r[kernel]["min"])["width"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="fewer states, passes and calls")
    results.add_options(parser)
    args = parser.parse_args()
    from robodyn.codegen.build import CFLAGS
    from robodyn.codegen.cpu import cpu_flags, default_block_width

    load_at_start = results.load_average()
    count, passes, repeat = (10_000, 2, 2) if args.quick else (100_000, 4, 3)
    rows, deviation = sweep(count, passes, repeat)
    if deviation > 1e-12:
        raise SystemExit(f"a block width changed the results: {deviation:.1e} relative to scalar")
    chosen = {"native": default_block_width(), "avx2": default_block_width(cpu_flags() - {"avx512f"})}
    print(f"PUMA 560, {count:,} states, 1 thread, ns per state (min / median of "
          f"{passes * repeat} calls); flags: {' '.join(CFLAGS)} [+ avx2: {' '.join(ISAS['avx2'])}]")
    for r in rows:
        mark = "  <- robodyn's choice" if chosen[r["isa"]] == r["width"] else ""
        print(f"  {r['isa']:>6} width {r['width']:>2}: ID {r['ID']['min']:6.1f} / "
              f"{r['ID']['median']:6.1f}   FD {r['FD']['min']:6.1f} / {r['FD']['median']:6.1f}{mark}")
    verdict = {}
    for isa in ISAS:
        verdict[isa] = {}
        for kernel in ("ID", "FD"):
            by = {r["width"]: r[kernel]["min"] for r in rows if r["isa"] == isa}
            best = _best(rows, isa, kernel)
            verdict[isa][kernel] = {"best_width": best, "chosen_width": chosen[isa],
                                    "chosen_over_best": round(by[chosen[isa]] / by[best], 3)}
            print(f"  {isa} {kernel}: best width {best}, robodyn's {chosen[isa]} takes "
                  f"{verdict[isa][kernel]['chosen_over_best']:.2f}x the best")
    print(f"  every width agrees with scalar code to {deviation:.1e} (relative)")
    path = results.target(args)
    if path is not None:
        command = " ".join(["python", "benchmarks/bench_block_width.py", *sys.argv[1:]])
        results.merge(path, "block_width", {
            "command": command, "load_average_at_start": load_at_start, "states": count,
            "passes": passes, "calls_per_pass": repeat, "flags": list(CFLAGS),
            "isas": {k: ("robodyn's flags (-march=native)" if v is None else
                         f"robodyn's flags + {' '.join(v)} (AVX2 code, run on this CPU)")
                     for k, v in ISAS.items()},
            "rows": rows, "verdict": verdict, "max_deviation_from_scalar": deviation})
        print(f"results: {path}")


if __name__ == "__main__":
    main()
