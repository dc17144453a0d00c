"""Kinova Gen3 held-out validation table, with the whole identifications timed.

In one run (real recordings in ../shared/data/kinova-gen3, motor current):

  1. whole identification on the first 70 % of the three whole-arm runs with ``rd.identify``
     for OLS, WLS and the physically consistent SDP (robodyn's default method), friction
     ``--friction`` (default linear), every other option at its default: seconds each, min /
     median over rounds in which the methods take turns, and their ratio to OLS; before the
     rounds, the first call of each in the process, one run (imports, first-call costs);
  2. per method, the held-out relative current error on the last 30 % of each whole-arm run
     (all joints) and of the three pooled, and on every jointwise run (its moving joint; never
     used in fitting), raw and against the reference-filtered current
     (``robodyn.validation.heldout``: zero-phase Butterworth, order 4, 2.5 Hz), with the noise
     floor beside each, and the data README's baseline (0.32 raw, 0.22 filtered, on the pooled
     last 30 %);
  3. cross-run validation with the default method: identify on one (or two) whole runs,
     predict a different whole run.

Full runs merge the figures into ``benchmarks/results/<machine>.json`` (benchmark
``validation``). Run: ``.venv/bin/python benchmarks/bench_validation.py [--quick] [--repeat N]
[--methods ols,wls,consistent] [--friction F] [--results PATH | --no-results]`` (``--quick``:
no cross-run part, written only with ``--results``; a full run takes under a minute on a
quiet 2-core machine).
"""

from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path
from typing import Any

import robodyn as rd
from robodyn.validation.heldout import HeldOutError, format_held_out, held_out_error, moving_joints

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))
import results  # noqa: E402
import timing  # noqa: E402

from tests.identification.kinova import (  # noqa: E402
    JOINTWISE_FILES,
    WHOLE_ARM,
    WHOLE_ARM_FILES,
    read,
    split,
)

#: The data README's baseline on the pooled last 30 % (raw, filtered) and its noise floor.
BASELINE = (0.32, 0.22)
BASELINE_SOURCE = "../shared/data/kinova-gen3/README.md"
#: Cross-run cases: fit on these whole runs, predict those.
CROSS_RUN = ((("RunTrajectory1",), ("Trajectory1",)),
             (("RunTrajectory1", "Trajectory1"), ("RecordTrajectory_quadratic",)),
             (("RecordTrajectory_quadratic",), ("RunTrajectory1", "Trajectory1")))


def figures(ident: Any, recs: list[Any], source: str, joints: list[int] | None = None,
            ) -> HeldOutError:
    """Held-out error of ``ident`` pooled over ``recs``."""
    return held_out_error([r.t for r in recs], [r.current for r in recs],
                          [ident.predict(r) for r in recs], ident.robot.joint_names, joints, source)


def _row(case: str, method: str, e: HeldOutError) -> dict[str, Any]:
    """A held-out row of the entry."""
    return {"case": case, "method": method, "recording": e.source, "joints": list(e.joints),
            "raw": round(e.raw, 4), "filtered": round(e.filtered, 4),
            "noise_floor": round(e.noise_floor, 4), "samples": e.samples}


def held_out(idents: dict[str, Any], test: dict[str, Any], jointwise: list[Any],
             ) -> tuple[list[dict[str, Any]], list[tuple[str, HeldOutError]]]:
    """Section 2: the rows of every method (entry rows, and rows to print)."""
    rows, printed = [], []
    for method, ident in idents.items():
        errors = [("last 30 %", figures(ident, [rec], name)) for name, rec in test.items()]
        errors.append(("last 30 %", figures(ident, list(test.values()), "all three pooled")))
        for rec in jointwise:
            (k,) = moving_joints(rec.q)
            errors.append(("jointwise", figures(ident, [rec], rec.source, [int(k)])))
        rows += [_row(case, method, e) for case, e in errors]
        printed += [(f"{method}, {case}", e) for case, e in errors]
        pooled = errors[len(test)][1]
        verdict = ["below" if f < b else "NOT below" for f, b in zip(
            (pooled.raw, pooled.filtered), BASELINE, strict=True)]
        print(f"{method}: pooled raw {pooled.raw:.3f} ({verdict[0]} {BASELINE[0]}), filtered "
              f"{pooled.filtered:.3f} ({verdict[1]} {BASELINE[1]}), noise floor "
              f"{pooled.noise_floor:.3f}", flush=True)
    return rows, printed


