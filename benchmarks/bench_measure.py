"""Reading and differentiating the Kinova Gen3 logs, against a plain pandas + NumPy pipeline.

For all ten files in ``../shared/data/kinova-gen3`` (78 columns, 1942-6535 rows each), times in
the same run:

  1. ``rd.read_recording(path, spec="kinova_gen3")``: line and field-count checks, per-cell
     validation, period estimate, joint velocity from the file, acceleration by zero-phase
     Butterworth differentiation at the bandwidth cut-off;
  2. the straightforward pipeline: ``pandas.read_csv`` + ``numpy.gradient`` twice (velocity and
     acceleration from positions, no filter, no checks, period assumed 1 ms);

and prints the totals and the ratio, plus the agreement of each velocity with the measured one.

Run: ``.venv/bin/python benchmarks/bench_measure.py [--repeat N]``.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
import pandas as pd

import robodyn as rd
from robodyn.measure.filtering import differentiate

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


def _best(fn, paths, repeat):
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        result = fn(paths)
        times.append(time.perf_counter() - start)
    return min(times), result


def _agreement(results):
    errs = []
    for meas, v, _ in results:
        moving = np.ptp(meas, axis=0) > 0.05
        errs.append(np.sqrt(np.mean((v - meas)[:, moving] ** 2)) / np.sqrt(np.mean(meas[:, moving] ** 2)))
    return min(errs), max(errs)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    paths = sorted(DATA.glob("*/*.csv.gz"))
    if not paths:
        raise SystemExit(f"no Kinova files under {DATA}")
    rows = sum(len(pd.read_csv(p, usecols=["Time"])) for p in paths)
    t_rd, r_rd = _best(_robodyn, paths, args.repeat)
    t_pl, r_pl = _best(_plain, paths, args.repeat)
    print(f"{len(paths)} Kinova Gen3 files, {rows} rows x 78 columns; best of {args.repeat}")
    print(f"  robodyn read_recording + filtered differentiation : {t_rd:7.3f} s")
    print(f"  pandas.read_csv + numpy.gradient (no checks)      : {t_pl:7.3f} s")
    print(f"  ratio robodyn / plain                             : {t_rd / t_pl:7.2f}")
    lo, hi = _agreement(r_rd)
    print(f"  velocity from position vs measured velocity (RMS / RMS, moving joints): "
          f"robodyn {lo:.3f}-{hi:.3f}", end="")
    lo, hi = _agreement(r_pl)
    print(f", numpy.gradient {lo:.3f}-{hi:.3f}")


if __name__ == "__main__":
    main()
