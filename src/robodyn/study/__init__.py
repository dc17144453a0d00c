"""Parameter studies on Dask: sweeps and Monte-Carlo studies over many cases.

``rd.sweep(task, cases)`` runs a picklable ``task(case) -> dict`` over a list of cases, a grid or
a sampler on a Dask cluster (a LocalCluster by default) and returns a pandas table. Ready-made
tasks: :class:`ActuatorSizing` (peak/RMS torque and power, tracking error),
:class:`CalibrationMonteCarlo` (held-out error of a kinematic calibration),
:class:`IdentificationMonteCarlo` (base parameter and held-out errors of ``rd.identify`` on
virtual-lab data) and :class:`UnderwaterEffects` (torques and free swing of an underwater arm).
"""

from robodyn.study.cases import Grid, LatinHypercube, RandomSampler, Range, case_seed, expand_cases
from robodyn.study.identification_mc import IdentificationMonteCarlo
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
from robodyn.study.underwater_task import UnderwaterEffects

__all__ = ["ERROR_COLUMN", "Grid", "IdentificationMonteCarlo", "LatinHypercube", "RandomSampler", "Range",
           "SweepInterrupted", "UnderwaterEffects", "case_seed", "default_workers", "expand_cases",
           "run_batch", "run_serial", "sweep", "table", "write_table"]
