"""The small AA300 sizing sweep of ``make demo``: payload x bandwidth on the local Dask cluster."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from robodyn.studies.models import RobotSource
from robodyn.studies.sizing import ActuatorSizing
from robodyn.studies.sweeps import sweep, write_table

__all__ = ["aa300_sweep_demo"]


def aa300_sweep_demo(directory: str | Path, *, workers: int | None = None,
                     progress: bool = True) -> tuple[pd.DataFrame, str]:
    """Size the AA300's actuators over 3 payloads x 3 PD bandwidths (9 cycles) on a LocalCluster.

    Writes ``aa300_sweep.parquet``/``.csv`` and the figures to ``directory``; returns the table
    and the report section (HTML fragment) to put in the demo report.
    """
    from robodyn.report.study_report import study_figures, study_section

    out = Path(directory)
    task = ActuatorSizing(RobotSource.of("aa300"), dt=2e-3)
    grid = {"payload": [0.0, 25.0, 50.0], "bandwidth_hz": [2.0, 4.0, 8.0]}
    table = sweep(task, grid, workers=workers, progress=progress)
    write_table(table, out, "aa300_sweep")
    varying = ("payload", "bandwidth_hz")
    figures = study_figures(table, varying, out / "aa300_sweep",
                            {"x": "payload", "y": "bandwidth_hz", "result": "peak_torque.column"})
    return table, study_section(table, title="AA300 actuator sizing sweep", varying=varying,
                                figures=figures)
