"""Roofline position of robodyn's generated kernels on this machine (issue 22 item 3).

Measured in one run, on one thread:

* the machine's **peak FP64 rate**: a C loop of 12 independent fused multiply-add chains on
  vectors of one register (8 doubles with AVX-512, else 4; GCC vector extensions),
  compiled with robodyn's own flags (``-O3 -march=native -ffp-contract=fast``): 2 flops per lane
  per FMA; the best of 100 rounds (10 with ``--quick``), as for every figure here (on a shared
  machine the minimum over many rounds is the undisturbed time);
* its **memory bandwidth**: the STREAM triad ``a = b + s c`` over three arrays of 64 MiB each
  (far beyond the caches), same flags, 24 bytes per element counted (write-allocate traffic not
  counted, as STREAM reports it); the best of several runs;
* robodyn's **inverse dynamics** (PUMA 560 with its friction, numeric parameters, 100,000 random
  states, ``threads=1``): ns per state, min and median over rounds, and its operation count read
  from the generated program (``robodyn.symbolic.opcount.count_ops`` of the kernel's body and
  outputs after robodyn's CSE: additions and multiplications), written into one reused array
  (``out=``: no allocation per call, as the peak loop has none), plus the sine and cosine of each
  angle the kernel takes, which the generated C evaluates by one branch-free polynomial per
  angle (``robodyn.codegen.c``'s ``sincos_block``: :data:`SINCOS_FLOPS` per angle, counted from
  its source; its compares and selects not counted);
* the inverse dynamics' **floor**: those flops at the peak rate, and how many times that floor
  the measured time is (the issue's target: 3x).
  Its **bytes per state** (q, qd, qdd in, tau out: 4 n doubles) at the measured bandwidth give
  the memory floor of a streaming batch.

Run: ``.venv/bin/python benchmarks/bench_roofline.py [--quick] [--results PATH | --no-results]``.
"""

from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path

import numpy as np

import robodyn as rd
from robodyn.codegen.build import CFLAGS, compile_library
from robodyn.codegen.c import _angles
from robodyn.codegen.cpu import cpu_flags
from robodyn.symbolic.opcount import count_ops

sys.path.insert(0, str(Path(__file__).parent))
import results  # noqa: E402
import timing  # noqa: E402

#: Flops of one angle's sine and cosine in the generated ``sincos_block`` (robodyn.codegen.c):
#: range reduction 3 + 8 (the quadrant number rounded by adding and subtracting 1.5 2^52, then
#: pi/2 in four parts), z and z^2 2, sine polynomial 8 + 5, cosine polynomial 12 + 2 + 5; the
#: quadrant's swap and signs are bit operations, not counted (an FMA counts 2, as in the peak).
#: 46 before 2026-12-06, when the quadrant took 3 flops and the rounding 1.
SINCOS_FLOPS = 45

#: Independent FMA chains of the peak loop (at least latency x FMA ports on current x86 cores,
#: few enough to stay in the vector registers).
CHAINS = 12

_PEAK = """
typedef double vec __attribute__((vector_size(%(bytes)d)));
double rd_peak(long iterations) {
    vec acc[%(chains)d];
    const vec m = (vec){0} + 0.999999999, c = (vec){0} + 1e-9;
    for (int k = 0; k < %(chains)d; ++k) acc[k] = (vec){0} + (double)(k + 1);
    for (long i = 0; i < iterations; ++i)
        for (int k = 0; k < %(chains)d; ++k) acc[k] = acc[k] * m + c;  /* one FMA per lane */
    double s = 0.0;
    for (int k = 0; k < %(chains)d; ++k)
        for (int l = 0; l < %(width)d; ++l) s += acc[k][l];
    return s;
}
void rd_triad(long n, double *a, const double *b, const double *c, double s) {
    for (long i = 0; i < n; ++i) a[i] = b[i] + s * c[i];
}
"""
_DECL = ("double rd_peak(long iterations);\n"
         "void rd_triad(long n, double *a, const double *b, const double *c, double s);")


def _library():
    width = 8 if "avx512f" in cpu_flags() else 4  # doubles per vector register (AVX-512, AVX2)
    source = _PEAK % {"bytes": 8 * width, "chains": CHAINS, "width": width}
    return compile_library(source, _DECL, flags=CFLAGS), width


def peak_gflops(lib, width: int, repeat: int) -> dict:
    """Best FP64 rate of the FMA loop, GFLOP/s (2 flops per lane per FMA)."""
    iterations = 2_000_000
    fns = {"peak": lambda: lib.lib.rd_peak(iterations)}
    t = timing.interleaved(fns, repeat=repeat)["peak"]
    flops = 2.0 * width * CHAINS * iterations
    return {"gflops": round(flops / min(t) / 1e9, 2),
            "median_gflops": round(flops / float(np.median(t)) / 1e9, 2),
            "vector_doubles": width, "chains": CHAINS, "repeats": repeat}


