"""Parameter studies on Dask: sweeps and Monte-Carlo studies over many cases.

``rd.sweep(task, cases)`` runs a picklable ``task(case) -> dict`` over a list of cases, a grid or
a sampler on a Dask cluster (a LocalCluster by default) and returns a pandas table. Ready-made
tasks: :class:`ActuatorSizing` (peak/RMS torque and power, tracking error) and
:class:`CalibrationMonteCarlo` (held-out error of a kinematic calibration).
"""

from robodyn.study.cases import Grid, LatinHypercube, RandomSampler, Range, case_seed, expand_cases
from robodyn.study.sweep import (
    ERROR_COLUMN,
    SweepInterrupted,
    default_workers,
    run_batch,
    run_serial,
    sweep,
    table,
    write_table,
)

__all__ = ["ERROR_COLUMN", "Grid", "LatinHypercube", "RandomSampler", "Range", "SweepInterrupted",
           "case_seed", "default_workers", "expand_cases", "run_batch", "run_serial", "sweep", "table",
           "write_table"]
