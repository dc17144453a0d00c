"""The controller-design question of thesis ch. 7: which effect must the controller's model keep?

The plant is the arm with every effect on (buoyancy, added mass, drag, lift and the current). It
tracks the same quintic move under a computed-torque controller
``tau = M^(q) (qdd_ref + Kp e + Kd ed) + h^(q, qd)`` whose model ``M^, h^`` omits one effect in
turn (:data:`OMITTED`; ``nothing``: the exact model; ``everything``: the dry arm's model). The
control law is evaluated at every RK4 stage (a continuous-time controller), so with the exact
model the error stays at the integrator's round-off (``e(0) = 0`` and ``e'' + Kd e' + Kp e = 0``).

A model that omits buoyancy over-estimates the gravity load by ``-g_B`` (``g_B < 0`` when the arm
is lighter in water), and at rest the error settles where ``M Kp e = g_B``::

    e_ss = Kp^-1 M(q)^-1 g_B(q)            (predicted_error; e = q_ref - q)

Per omitted effect and joint the table gives ``rms_error``, ``max_error`` (rad or m),
``steady_error`` (signed ``q_ref - q`` at the end of the hold) and ``peak_tau`` (N m or N).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd
from tqdm import tqdm

from robodyn.numeric.model import Model, compile_model
from robodyn.robot.errors import StudyError
from robodyn.robot.hydro import fluid_of, with_current, with_values
from robodyn.robot.model import Robot
from robodyn.simulation.controllers import ComputedTorque
from robodyn.simulation.simulation import Trajectory, simulate
from robodyn.simulation.trajectory import JointTrajectory
from robodyn.studies.underwater import effect_variant
from robodyn.symbolic.hydro.lift_reach import lift_reaches_joints

__all__ = ["OMITTED", "ModelErrorStudy", "model_error_study", "model_without"]

#: What the controller's model leaves out, in the order of the table.
OMITTED: tuple[str, ...] = ("nothing", "added_mass", "buoyancy", "drag", "lift", "current",
                            "everything")
#: Hydro keys each omission sets to zero.
_KEYS: Mapping[str, tuple[str, ...]] = {
    "added_mass": ("added_mass", "axial_added_mass"), "buoyancy": ("volume",),
    "drag": ("drag", "skin_friction"), "lift": ("lift",),
}


@dataclass(frozen=True, eq=False)
class ModelErrorStudy:
    """Computed-torque tracking of the full underwater plant with incomplete models.

    Attributes
    ----------
    robot : str
    reference : JointTrajectory
    runs : dict of str to Trajectory
        One run per entry of :data:`OMITTED`.
    table : pandas.DataFrame
        One row per omitted effect and joint (see the module docstring).
    kp, kd : (n,) ndarray
        Error-dynamics gains, 1/s^2 and 1/s.
    predicted_error : (n,) ndarray
        ``Kp^-1 M^-1 g_B`` at the end of the buoyancy-omitting run, rad (m).
    current : (3,) ndarray
        The plant's current, base frame, m/s.
    notes : tuple of str
        What the study left out and why (the ``lift`` row where lift cannot reach the joints).
    """

    robot: str
    reference: JointTrajectory
    runs: dict[str, Trajectory]
    table: pd.DataFrame
    kp: np.ndarray
    kd: np.ndarray
    predicted_error: np.ndarray
    current: np.ndarray
    notes: tuple[str, ...] = ()


def model_without(full: Robot, effect: str) -> Robot:
    """``full`` (every effect on; not modified) without ``effect`` (one of :data:`OMITTED`)."""
    if effect not in OMITTED:
        raise StudyError(f"unknown effect {effect!r}; choose one of {', '.join(OMITTED)}")
    if effect == "nothing":
        return full
    if effect == "everything":
        return effect_variant(full, "dry")
    if effect == "current":
        fluid = with_current(fluid_of(full), [0.0, 0.0, 0.0])
        return dataclasses.replace(full, fluid=fluid)
    links = tuple(lk if lk.hydro is None else dataclasses.replace(
        lk, hydro=with_values(lk.hydro, dict.fromkeys(_KEYS[effect], 0.0))) for lk in full.links)
    return dataclasses.replace(full, links=links)


def model_error_study(robot: Robot, reference: JointTrajectory, duration: float, *,
                      dt: float = 1e-3, bandwidth: float = 2.0,
                      current: Sequence[float] = (0.5, 0.0, 0.0), lift: float | None = None,
                      parameters: Mapping[str, float] | None = None,
                      omitted: Sequence[str] = OMITTED, backend: str = "c",
                      progress: bool = False) -> ModelErrorStudy:
    """Track ``reference`` on the full plant with a computed-torque model that omits each effect.

    Parameters
    ----------
    robot : Robot
        With hydro blocks (not modified).
    reference : JointTrajectory
        The move (held at its end); the run starts on it at rest.
    duration : float
        Simulated time, s (move and hold).
    dt : float
        RK4 step, s.
    bandwidth : float
        Error-dynamics natural frequency, Hz: ``Kp = w^2``, ``Kd = 2 w``, ``w = 2 pi bandwidth``.
    current : (3,) sequence of float
        The plant's current, base frame, m/s.
    lift : float, optional
        C_L of every wet link (default: the description's).
    parameters : mapping of str to float, optional
    omitted : sequence of str
        The models to try, a subset of :data:`OMITTED` (run in its order).
    backend : {"c", "numpy"}
    progress : bool

    Returns
    -------
    ModelErrorStudy
        ``predicted_error`` is NaN unless ``buoyancy`` is among ``omitted``.
    """
    if not np.isfinite(bandwidth) or bandwidth <= 0:
        raise StudyError(f"bandwidth must be a positive frequency in Hz, got {bandwidth!r}")
    unknown = [e for e in omitted if e not in OMITTED]
    if unknown:
        raise StudyError(f"unknown effect(s) {', '.join(map(repr, unknown))}; choose from "
                         f"{', '.join(OMITTED)}")
    params = dict(parameters or {})
    c = np.asarray(current, dtype=float)
    full = effect_variant(robot, "current", current=c, lift=lift)
    plant = compile_model(full, backend=backend, parameters=params)  # type: ignore[arg-type]
    n = robot.dof
    w = 2 * np.pi * bandwidth
    kp, kd = np.full(n, w**2), np.full(n, 2 * w)
    q0 = reference.at(np.zeros(1))[0][0]
    t_end = dt * round(duration / dt)
    q_end = reference.at(np.array([t_end]))[0][0]
    runs: dict[str, Trajectory] = {}
    models: dict[str, Model] = {}
    rows: list[dict[str, Any]] = []
    chosen = [e for e in OMITTED if e in omitted]
    notes: tuple[str, ...] = ()
    if "lift" in chosen and not lift_reaches_joints(robot, c, params):
        chosen.remove("lift")
        notes = ("No 'lift' row: on this arm lift cannot change any joint torque (it acts normal "
                 "to the plane of motion; see robodyn.symbolic.hydro.lift_reach).",)
    for effect in tqdm(chosen, desc=f"model error {robot.name}", unit="model",
                       disable=not progress):
        model = plant if effect == "nothing" else compile_model(  # type: ignore[arg-type]
            model_without(full, effect), backend=backend, parameters=params)
        models[effect] = model
        law = ComputedTorque(reference, np.diag(kp), np.diag(kd),
                             model=None if effect == "nothing" else model)
        run = simulate(plant, q0, None, t_end, dt, controller=law, control="continuous")
        runs[effect] = run
        q_r = reference.at(run.t)[0]
        err = q_r - run.q
        cols = {"rms_error": np.sqrt(np.mean(err**2, axis=0)), "max_error": np.abs(err).max(axis=0),
                "steady_error": q_end - run.q[-1], "peak_tau": np.abs(run.tau).max(axis=0)}
        for i, joint in enumerate(robot.joint_names):
            rows.append({"omitted": effect, "joint": joint,
                         **{k: float(v[i]) for k, v in cols.items()}})
    predicted = np.full(n, np.nan)
    if "buoyancy" in runs:
        # e_ss = Kp^-1 M^-1 g_B at the settled pose of the buoyancy-omitting run
        q_ss = runs["buoyancy"].q[-1]
        g_b = plant.gravity(q_ss) - models["buoyancy"].gravity(q_ss)
        predicted = np.linalg.solve(plant.mass_matrix(q_ss), g_b) / kp
    return ModelErrorStudy(robot=robot.name, reference=reference, runs=runs,
                           table=pd.DataFrame(rows), kp=kp, kd=kd, predicted_error=predicted,
                           current=c, notes=notes)
