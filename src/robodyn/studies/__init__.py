"""Parameter studies on Dask: sweeps and Monte-Carlo studies over many cases.

``rd.sweep(task, cases)`` runs a picklable ``task(case) -> dict`` over a list of cases, a grid or
a sampler on a Dask cluster (a LocalCluster by default) and returns a pandas table. Ready-made
tasks: :class:`ActuatorSizing` (peak/RMS torque and power, tracking error),
:class:`CalibrationMonteCarlo` (held-out error of a kinematic calibration),
:class:`IdentificationMonteCarlo` (base parameter and held-out errors of ``rd.identify`` on
virtual-lab data) and :class:`UnderwaterEffects` (torques and free swing of an underwater arm).
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

# Imported on first use (PEP 562): the package also holds light modules that the command line
# reads for its help (underwater_effects), which must not pull in Dask, pandas or SymPy.
_EXPORTS = {
    **dict.fromkeys(("Grid", "LatinHypercube", "RandomSampler", "Range", "case_seed", "expand_cases"),
                    "robodyn.studies.cases"),
    "IdentificationMonteCarlo": "robodyn.studies.identification_mc",
    **dict.fromkeys(("ERROR_COLUMN", "SweepInterrupted", "default_workers", "run_batch", "run_serial",
                     "sweep", "table", "write_table"), "robodyn.studies.sweeps"),
    "UnderwaterEffects": "robodyn.studies.underwater_task",
}

if TYPE_CHECKING:
    from robodyn.studies.cases import Grid, LatinHypercube, RandomSampler, Range, case_seed, expand_cases
    from robodyn.studies.identification_mc import IdentificationMonteCarlo
    from robodyn.studies.sweeps import (
        ERROR_COLUMN,
        SweepInterrupted,
        default_workers,
        run_batch,
        run_serial,
        sweep,
        table,
        write_table,
    )
    from robodyn.studies.underwater_task import UnderwaterEffects


def __getattr__(name: str) -> Any:
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'robodyn.studies' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


__all__ = ["ERROR_COLUMN", "Grid", "IdentificationMonteCarlo", "LatinHypercube", "RandomSampler", "Range",
           "SweepInterrupted", "UnderwaterEffects", "case_seed", "default_workers", "expand_cases",
           "run_batch", "run_serial", "sweep", "table", "write_table"]
