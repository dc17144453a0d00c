"""Sensitivity of an underwater arm to the drag coefficient and to the current speed.

Two small sweeps on the arm with every effect on (the ``current``/``lift`` variant of
:func:`robodyn.studies.underwater.effect_variant`):

* ``C_d``: every wet link's normal drag coefficient set to each value, in still water;
* ``current``: the current set to each speed along a fixed direction, C_d as described.

Per value and joint the table gives (N m or N; rad or m):

===================  ==========================================================================
``added_peak_tau``   max |tau_id(wet) - tau_id(dry)| along the planned move: the torque the fluid
                     adds to what the motors must give to follow it exactly
``added_rms_tau``    RMS of that difference
``free_amplitude``   half the peak-to-peak swing of q over the second half of the free run (released
                     at rest from the start of the move, no torque)
``free_mean``        mean of q over that half (where the free swing settles: a current shifts it)
``free_rms_speed``   RMS of qd over that half, rad/s (m/s): how much motion drag has left
===================  ==========================================================================
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd
from tqdm import tqdm

from robodyn.numeric.model import compile_model
from robodyn.robot.errors import StudyError
from robodyn.robot.hydro import with_values
from robodyn.robot.model import Robot
from robodyn.simulation.simulation import Trajectory, simulate
from robodyn.simulation.trajectory import JointTrajectory
from robodyn.studies.underwater import effect_variant
from robodyn.studies.underwater_effects import DEFAULT_CD_VALUES, DEFAULT_CURRENT_SPEEDS

__all__ = ["DEFAULT_CD_VALUES", "DEFAULT_CURRENT_SPEEDS", "Sensitivity", "sensitivity",
           "with_drag_coefficient"]



@dataclass(frozen=True, eq=False)
class Sensitivity:
    """Both sweeps of one robot.

    Attributes
    ----------
    robot : str
    cd_values : (K,) ndarray
        C_d of every wet link, per case of the first sweep.
    current_speeds : (J,) ndarray
        m/s, per case of the second sweep.
    direction : (3,) ndarray
        Unit direction of the current, base frame.
    table : pandas.DataFrame
        Columns ``parameter`` ("C_d" or "current"), ``value``, ``joint`` and those of the module
        docstring; one row per case and joint.
    free : dict of (str, float) to Trajectory
        The free run of each case.
    """

    robot: str
    cd_values: np.ndarray
    current_speeds: np.ndarray
    direction: np.ndarray
    table: pd.DataFrame
    free: dict[tuple[str, float], Trajectory]


def with_drag_coefficient(robot: Robot, cd: float) -> Robot:
    """``robot`` (not modified) with every wet link's normal drag coefficient set to ``cd``."""
    if not np.isfinite(cd) or cd < 0:
        raise StudyError(f"drag coefficient must be a finite number >= 0, got {cd!r}")
    links = tuple(lk if lk.hydro is None
                  else dataclasses.replace(lk, hydro=with_values(lk.hydro, {"drag": cd}))
                  for lk in robot.links)
    return dataclasses.replace(robot, links=links)


def _values(values: Sequence[float], name: str) -> np.ndarray:
    a = np.asarray(values, dtype=float)
    if a.ndim != 1 or a.size == 0 or not np.all(np.isfinite(a)) or np.any(a < 0):
        raise StudyError(f"{name} must be one or more finite numbers >= 0, got {values!r}")
    return a


def sensitivity(robot: Robot, reference: JointTrajectory, t: np.ndarray, *,
                free_time: float = 3.0, dt: float = 1e-3,
                cd_values: Sequence[float] = DEFAULT_CD_VALUES,
                current_speeds: Sequence[float] = DEFAULT_CURRENT_SPEEDS,
                direction: Sequence[float] = (1.0, 0.0, 0.0), lift: float | None = None,
                parameters: Mapping[str, float] | None = None, backend: str = "c",
                progress: bool = False) -> Sensitivity:
    """Sweep C_d and the current speed; added torque along a plan and the free decay.

    Parameters
    ----------
    robot : Robot
        With hydro blocks (not modified).
    reference : JointTrajectory
        The planned move; its inverse dynamics is evaluated at times ``t``.
    t : (N,) ndarray
        Sample times of the plan, s.
    free_time, dt : float
        Free run duration and RK4 step, s; the free run starts at rest at ``reference.q[0]``.
    cd_values : sequence of float
        C_d of every wet link, one case each (still water).
    current_speeds : sequence of float
        Current speeds, m/s, along ``direction`` (C_d as described).
    direction : (3,) sequence of float
        Direction of the current, base frame (normalised here).
    lift : float, optional
        C_L of every wet link (default: the description's).
    parameters : mapping of str to float, optional
        Values of the description's named parameters.
    backend : {"c", "numpy"}
    progress : bool
        A tqdm bar on stderr.

    Returns
    -------
    Sensitivity

    Raises
    ------
    StudyError
        Negative or non-finite sweep values, a zero direction, a robot without hydro blocks.
    """
    cds, speeds = _values(cd_values, "cd_values"), _values(current_speeds, "current_speeds")
    d = np.asarray(direction, dtype=float)
    if d.shape != (3,) or not np.all(np.isfinite(d)) or not np.linalg.norm(d) > 0:
        raise StudyError(f"current direction must be three finite numbers, not all zero, got "
                         f"{direction!r}")
    d = d / np.linalg.norm(d)
    params = dict(parameters or {})
    q_r, qd_r, qdd_r = reference.at(t)
    dry = compile_model(effect_variant(robot, "dry"), backend=backend,  # type: ignore[arg-type]
                        parameters=params)
    tau_dry = dry.inverse_dynamics(q_r, qd_r, qdd_r)
    cases: list[tuple[str, float, Robot]] = []
    for cd in cds:
        still = effect_variant(robot, "lift", lift=lift)
        cases.append(("C_d", float(cd), with_drag_coefficient(still, float(cd))))
    for v in speeds:
        cases.append(("current", float(v), effect_variant(robot, "current", current=v * d, lift=lift)))
    rows: list[dict[str, Any]] = []
    free: dict[tuple[str, float], Trajectory] = {}
    for name, value, variant in tqdm(cases, desc=f"sensitivity {robot.name}", unit="case",
                                     disable=not progress):
        model = compile_model(variant, backend=backend, parameters=params)  # type: ignore[arg-type]
        added = model.inverse_dynamics(q_r, qd_r, qdd_r) - tau_dry
        run = simulate(model, q_r[0], None, free_time, dt)
        half = run.q[run.q.shape[0] // 2:]
        free[(name, value)] = run
        cols = {
            "added_peak_tau": np.abs(added).max(axis=0),
            "added_rms_tau": np.sqrt(np.mean(added**2, axis=0)),
            # half the peak-to-peak swing over the second half of the free run
            "free_amplitude": 0.5 * (half.max(axis=0) - half.min(axis=0)),
            "free_mean": half.mean(axis=0),
            "free_rms_speed": np.sqrt(np.mean(run.qd[run.qd.shape[0] // 2:] ** 2, axis=0)),
        }
        for i, joint in enumerate(robot.joint_names):
            rows.append({"parameter": name, "value": value, "joint": joint,
                         **{k: float(c[i]) for k, c in cols.items()}})
    return Sensitivity(robot=robot.name, cd_values=cds, current_speeds=speeds, direction=d,
                       table=pd.DataFrame(rows), free=free)
