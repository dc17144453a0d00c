"""Identification speed: stacking the identification matrix, and whole identifications.

Prints, in one run:

  1. stacking the identification matrix (full regressor, 7 x 105 per sample) for 100,000
     Kinova Gen3 samples: robodyn's batched compiled regressor writing straight into one
     matrix (``robodyn.identification.stacking.identification_matrix``), into a fresh matrix and
     into a reused one (``out=``), on 1 and 2 threads; the memory floor of each case (NumPy
     writing a fresh matrix of the same shape, and filling the reused one); against a Python
     loop over Pinocchio's ``computeJointTorqueRegressor`` on the same arm (the manufacturer's
     URDF, ../shared/data/kinova-gen3/gen3.urdf), like for like: into a fresh matrix and into
     one already written; the ratios (target >= 10x), the ratio zero compute would give, and
     the agreement of the rigid-body columns;
  2. whole identifications of the Kinova whole-arm runs (all three, motor current) with
     ``rd.identify`` for OLS, WLS and the physically consistent SDP, in seconds each.

Run: ``.venv/bin/python benchmarks/bench_identify.py [--samples N] [--repeat N] [--stacking-only]``.
"""

from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path

import numpy as np

import robodyn as rd
from robodyn.identification import identify
from robodyn.identification.stacking import identification_matrix
from robodyn.symbolic.regressor import INERTIAL_NAMES, PER_JOINT

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
from timing import best_of_with_result as best_of  # noqa: E402

from tests.identification.kinova import DATA, WHOLE_ARM_FILES, read  # noqa: E402
from tests.urdf_chains import pin_q  # noqa: E402

PIN_ORDER = [INERTIAL_NAMES.index(k) for k in ("M", "MX", "MY", "MZ", "XX", "XY", "YY", "XZ", "YZ", "ZZ")]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=100_000)
    parser.add_argument("--repeat", type=int, default=3, help="timing repeats (best is kept)")
    parser.add_argument("--stacking-only", action="store_true", help="skip the whole identifications")
    args = parser.parse_args()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = rd.load("kinova_gen3")
    model = rd.compile_model(robot)
    n, count = robot.dof, args.samples
    rng = np.random.default_rng(0)
    q, qd, qdd = rng.uniform(-2, 2, (3, count, n))

    def line(label: str, t: float) -> None:
        print(f"  {label:<52} {t:8.3f} s  {1e9 * t / count:8.0f} ns/sample")

    t_rd, y = best_of(lambda: identification_matrix(model, q, qd, qdd), args.repeat)
    t_rd2, y2 = best_of(lambda: identification_matrix(model, q, qd, qdd, threads=2), args.repeat)
    assert np.array_equal(y, y2), "threads changed the identification matrix"
    y2 = None
    buf = np.empty_like(y)
    buf.fill(0.0)  # touched once: the reused case has no page faults
    t_out, w_out = best_of(lambda: identification_matrix(model, q, qd, qdd, out=buf), args.repeat)
    t_out2, _ = best_of(lambda: identification_matrix(model, q, qd, qdd, threads=2, out=buf),
                        args.repeat)
    assert np.array_equal(w_out, y), "out= changed the identification matrix"
    print(f"stacking {count} Gen3 samples ({count * n} x {y.shape[1]}, "
          f"{y.nbytes / 1e6:.0f} MB):")
    line("robodyn identification_matrix, fresh matrix", t_rd)
    line("  the same on 2 threads", t_rd2)
    line("robodyn into a reused matrix (out=)", t_out)
    line("  the same on 2 threads", t_out2)
    # what merely writing the matrix costs: NumPy writing a fresh matrix of the same size (page
    # faults + stores), and filling the reused one (ordinary stores; robodyn's streaming stores
    # into a large reused matrix can beat it)
    t_fill, _ = best_of(lambda: np.full(y.shape, 1.0), args.repeat)
    t_refill, _ = best_of(lambda: buf.fill(1.0), args.repeat)
    line("writing alone, fresh: NumPy np.full of the same shape", t_fill)
    line("writing alone, reused: NumPy fill of the reused matrix", t_refill)
    print(f"  robodyn minus writing alone: fresh {1e9 * (t_rd - t_fill) / count:.0f} ns/sample, "
          f"reused {1e9 * (t_out - t_refill) / count:.0f} ns/sample (1 thread)")
    try:
        import pinocchio as pin
    except ImportError:
        print("  pinocchio not installed: no peer timing")
    else:
        pmodel = pin.buildModelFromUrdf(str(DATA / "gen3.urdf"))
        pmodel.gravity.linear = np.array([0.0, 0.0, -9.81])
        data = pmodel.createData()
        qp = np.array([pin_q(pmodel, qi) for qi in q])  # continuous joints: (cos, sin)

        def loop(out: np.ndarray) -> np.ndarray:
            for i in range(count):
                out[i * n:(i + 1) * n] = pin.computeJointTorqueRegressor(pmodel, data, qp[i], qd[i], qdd[i])
            return out

        # like for like: into a fresh matrix (page faults, as robodyn's fresh case), and into one
        # already written (as robodyn's out=)
        t_pin, _ = best_of(lambda: loop(np.empty((count * n, 10 * n))), 2)
        written = np.full((count * n, 10 * n), 0.0)
        t_pin_out, w = best_of(lambda: loop(written), 2)
        line("Pinocchio computeJointTorqueRegressor loop, fresh matrix", t_pin)
        line("  the same into a matrix already written", t_pin_out)
        print(f"  ratio Pinocchio loop / robodyn (target >= 10x), like for like (robodyn writes "
              f"{y.shape[1]} columns, Pinocchio {w.shape[1]}; one Python call per sample):")
        print(f"    fresh matrix:  {t_pin / t_rd:5.1f}x on 1 thread, {t_pin / t_rd2:5.1f}x on 2 "
              f"(NumPy's np.full alone: {t_pin / t_fill:.1f}x on 1)")
        print(f"    reused matrix: {t_pin_out / t_out:5.1f}x on 1 thread, {t_pin_out / t_out2:5.1f}x "
              f"on 2 (NumPy's fill alone: {t_pin_out / t_refill:.1f}x on 1)")
        cols = [PER_JOINT * j + k for j in range(n) for k in PIN_ORDER]
        dev = np.abs(y[:, cols] - w).max() / np.abs(w).max()
        print(f"  rigid-body columns agree to {dev:.1e} (relative to the largest entry)")

    if args.stacking_only:
        return
    runs = [read(p) for p in WHOLE_ARM_FILES]
    print(f"whole identification, Kinova whole-arm runs ({sum(r.n_samples for r in runs)} samples, "
          f"target current, defaults):")
    for method in ("ols", "wls", "consistent"):
        t, ident = best_of(lambda m=method: identify(robot, runs, target="current", method=m,
                                                        model=model), 1)
        print(f"  {method:>10}: {t:6.2f} s  (cut-off {ident.preprocess.cutoff:g} Hz, decimate "
              f"{ident.preprocess.decimate}, {len(ident.base_parameters)} base parameters, "
              f"lambda {ident.regularization:.3g})")


if __name__ == "__main__":
    main()