def cross_run(robot: rd.Robot, model: Any, runs: dict[str, Any], friction: str,
              ) -> tuple[list[dict[str, Any]], list[tuple[str, HeldOutError]]]:
    """Section 3: fit on whole runs with the default method, predict a different whole run."""
    rows, printed = [], []
    for fit_on, check_on in CROSS_RUN:
        ident = rd.identify(robot, [runs[n] for n in fit_on], target="current", friction=friction,
                            model=model)
        for name in check_on:
            e = figures(ident, [runs[name]], name)
            rows.append({**_row("cross-run", ident.method, e), "fit_on": list(fit_on)})
            printed.append((f"{ident.method}, fit on {'+'.join(fit_on)}", e))
    return rows, printed


def main() -> None:
    """Command line: time the identifications, print the tables, merge the entry."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--methods", default="ols,wls,consistent")
    parser.add_argument("--friction", default="linear")
    parser.add_argument("--repeat", type=int, default=3, help="rounds (at least 3; default 3)")
    parser.add_argument("--quick", action="store_true", help="no cross-run part")
    results.add_options(parser)
    args = parser.parse_args()
    path = results.target(args)
    repeats = max(3, args.repeat)
    command = "python benchmarks/bench_validation.py" + (" --quick" if args.quick else "")
    for flag, value, default in (("--repeat", repeats, 3), ("--methods", args.methods,
                                 "ols,wls,consistent"), ("--friction", args.friction, "linear")):
        command += f" {flag} {value}" if value != default else ""
    entry: dict[str, Any] = {"command": command, "load_average_at_start": results.load_average()}
    warnings.simplefilter("ignore")  # URDF plausibility notes, joint-7 gain fallback on full runs
    robot = rd.load("kinova_gen3")
    model = rd.compile_model(robot)
    runs = {name: read(p) for name, p in zip(WHOLE_ARM, WHOLE_ARM_FILES, strict=True)}
    train = [split(r)[0] for r in runs.values()]
    test = {name: split(r)[1] for name, r in runs.items()}
    jointwise = [read(p) for p in JOINTWISE_FILES]
    methods = args.methods.split(",")
    idents = {}

    def fn(method: str) -> Any:
        """One whole identification; the last of each method is kept for the tables."""
        idents[method] = rd.identify(robot, train, target="current", method=method,
                                     friction=args.friction, model=model)

    # the first call of each method in this process, one run (imports and first-call costs),
    # then the rounds
    first = timing.interleaved({m: (lambda m=m: fn(m)) for m in methods}, 1)
    times = timing.interleaved({m: (lambda m=m: fn(m)) for m in methods}, repeats)
    rows, printed = held_out(idents, test, jointwise)
    cross, cross_printed = ([], []) if args.quick else cross_run(robot, model, runs, args.friction)
    print()
    print(format_held_out(printed + cross_printed))
    print(f"\nREADME baseline (last 30 %, pooled): raw {BASELINE[0]}, filtered {BASELINE[1]}, "
          "noise floor ~0.26")
    samples = sum(r.n_samples for r in train)
    print(f"\nwhole identification, first 70 % of the three whole-arm runs ({samples} samples, "
          f"current, friction {args.friction}), {repeats} rounds:")
    ref = times.get("ols")
    for method, sec in times.items():
        ratio = f"  ({results.ratio(sec, ref)['min']:.2f}x OLS)" if ref else ""
        print(f"  {method:<11} {min(sec):7.2f} s (median {sorted(sec)[len(sec) // 2]:.2f}){ratio}; "
              f"first call in the process {first[method][0]:.2f} s")
    entry.update({
        "robot": "kinova_gen3", "target": "current", "friction": args.friction,
        "train_samples": samples, "runs": list(WHOLE_ARM), "repeats": repeats,
        "seconds": {m: results.summary(v, 1, 2) for m, v in times.items()},
        "vs_ols": {m: results.ratio(v, ref) for m, v in times.items()} if ref else {},
        "first_call_s": {m: round(v[0], 2) for m, v in first.items()},
        "reference_filter_hz": printed[0][1].cutoff,
        "baseline": {"raw": BASELINE[0], "filtered": BASELINE[1], "noise_floor": "about 0.26",
                     "source": BASELINE_SOURCE},
        "held_out": rows, "cross_run": cross})
    if path is not None:
        print(f"figures written to {results.merge(path, 'validation', entry)}")


if __name__ == "__main__":
    main()
