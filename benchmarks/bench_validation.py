"""Kinova Gen3 held-out validation table, with the whole identifications timed.

Prints, in one run (real recordings in ../shared/data/kinova-gen3, motor current):

  1. whole identification on the first 70 % of the three whole-arm runs with ``rd.identify``
     for OLS, WLS and the physically consistent SDP: seconds each and their ratio to OLS;
  2. per method, the held-out relative current error on the last 30 % of each whole-arm run
     (all joints) and of the three pooled, and on every jointwise run (its moving joint),
     raw and against the reference-filtered current (``robodyn.validation.heldout``: zero-phase
     Butterworth, order 4, 2.5 Hz), with the noise floor beside each, and the data README's
     baseline (0.32 raw, 0.22 filtered, on the pooled last 30 %);
  3. cross-run validation: identify on one (or two) whole runs, predict a different whole run.

Run: ``.venv/bin/python benchmarks/bench_validation.py [--methods ols,wls,consistent] [--friction F]``.
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from pathlib import Path

import numpy as np

import robodyn as rd
from robodyn.validation.heldout import HeldOutError, format_held_out, held_out_error, moving_joints

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
from tests.identification.kinova import JOINTWISE_FILES, WHOLE_ARM, WHOLE_ARM_FILES, read, split  # noqa: E402

BASELINE = (0.32, 0.22)


def figures(ident, recs, source: str, joints=None) -> HeldOutError:
    """Held-out error of ``ident`` pooled over ``recs``."""
    return held_out_error([r.t for r in recs], [r.current for r in recs],
                          [ident.predict(r) for r in recs], ident.robot.joint_names, joints, source)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--methods", default="ols,wls,consistent")
    parser.add_argument("--friction", default="linear")
    args = parser.parse_args()
    warnings.simplefilter("ignore")  # URDF plausibility notes, joint-7 gain fallback on full runs
    robot = rd.load("kinova_gen3")
    model = rd.compile_model(robot)
    runs = {name: read(p) for name, p in zip(WHOLE_ARM, WHOLE_ARM_FILES, strict=True)}
    train = [split(r)[0] for r in runs.values()]
    test = {name: split(r)[1] for name, r in runs.items()}
    jointwise = [read(p) for p in JOINTWISE_FILES]
    timings: dict[str, float] = {}
    rows: list[tuple[str, HeldOutError]] = []
    for method in args.methods.split(","):
        start = time.perf_counter()
        ident = rd.identify(robot, train, target="current", method=method, friction=args.friction,
                            model=model)
        timings[method] = time.perf_counter() - start
        tag = f"{method}, last 30 %"
        for name, rec in test.items():
            rows.append((tag, figures(ident, [rec], name)))
        pooled = figures(ident, list(test.values()), "all three (README baseline split)")
        rows.append((tag, pooled))
        for rec in jointwise:
            (k,) = moving_joints(rec.q)
            rows.append((f"{method}, jointwise", figures(ident, [rec], rec.source, [int(k)])))
        verdict = ["below" if f < b else "NOT below" for f, b in zip((pooled.raw, pooled.filtered),
                                                                      BASELINE, strict=True)]
        print(f"{method}: pooled raw {pooled.raw:.3f} ({verdict[0]} {BASELINE[0]}), filtered "
              f"{pooled.filtered:.3f} ({verdict[1]} {BASELINE[1]}), noise floor {pooled.noise_floor:.3f}",
              flush=True)
    # cross-run: fit on whole runs, predict a different whole run
    cases = [(("RunTrajectory1",), ("Trajectory1",)),
             (("RunTrajectory1", "Trajectory1"), ("RecordTrajectory_quadratic",)),
             (("RecordTrajectory_quadratic",), ("RunTrajectory1", "Trajectory1"))]
    for fit_on, check_on in cases:
        ident = rd.identify(robot, [runs[n] for n in fit_on], target="current", friction=args.friction,
                            model=model)
        for name in check_on:
            rows.append((f"wls, fit on {'+'.join(fit_on)}", figures(ident, [runs[name]], name)))
    print()
    print(format_held_out(rows))
    print(f"\nREADME baseline (last 30 %, pooled): raw {BASELINE[0]}, filtered {BASELINE[1]}, "
          "noise floor ~0.26")
    print("\nwhole identification, first 70 % of the three whole-arm runs "
          f"({sum(r.n_samples for r in train)} samples, current, friction {args.friction}):")
    ref = timings.get("ols")
    for method, sec in timings.items():
        ratio = f"  ({sec / ref:.2f}x OLS)" if ref else ""
        print(f"  {method:<11} {sec:7.2f} s{ratio}")
    print(f"load average: {' '.join(f'{x:.1f}' for x in np.round(__import__('os').getloadavg(), 1))}")


if __name__ == "__main__":
    main()