def triad_gbs(lib, repeat: int) -> dict:
    """Best STREAM-triad bandwidth, GB/s (24 bytes per element)."""
    n = 8 * 2**20  # 64 MiB per array
    a, b, c = np.zeros(n), np.ones(n), np.full(n, 2.0)
    ffi = lib.ffi
    pa, pb, pc = (ffi.from_buffer("double[]", x) for x in (a, b, c))
    fns = {"triad": lambda: lib.lib.rd_triad(n, pa, pb, pc, 3.0)}
    fns["triad"]()  # first touch
    t = timing.interleaved(fns, repeat=repeat)["triad"]
    assert a[0] == 7.0
    return {"gbs": round(24.0 * n / min(t) / 1e9, 2),
            "median_gbs": round(24.0 * n / float(np.median(t)) / 1e9, 2),
            "array_mib": 64, "repeats": repeat}


def inverse_dynamics(count: int, repeat: int) -> dict:
    """PUMA 560 inverse dynamics, 1 thread: ns per state and the kernel's operation count."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = rd.load("puma560")
    model = rd.compile_model(robot)
    kernel = next(k for k in model.kernels.kernels if k.name == "inverse_dynamics")
    ops = count_ops([e for _, e in kernel.body]) + count_ops(list(kernel.outputs[0].entries))
    rng = np.random.default_rng(0)
    q, qd, qdd = (rng.uniform(-1, 1, (count, robot.dof)) for _ in range(3))
    out = np.empty_like(q)  # the result written into one reused array, as the peak loop's
    model.inverse_dynamics(q[:64], qd[:64], qdd[:64])  # loaded, warm
    t = timing.interleaved({"id": lambda: model.inverse_dynamics(q, qd, qdd, threads=1, out=out)},
                           repeat)["id"]
    return {"ns_per_state": results.summary(t, 1e9 / count, 2), "additions": ops.additions,
            "multiplications": ops.multiplications, "sincos_angles": len(_angles(kernel)),
            "sincos_flops_per_angle": SINCOS_FLOPS, "bytes_per_state": 8 * 4 * robot.dof,
            "states": count}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="fewer states and repeats")
    results.add_options(parser)
    args = parser.parse_args()
    repeat = 10 if args.quick else 100
    load_at_start = results.load_average()
    lib, width = _library()
    peak = peak_gflops(lib, width, repeat)
    bw = triad_gbs(lib, repeat)
    idyn = inverse_dynamics(10_000 if args.quick else 100_000, repeat)
    flops = idyn["additions"] + idyn["multiplications"] + idyn["sincos_angles"] * SINCOS_FLOPS
    floor_ns = flops / peak["gflops"]  # GFLOP/s = flop per ns
    memory_ns = idyn["bytes_per_state"] / bw["gbs"]  # GB/s = byte per ns
    measured = idyn["ns_per_state"]["min"]
    roofline = {
        "flops_per_state": flops, "achieved_gflops": round(flops / measured, 2),
        "fraction_of_peak": round(flops / measured / peak["gflops"], 3),
        "compute_floor_ns": round(floor_ns, 2), "memory_floor_ns": round(memory_ns, 2),
        "times_compute_floor": round(measured / floor_ns, 2), "target_times_floor": 3.0,
    }
    print(f"peak FP64, 1 thread ({width} doubles per vector, {CHAINS} FMA chains, "
          f"{' '.join(CFLAGS)}): {peak['gflops']:.1f} GFLOP/s (median {peak['median_gflops']:.1f})")
    print(f"STREAM triad, 1 thread, 3 x 64 MiB: {bw['gbs']:.1f} GB/s (median {bw['median_gbs']:.1f})")
    print(f"PUMA 560 inverse dynamics (with friction), {idyn['states']:,} states, 1 thread: "
          f"{measured:.1f} ns/state (median {idyn['ns_per_state']['median']:.1f}); "
          f"{idyn['multiplications']} mul + {idyn['additions']} add + {idyn['sincos_angles']} "
          f"angles x {SINCOS_FLOPS} (sin and cos) = {flops} flops")
    times = roofline["times_compute_floor"]
    print(f"  achieved {roofline['achieved_gflops']:.2f} GFLOP/s = "
          f"{100 * roofline['fraction_of_peak']:.1f} % of peak; compute floor {floor_ns:.1f} "
          f"ns/state -> {times:.2f}x the floor (target <= 3x: {'met' if times <= 3 else 'NOT met'})")
    bound = "compute" if floor_ns >= memory_ns else "memory"
    print(f"  memory floor of a streaming batch ({idyn['bytes_per_state']} B/state at the triad "
          f"rate): {memory_ns:.2f} ns/state: by its floors the kernel is {bound}-bound "
          f"({flops / idyn['bytes_per_state']:.2f} flop/B against the ridge at "
          f"{peak['gflops'] / bw['gbs']:.2f})")
    path = results.target(args)
    if path is not None:
        command = " ".join(["python", "benchmarks/bench_roofline.py", *sys.argv[1:]])
        results.merge(path, "roofline", {"command": command, "load_average_at_start": load_at_start,
                                          "peak": peak, "triad": bw, "inverse_dynamics": idyn,
                                          "roofline": roofline})
        print(f"results: {path}")


if __name__ == "__main__":
    main()
