"""The real Kinova Gen3 recordings (../shared/data/kinova-gen3), read for the identification tests."""

from __future__ import annotations

from pathlib import Path

import numpy as np

import robodyn as rd

DATA = Path(__file__).resolve().parents[3] / "shared" / "data" / "kinova-gen3"
if not DATA.exists():
    DATA = Path("/work/shared/data/kinova-gen3")
WHOLE_ARM = ("RunTrajectory1", "Trajectory1", "RecordTrajectory_quadratic")
WHOLE_ARM_FILES = tuple(DATA / "identification_data" / f"{name}.csv.gz" for name in WHOLE_ARM)
JOINTWISE_FILES = tuple(DATA / "jointwise_motion" / f"joint_{k}_trapez.csv.gz" for k in range(1, 8))
PERIOD = 1e-3  # README: the Time column is a sample index, period about 1 ms


def read(path: Path) -> rd.Recording:
    """``rd.read_recording(path, spec="kinova_gen3")``; while the reader is not in the tree, the
    same columns read with pandas (Position, Velocity, Cur; Time x 1 ms)."""
    try:
        return rd.read_recording(path, spec="kinova_gen3")
    except ImportError:
        import pandas as pd

        d = pd.read_csv(path)
        cols = lambda name: d[[f"{name}{k}" for k in range(1, 8)]].to_numpy(float)  # noqa: E731
        return rd.Recording(t=d["Time"].to_numpy(float) * PERIOD, q=cols("Position"),
                            qd=cols("Velocity"), current=cols("Cur"),
                            joint_names=tuple(f"joint_{k}" for k in range(1, 8)), source=path.name)


def split(rec: rd.Recording, fraction: float = 0.7) -> tuple[rd.Recording, rd.Recording]:
    """First ``fraction`` of the samples and the rest."""
    k = int(round(fraction * rec.n_samples))
    return rec.slice(rec.t[0], rec.t[k - 1]), rec.slice(rec.t[k], rec.t[-1])


def relative_error(e: np.ndarray, y: np.ndarray) -> float:
    """``||e|| / ||y||`` (Frobenius over samples and joints)."""
    return float(np.linalg.norm(e) / np.linalg.norm(y))
