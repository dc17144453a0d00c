"""Reading and differentiating the Kinova Gen3 logs, against a plain pandas + NumPy pipeline.

For all ten files in ``../shared/data/kinova-gen3`` (78 columns, 1942-6535 rows each), times in
the same run:

  1. ``rd.read_recording(path, spec="kinova_gen3")``: line and field-count checks, per-cell
     validation, period estimate, joint velocity from the file, acceleration by zero-phase
     Butterworth differentiation at the bandwidth cut-off;
  2. the straightforward pipeline: ``pandas.read_csv`` + ``numpy.gradient`` twice (velocity and
     acceleration from positions, no filter, no checks, period assumed 1 ms);

and prints the totals (min / median over rounds in which the two take turns) and the ratio, plus
the agreement of each velocity from positions with the measured one.

Full runs merge the figures into ``benchmarks/results/<machine>.json`` (benchmark ``measure``).
Run: ``.venv/bin/python benchmarks/bench_measure.py [--quick] [--results PATH | --no-results]``
(``--quick``: 3 rounds instead of 5; written only with ``--results``).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

import robodyn as rd
from robodyn.measure.filtering import differentiate

sys.path.insert(0, str(Path(__file__).resolve().parent))
import results  # noqa: E402
import timing  # noqa: E402

REPEATS = 5
ROBODYN = "robodyn"
PLAIN = "pandas + numpy"
#: What each pipeline does (the rows' differences).
PIPELINES = {
    ROBODYN: "rd.read_recording(path, spec='kinova_gen3'): line and field-count checks, every cell "
             "validated, period estimated from the time column, velocity read from the file, "
             "acceleration by zero-phase Butterworth differentiation at the bandwidth cut-off; "
             "plus a velocity from positions by the same filtered differentiation for the "
             "comparison",
    PLAIN: "pandas.read_csv, then numpy.gradient twice (velocity and acceleration from "
           "positions): no checks, no filter, period assumed 1 ms"}

DATA = Path(__file__).resolve().parents[2] / "shared" / "data" / "kinova-gen3"
if not DATA.is_dir():
    DATA = Path("/work/shared/data/kinova-gen3")


def _robodyn(paths):
    out = []
    for p in paths:
        rec = rd.read_recording(p, spec="kinova_gen3")
        _, v, _ = differentiate(rec.t, rec.q)  # velocity from position too, for the comparison
        out.append((rec.qd, v, rec.qdd))
    return out


def _plain(paths):
    out = []
    for p in paths:
        frame = pd.read_csv(p)
        q = frame[[f"Position{k}" for k in range(1, 8)]].to_numpy()
        qd_meas = frame[[f"Velocity{k}" for k in range(1, 8)]].to_numpy()
        v = np.gradient(q, 1e-3, axis=0)
        a = np.gradient(v, 1e-3, axis=0)
        out.append((qd_meas, v, a))
    return out


def _agreement(outputs):
    """Per file: RMS(velocity from position - measured velocity) / RMS(measured), moving joints."""
    errs = []
    for meas, v, _ in outputs:
        moving = np.ptp(meas, axis=0) > 0.05
        errs.append(float(np.sqrt(np.mean((v - meas)[:, moving] ** 2))
                          / np.sqrt(np.mean(meas[:, moving] ** 2))))
    return errs


def main() -> None:
    """Command line: time both pipelines in turns, compare velocities, merge the figures."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="3 rounds instead of 5")
    results.add_options(parser)
    args = parser.parse_args()
    path = results.target(args)
    repeats = 3 if args.quick else REPEATS
    entry: dict[str, Any] = {
        "command": "python benchmarks/bench_measure.py" + (" --quick" if args.quick else ""),
        "load_average_at_start": results.load_average()}
    paths = sorted(DATA.glob("*/*.csv.gz"))
    if not paths:
        raise SystemExit(f"no Kinova files under {DATA}")
    rows = sum(len(pd.read_csv(p, usecols=["Time"])) for p in paths)
    out = {}
    times = timing.interleaved({label: (lambda fn=fn, k=label: out.__setitem__(k, fn(paths)))
                                for label, fn in ((ROBODYN, _robodyn), (PLAIN, _plain))}, repeats)
    errors = {label: _agreement(r) for label, r in out.items()}
    entry.update({
        "files": len(paths), "rows": rows, "columns": 78, "repeats": repeats,
        "seconds": {k: results.summary(v, 1.0, 3) for k, v in times.items()},
        "ratio": results.ratio(times[ROBODYN], times[PLAIN]),
        "velocity_error": {k: [round(e, 4) for e in v] for k, v in errors.items()},
        "error_ratio": [round(p / r, 2) for p, r in zip(errors[PLAIN], errors[ROBODYN],
                                                          strict=True)],
        "pipelines": PIPELINES})
    sec, ratio = entry["seconds"], entry["ratio"]
    print(f"{len(paths)} Kinova Gen3 files, {rows} rows x 78 columns; min / median of {repeats} "
          "rounds in which the pipelines take turns")
    print(f"  robodyn read_recording + filtered differentiation : {sec[ROBODYN]['min']:7.3f} / "
          f"{sec[ROBODYN]['median']:.3f} s")
    print(f"  pandas.read_csv + numpy.gradient (no checks)      : {sec[PLAIN]['min']:7.3f} / "
          f"{sec[PLAIN]['median']:.3f} s")
    print(f"  ratio robodyn / plain                             : {ratio['min']:7.2f} / "
          f"{ratio['median']:.2f}")
    rd_err, pl_err, er = errors[ROBODYN], errors[PLAIN], entry["error_ratio"]
    print(f"  velocity from position vs measured velocity (RMS / RMS, moving joints): robodyn "
          f"{min(rd_err):.3f}-{max(rd_err):.3f}, numpy.gradient {min(pl_err):.3f}-"
          f"{max(pl_err):.3f} (numpy.gradient / robodyn per file {min(er):.2f}-{max(er):.2f}x)")
    if path is not None:
        print(f"figures written to {results.merge(path, 'measure', entry)}")


if __name__ == "__main__":
    main()
