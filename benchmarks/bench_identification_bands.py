"""Why "Kinova across runs <= 0.35 raw" (issue 20) needs more than a rigid-body model.

Prints, for the Kinova Gen3 across-runs split of ``bench_identification_quality.py``
(fit RunTrajectory1 + RecordTrajectory_quadratic, predict Trajectory1, motor current):

* the least raw error of any prediction band-limited to ``fc``: ``||y - lowpass_fc(y)|| / ||y||``;
* per frequency band, the correlation of the current of the two runs of the same motion
  (RunTrajectory1 and Trajectory1, sample by sample): what repeats is not noise;
* the other run's current (low-passed at 10 Hz) as a prediction of Trajectory1;
* per band, the default ``rd.identify`` model evaluated with states filtered at 20 Hz
  (``prediction_cutoff=20``): its correlation with the measured current and the ratio of the
  measured to the predicted RMS (1 = the right amplitude).

Filters: 4th-order Butterworth, zero phase (``scipy.signal.filtfilt``), at 1 kHz.
Run: ``python benchmarks/bench_identification_bands.py``; figures quoted in docs/identification.md.
"""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

import numpy as np
import scipy.signal as ss

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))

import robodyn as rd  # noqa: E402
from tests.identification.kinova import WHOLE_ARM, WHOLE_ARM_FILES, read  # noqa: E402

FS = 1000.0
BANDS = ((2.5, 5.0), (5.0, 10.0), (10.0, 25.0))


def _low(x: np.ndarray, fc: float) -> np.ndarray:
    return ss.filtfilt(*ss.butter(4, fc / (FS / 2)), x, axis=0)


def _band(x: np.ndarray, lo: float, hi: float) -> np.ndarray:
    return ss.filtfilt(*ss.butter(4, [lo / (FS / 2), hi / (FS / 2)], "band"), x, axis=0)


def _row(label: str, values: np.ndarray) -> None:
    print(f"  {label:34s} " + " ".join(f"{v:6.2f}" for v in values))


def main() -> None:
    warnings.simplefilter("ignore")
    runs = {name: read(path) for name, path in zip(WHOLE_ARM, WHOLE_ARM_FILES, strict=True)}
    check, repeat = runs["Trajectory1"], runs["RunTrajectory1"]
    y = np.asarray(check.current)
    n = min(len(y), repeat.n_samples)
    other = np.asarray(repeat.current)[:n]
    print("least raw error of a prediction band-limited to fc, Trajectory1:")
    for fc in (2.5, 5.0, 10.0, 20.0):
        print(f"  {fc:4g} Hz: {np.linalg.norm(y - _low(y, fc)) / np.linalg.norm(y):.3f}")
    pred_other = _low(other, 10.0)
    print(f"other run of the same motion (RunTrajectory1, < 10 Hz) as the prediction: "
          f"{np.linalg.norm(y[:n] - pred_other) / np.linalg.norm(y[:n]):.3f}")
    robot = rd.load("kinova_gen3")
    ident = rd.identify(robot, [repeat, runs["RecordTrajectory_quadratic"]], target="current",
                        prediction_cutoff=20.0)
    p = ident.predict(check)
    print("per band, joints 1-7:")
    for lo, hi in BANDS:
        yb, ob, pb = _band(y, lo, hi), _band(other, lo, hi), _band(p, lo, hi)
        print(f" {lo:g}-{hi:g} Hz")
        _row("measured RMS, A", np.sqrt(np.mean(yb**2, axis=0)))
        _row("corr. with the other run", [np.corrcoef(yb[:n, j], ob[:, j])[0, 1] for j in range(7)])
        _row("corr. with the model (20 Hz)", [np.corrcoef(yb[:, j], pb[:, j])[0, 1] for j in range(7)])
        _row("measured / model RMS", np.sqrt(np.mean(yb**2, axis=0) / np.mean(pb**2, axis=0)))


if __name__ == "__main__":
    main()
