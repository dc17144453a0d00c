"""The effect series of thesis ch. 7: what each hydrodynamic effect does to an arm's motion.

The same arm is simulated in air and in water with the effects switched on one at a time, each
variant keeping the ones before it (the thesis's series)::

    dry  ->  + buoyancy  ->  + added mass  ->  + drag  ->  + lift  ->  + current

Variants are new :class:`~robodyn.robot.model.Robot` objects (the description is immutable):
``dry`` drops the ``fluid`` and ``hydro`` blocks; the others keep every link's shapes and volume
(buoyancy) and set the coefficients of the effects not yet on to zero (``added_mass`` and
``axial_added_mass``; ``drag`` and ``skin_friction``; ``lift``) and the current to zero. Each
variant is compiled once (:func:`robodyn.compile_model` caches by description and values).

Two motions per variant:

* tracked: a rest-to-rest quintic move from ``start`` to ``end`` in ``move_time`` s, then held
  for ``hold_time`` s, under the SAME plain PD controller in every variant (gains set from the
  dry arm's mass matrix at the start: ``kp_i = M_ii w^2``, ``kd_i = 2 M_ii w``,
  ``w = 2 pi bandwidth``; the controller knows nothing of the water);
* free: released at rest from ``start`` with no torque for ``free_time`` s.

Per variant and joint the table gives (N m or N; rad or m; s):

===================  ==========================================================================
``peak_tau``         max |tau| of the PD-tracked run
``rms_tau``          RMS of tau over the tracked run
``ideal_peak_tau``   max |tau| of the inverse dynamics along the plan (what the motors must give
                     to follow it exactly); ``ideal_rms_tau`` its RMS
``effect_peak_tau``  max |tau_id(this variant) - tau_id(previous variant)| along the plan: the
                     torque this effect adds
``rms_error``        RMS of the tracking error q_ref - q; ``max_error`` its largest |value|
``steady_error``     |q_ref - q| at the end of the hold
``settling``         time after the end of the move until q stays within max(2 % of the move,
                     1e-3) of its final value
``diff_vs_dry``      RMS over time of q - q_dry (tracked run)
``free_amplitude``   half the peak-to-peak swing of q over the second half of the free run
``free_diff_vs_dry`` RMS over time of q - q_dry (free run)
===================  ==========================================================================
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd
from tqdm import tqdm

from robodyn.numeric.model import Model, compile_model
from robodyn.robot.errors import StudyError
from robodyn.robot.hydro import fluid_of, with_current, with_values
from robodyn.robot.model import Robot
from robodyn.robot.overrides import checked_parameter_values
from robodyn.robot.sizes import time_grid_steps
from robodyn.simulation.controllers import PD
from robodyn.simulation.simulation import Trajectory, simulate
from robodyn.simulation.trajectory import JointTrajectory, quintic
from robodyn.studies.underwater_effects import DEFAULT_CURRENT, EFFECTS, LABELS
from robodyn.symbolic.hydro.lift_reach import lift_reaches_joints
from robodyn.text import markdown_table

__all__ = [
    "DEFAULT_CURRENT",
    "EFFECTS",
    "LABELS",
    "EffectRun",
    "EffectSeries",
    "check_series_size",
    "effect_series",
    "effect_variant",
]

#: Why the ``+ lift`` row is left out where lift cannot reach the joints in still water.
LIFT_DROPPED = (
    "No '+ lift' row: in still water lift cannot change any of this arm's joint torques, "
    "whatever C_L. Lift acts along e x u_n, normal to each link's axis and to its flow relative "
    "to the water; with the links moving in one plane that is normal to the plane, so the "
    "bearings carry it (see robodyn.symbolic.hydro.lift_reach).")
LIFT_IN_CURRENT = (" In the current of the '+ current' row it does act (the current has a "
                   "component out of the plane), and that row includes it.")
LIFT_NOT_IN_CURRENT = " Nor in the current of the '+ current' row (it lies in the plane)."

#: Coefficients each effect switches on (the others are set to zero before it).
_COEFFICIENTS: Mapping[str, tuple[str, ...]] = {
    "added_mass": ("added_mass", "axial_added_mass"), "drag": ("drag", "skin_friction"),
    "lift": ("lift",),
}


@dataclass(frozen=True, eq=False)
class EffectRun:
    """One variant of the series.

    Attributes
    ----------
    effect : str
        One of :data:`EFFECTS` (the last effect switched on).
    label : str
    robot : Robot
        The variant's description.
    tracked, free : Trajectory
        PD-tracked move and free (torque-free) motion.
    ideal_tau : (N, n) ndarray
        Inverse dynamics along the plan at the tracked run's sample times, N m (N).
    """

    effect: str
    label: str
    robot: Robot
    tracked: Trajectory
    free: Trajectory
    ideal_tau: np.ndarray


@dataclass(frozen=True, eq=False)
class EffectSeries:
    """The effect series of one robot (see the module docstring for the table's columns).

    Attributes
    ----------
    robot : str
        Name of the robot.
    runs : tuple of EffectRun
        In the order of :data:`EFFECTS`.
    reference : JointTrajectory
        The planned move (held at its end after ``move_time``).
    table : pandas.DataFrame
        One row per variant and joint.
    kp, kd : (n,) ndarray
        PD gains, N m/rad and N m s/rad (N/m, N s/m).
    current : (3,) ndarray
        Current of the ``current`` variant, base frame, m/s.
    lift : float or None
        Lift coefficient given for the ``lift`` variant (None: the description's).
    move_time, hold_time, free_time, dt : float
        s.
    notes : tuple of str
        What the series left out and why (e.g. the ``+ lift`` row on a planar arm).
    """

    robot: str
    runs: tuple[EffectRun, ...]
    reference: JointTrajectory
    table: pd.DataFrame
    kp: np.ndarray
    kd: np.ndarray
    current: np.ndarray
    lift: float | None
    move_time: float
    hold_time: float
    free_time: float
    dt: float
    notes: tuple[str, ...] = ()

    def run(self, effect: str) -> EffectRun:
        """The variant whose last effect is ``effect``."""
        for r in self.runs:
            if r.effect == effect:
                return r
        raise KeyError(f"no variant {effect!r}; the series has {', '.join(r.effect for r in self.runs)}")

    def markdown(self, digits: int = 4) -> str:
        """The table as GitHub markdown (numbers to ``digits`` significant figures)."""
        rows = [[f"{v:.{digits}g}" if isinstance(v, float) else str(v) for v in row]
                for row in self.table.itertuples(index=False)]
        return "\n".join([markdown_table(list(self.table.columns), rows), "", *self.notes]) + "\n"


def _has_hydro(robot: Robot) -> bool:
    return any(link.hydro is not None for link in robot.links)


def effect_variant(robot: Robot, effect: str, *, current: Sequence[float] | None = None,
                   lift: float | None = None) -> Robot:
    """The variant of ``robot`` with the effects of :data:`EFFECTS` up to ``effect`` switched on.

    Parameters
    ----------
    robot : Robot
        A robot with at least one ``hydro`` block (not modified).
    effect : str
        One of :data:`EFFECTS`.
    current : (3,) sequence of float, optional
        Current velocity of the ``current`` variant, base frame, m/s (default: the
        description's).
    lift : float, optional
        Lift coefficient C_L of every wet link from the ``lift`` variant on (default: the
        description's).

    Returns
    -------
    Robot
        A new robot; coefficients of effects not yet on are 0, the current is zero before the
        ``current`` variant; ``dry`` has no ``fluid`` and no ``hydro`` blocks.

    Raises
    ------
    StudyError
        An unknown effect, a robot without hydro blocks.
    """
    if effect not in EFFECTS:
        raise StudyError(f"unknown effect {effect!r}; choose one of {', '.join(EFFECTS)}")
    if not _has_hydro(robot):
        raise StudyError(
            f"{robot.source}: robot {robot.name!r} has no hydro blocks: the underwater study needs "
            "links with a 'hydro' block (cylinders, coefficients) and a 'fluid' block "
            "(see docs/underwater.md)")
    level = EFFECTS.index(effect)
    if level == 0:
        links = tuple(dataclasses.replace(lk, hydro=None) for lk in robot.links)
        return dataclasses.replace(robot, links=links, fluid=None)
    links = []
    for lk in robot.links:
        if lk.hydro is None:
            links.append(lk)
            continue
        values: dict[str, float] = {}
        for name, keys in _COEFFICIENTS.items():
            for key in keys:
                if level < EFFECTS.index(name):
                    values[key] = 0.0
                elif key == "lift" and lift is not None:
                    values[key] = float(lift)
        links.append(dataclasses.replace(lk, hydro=with_values(lk.hydro, values)))
    fluid = fluid_of(robot)
    if level < EFFECTS.index("current"):
        fluid = with_current(fluid, [0.0, 0.0, 0.0])
    elif current is not None:
        fluid = with_current(fluid, current)
    return dataclasses.replace(robot, links=tuple(links), fluid=fluid)


def _series_current(robot: Robot, parameters: Mapping[str, float],
                    current: Sequence[float] | None) -> np.ndarray:
    """The current of the ``current`` variant: given, else the description's, else the default."""
    if current is not None:
        c = np.asarray(current, dtype=float)
        if c.shape != (3,) or not np.all(np.isfinite(c)):
            raise StudyError(f"current must be three finite numbers (m/s), got {current!r}")
        return c
    fluid = fluid_of(robot)
    values = {**{k: float(v) for k, v in robot.parameters.items()}, **parameters}
    subs = {s: values[s.name] for s in fluid.current.free_symbols} if fluid else {}
    c = np.array([float(e.xreplace(subs)) for e in fluid.current]) if fluid else np.zeros(3)
    return c if np.any(c) else np.array(DEFAULT_CURRENT)


def _default_move(robot: Robot, parameters: Mapping[str, float]) -> tuple[np.ndarray, np.ndarray]:
    """Start at 0 (or mid-range), move +0.8 rad per revolute joint, +0.1 m per prismatic."""
    values = {**{k: float(v) for k, v in robot.parameters.items()}, **parameters}
    start, end = np.zeros(robot.dof), np.zeros(robot.dof)
    for i, j in enumerate(robot.joints):
        lo, hi = (None if b is None else float(b.subs({s: values[s.name] for s in b.free_symbols}))
                  for b in (j.lower, j.upper))
        step = 0.1 if j.type == "prismatic" else 0.8
        s = 0.0 if lo is None or hi is None else 0.5 * (lo + hi)
        s = s if lo is None or s >= lo else lo
        end_i = s + step if hi is None or s + step <= hi else s - step
        start[i], end[i] = s, end_i
    return start, end


def _settling(t: np.ndarray, q: np.ndarray, t_end: float, band: np.ndarray) -> np.ndarray:
    """Per joint: time after ``t_end`` after which |q - q_final| stays within ``band``, s."""
    out = np.zeros(q.shape[1])
    after = t >= t_end
    for i in range(q.shape[1]):
        outside = np.abs(q[after, i] - q[-1, i]) > band[i]
        if outside.any():
            last = np.flatnonzero(outside)[-1]
            out[i] = t[after][min(last + 1, outside.size - 1)] - t_end
    return out


def _rms(a: np.ndarray) -> np.ndarray:
    return np.sqrt(np.mean(a**2, axis=0))


def effect_model(robot: Robot, effect: str, parameters: Mapping[str, float], *, backend: str = "c",
                 current: Sequence[float] | None = None, lift: float | None = None) -> Model:
    """The compiled model :func:`effect_series` simulates for ``effect`` (one of :data:`EFFECTS`).

    ``current`` as in :func:`effect_series` (None: the description's, else the default);
    ``parameters`` are compiled in. Compiled once per description and values (cached), so
    study tasks list these models for a sweep to ship (:mod:`robodyn.studies.shipping`).
    """
    c = _series_current(robot, parameters, current)
    variant = effect_variant(robot, effect, current=c, lift=lift)
    return compile_model(variant, backend=backend, parameters=dict(parameters))  # type: ignore[arg-type]


def effect_series(robot: Robot, *, start: Sequence[float] | None = None,
                  end: Sequence[float] | None = None, move_time: float = 2.0,
                  hold_time: float = 1.0, free_time: float = 3.0, dt: float = 1e-3,
                  bandwidth: float = 2.0, current: Sequence[float] | None = None,
                  lift: float | None = None, parameters: Mapping[str, float] | None = None,
                  effects: Sequence[str] = EFFECTS, backend: str = "c",
                  progress: bool = False) -> EffectSeries:
    """Simulate the effect series of an underwater arm (thesis ch. 7).

    Parameters
    ----------
    robot : Robot
        With at least one ``hydro`` block (e.g. ``rd.load("underwater_2r")``).
    start, end : (n,) sequence of float, optional
        Ends of the tracked move, rad (m); the free run starts at ``start``. Default: 0 (the
        middle of the joint range when limited) and +0.8 rad (+0.1 m) per joint.
    move_time, hold_time, free_time : float
        Duration of the quintic move, of the hold after it and of the free run, s (each a whole
        number of ``dt``).
    dt : float
        RK4 step and sample interval, s.
    bandwidth : float
        Closed-loop natural frequency of the PD gains, Hz.
    current : (3,) sequence of float, optional
        Current of the ``current`` variant, base frame, m/s. Default: the description's current
        at ``parameters`` when it is not zero, else :data:`DEFAULT_CURRENT`.
    lift : float, optional
        C_L of every wet link from the ``lift`` variant on (default: the description's; zero for
        circular sections, so ``+ lift`` then repeats ``+ drag``).
    parameters : mapping of str to float, optional
        Values of the description's named parameters for every variant.
    effects : sequence of str
        Variants to run, a subset of :data:`EFFECTS` in any order (``dry`` is always run: the
        differences are against it).
    backend : {"c", "numpy"}
        Backend of :func:`robodyn.compile_model`.
    progress : bool
        Show a tqdm progress bar on stderr.

    Returns
    -------
    EffectSeries

    Raises
    ------
    StudyError
        A robot without hydro blocks, an unknown effect, a bad current or move.
    """
    params = dict(parameters or {})
    unknown = [e for e in effects if e not in EFFECTS]
    if unknown:
        raise StudyError(f"unknown effect(s) {', '.join(map(repr, unknown))}; choose from "
                         f"{', '.join(EFFECTS)}")
    chosen = [e for e in EFFECTS if e == "dry" or e in effects]
    effect_variant(robot, "dry")  # refuses a robot without hydro blocks before any work
    # unknown names and impossible values are refused before the progress bar starts
    checked_parameter_values(robot, params, where="effect_series(parameters=...)")
    c = _series_current(robot, params, current)
    notes = []
    if "lift" in chosen and not lift_reaches_joints(robot, (0.0, 0.0, 0.0), params):
        chosen.remove("lift")
        in_current = lift_reaches_joints(robot, c, params)
        notes.append(LIFT_DROPPED + (LIFT_IN_CURRENT if in_current else LIFT_NOT_IN_CURRENT))
    n = robot.dof
    q0, q1 = _default_move(robot, params)
    if start is not None:
        q0 = _move_vector(start, n, "start")
    if end is not None:
        q1 = _move_vector(end, n, "end")
    check_series_size(n, len(chosen), move_time, hold_time, free_time, dt)
    reference = quintic(q0, q1, move_time, dt=dt)
    duration = move_time + hold_time
    t = dt * np.arange(round(duration / dt) + 1)
    q_r, qd_r, qdd_r = reference.at(t)
    runs: list[EffectRun] = []
    kp = kd = np.zeros(n)
    bar = tqdm(chosen, desc=f"underwater {robot.name}", unit="variant", disable=not progress)
    for effect in bar:
        bar.set_postfix_str(LABELS[effect])
        model = effect_model(robot, effect, params, backend=backend, current=c, lift=lift)
        variant = model.robot
        if effect == "dry":
            kp, kd = _gains(model, q0, bandwidth)
        tracked = simulate(model, q0, None, duration, dt, controller=PD(kp, kd, reference))
        free = simulate(model, q0, None, free_time, dt)
        ideal = model.inverse_dynamics(q_r, qd_r, qdd_r)
        runs.append(EffectRun(effect=effect, label=LABELS[effect], robot=variant, tracked=tracked,
                              free=free, ideal_tau=ideal))
    table = _table(robot, runs, reference, move_time, q_r)
    return EffectSeries(robot=robot.name, runs=tuple(runs), reference=reference, table=table,
                        kp=kp, kd=kd, current=c, lift=lift, move_time=move_time,
                        hold_time=hold_time, free_time=free_time, dt=dt, notes=tuple(notes))


#: Cost of one step of a computed-torque run of the model-error study (RK4 with the controller
#: evaluated in every stage, about 400 us), in values of the grid bound (about 1 us each).
CONTINUOUS_STEP_VALUES = 400


def check_series_size(n: int, variants: int, move_time: float, hold_time: float,
                      free_time: float, dt: float, *, where: str = "effect_series",
                      names: tuple[str, str, str, str] = ("move_time", "hold_time", "free_time",
                                                          "dt"), model_error: int = 0) -> None:
    """Refuse an effect series whose samples would not fit, before anything is simulated.

    Every variant keeps a tracked run and a free run (t, q, qd, qdd, tau and three energies) and
    its ideal torques, besides the reference: about ``variants (4 + 5 n) + 1 + 6 n`` values a
    sample of ``move_time + hold_time + free_time``, bounded by
    :func:`robodyn.robot.sizes.time_grid_steps` (``$ROBODYN_MAX_GRID_SAMPLES`` raises it).

    Parameters
    ----------
    n : int
        Joints.
    variants : int
        Effect variants simulated.
    move_time, hold_time, free_time, dt : float
        s, each positive.
    where : str
        The function or command, for the message.
    names : tuple of str
        The names the user gave the three durations and the step (the command line's options).
    model_error : int
        Computed-torque runs of the model-error study to come (``robodyn underwater`` without
        ``--series-only``): each adds :data:`CONTINUOUS_STEP_VALUES` a sample, so that the whole
        study ends in about a minute.

    Raises
    ------
    InputError
        A non-positive duration or step, or too many samples.
    """
    move, hold, free, step = names
    for name, value in ((move, move_time), (hold, hold_time), (free, free_time)):
        time_grid_steps(value, dt, where, duration_name=name, dt_name=step)
    time_grid_steps(move_time + hold_time + free_time, dt, where,
                    duration_name=f"{move} + {hold} + {free}", dt_name=step,
                    values_per_sample=variants * (4 + 5 * n) + 1 + 6 * n
                    + model_error * CONTINUOUS_STEP_VALUES)


def _move_vector(v: Sequence[float], n: int, name: str) -> np.ndarray:
    a = np.asarray(v, dtype=float)
    if a.shape != (n,) or not np.all(np.isfinite(a)):
        raise StudyError(f"{name} must be {n} finite joint positions, got {v!r}")
    return a


def _gains(model: Model, q0: np.ndarray, bandwidth: float) -> tuple[np.ndarray, np.ndarray]:
    """PD gains from the dry mass matrix diagonal: kp = M_ii w^2, kd = 2 M_ii w (critical)."""
    if not np.isfinite(bandwidth) or bandwidth <= 0:
        raise StudyError(f"bandwidth must be a positive frequency in Hz, got {bandwidth!r}")
    w = 2 * np.pi * bandwidth
    m = np.diag(model.mass_matrix(q0))
    return m * w**2, 2 * m * w


def _table(robot: Robot, runs: list[EffectRun], reference: JointTrajectory, move_time: float,
           q_r: np.ndarray) -> pd.DataFrame:
    dry = runs[0]
    q_end = q_r[-1]
    # settling band: 2 % of the move, at least 1 mrad (1 mm)
    band = np.maximum(0.02 * np.abs(reference.q[-1] - reference.q[0]), 1e-3)
    rows = []
    previous = dry.ideal_tau
    for run in runs:
        tr, fr = run.tracked, run.free
        half = fr.q[fr.q.shape[0] // 2:]
        cols = {
            "peak_tau": np.abs(tr.tau).max(axis=0),
            "rms_tau": _rms(tr.tau),
            "ideal_peak_tau": np.abs(run.ideal_tau).max(axis=0),
            "ideal_rms_tau": _rms(run.ideal_tau),
            # the torque this effect adds to the plan's inverse dynamics
            "effect_peak_tau": np.abs(run.ideal_tau - previous).max(axis=0),
            "rms_error": _rms(q_r - tr.q),
            "max_error": np.abs(q_r - tr.q).max(axis=0),
            "steady_error": np.abs(q_end - tr.q[-1]),
            "settling": _settling(tr.t, tr.q, move_time, band),
            "diff_vs_dry": _rms(tr.q - dry.tracked.q),
            # half the peak-to-peak swing over the second half of the free run
            "free_amplitude": 0.5 * (half.max(axis=0) - half.min(axis=0)),
            "free_diff_vs_dry": _rms(fr.q - dry.free.q),
        }
        previous = run.ideal_tau
        for i, joint in enumerate(robot.joint_names):
            rows.append({"variant": run.label, "effect": run.effect, "joint": joint,
                         **{k: float(v[i]) for k, v in cols.items()}})
    return pd.DataFrame(rows)
