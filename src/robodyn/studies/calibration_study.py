"""Simulation study: calibrating a "true" PUMA 560 with manufacturing errors from tracker data.

The true robot is the nominal description with every joint placement ``pre_i`` moved by a random
rigid error (normal, ``length_error`` per coordinate, ``angle_error`` per axis) and every joint
given a zero offset (normal, ``offset_error``); a tracker in its own frame (a few metres away,
turned about the vertical, slightly tilted) measures a target on the flange with Gaussian noise
of ``sigma`` per coordinate. Each error model is calibrated on ``n_poses`` random poses and
checked on ``n_test`` other poses: "before" is the nominal kinematics with the tracker placement
and target offset fitted, "after" the calibrated model; held-out errors are against the noisy
measurements (what a user sees) and against the noise-free truth.

The errors are not drawn in the parameters of any one error model, but they are purely geometric:
a rigid error of each joint placement and a joint zero offset. Such a "true" robot lies inside the
span of every *complete* model (Hayati, S-model, POE), which can therefore represent it exactly
and is only limited by the noise here: this study does not show how a model copes with errors
outside its span (see ``tests/calibration/test_nongeometric.py`` for a truth with joint compliance
and transmission errors, which no geometric model spans). Only standard DH, which is not complete,
shows a model error: it has no rotation about the common normal's perpendicular at the parallel
joints 2 and 3 of the PUMA, and its ``d2`` and ``d3`` only enter as their sum. Non-geometric
errors (joint compliance, transmission errors) are not simulated in this function.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from robodyn.calibration.frames import robot_frames, robot_positions
from robodyn.calibration.kinematics import hom, rot, trans
from robodyn.calibration.nominal import numeric, robot_geometry
from robodyn.calibration.pipeline import calibrate, nominal_placement, random_configurations
from robodyn.calibration.result import Calibration, ErrorStats
from robodyn.calibration.solve import fit
from robodyn.calibration.to_robot import sym
from robodyn.robot.model import Robot

__all__ = ["RUNS", "StudyCase", "StudyResult", "circle_sets", "perturbed_robot", "puma_study",
           "robot_frames", "robot_positions"]

#: The study's calibrations: (error model, initial estimate).
RUNS = (("dh", "nominal"), ("dh", "circle-point"), ("hayati", "nominal"), ("s-model", "circle-point"),
        ("s-model", "nominal"), ("poe", "nominal"))


def _small_rotation(v: np.ndarray) -> np.ndarray:
    """Rotation by the rotation vector ``v`` (rad), shape (3, 3)."""
    angle = np.linalg.norm(v)
    if angle == 0:
        return np.eye(3)
    k = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]]) / angle
    return np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * k @ k


def perturbed_robot(robot: Robot, rng: np.random.Generator | int, *, length_error: float = 1e-3,
                    angle_error: float = math.radians(0.1), offset_error: float = math.radians(0.1),
                    base: np.ndarray | None = None, target: Sequence[float] | None = None) -> Robot:
    """A "true" robot: the nominal one with random manufacturing errors (module docstring).

    Parameters
    ----------
    robot : Robot
    rng : numpy.random.Generator or int
    length_error : float
        Standard deviation of each placement coordinate error, m.
    angle_error : float
        Standard deviation of each placement rotation error, rad.
    offset_error : float
        Standard deviation of each joint zero offset, rad (m for prismatic joints: ``length_error``).
    base : numpy.ndarray, shape (4, 4), optional
        Robot world frame in the instrument frame (default: the robot's own base).
    target : sequence of float, optional
        Target position in the tool frame, m.

    Returns
    -------
    Robot
        Numeric kinematics; links, drives and friction unchanged.
    """
    rng = np.random.default_rng(rng)
    subs = robot.defaults()
    joints = []
    for joint in robot.joints:
        pre = numeric(joint.pre, subs)
        axis = numeric(joint.axis, subs).ravel()
        axis /= np.linalg.norm(axis)
        err = hom(_small_rotation(rng.normal(0, angle_error, 3)), rng.normal(0, length_error, 3))
        if joint.type == "revolute":
            zero = hom(_small_rotation(axis * rng.normal(0, offset_error)))
        else:
            zero = hom(None, axis * rng.normal(0, length_error))
        joints.append(replace(joint, pre=sym(pre @ err @ zero), post=sym(numeric(joint.post, subs)),
                              axis=sym(axis[:, None])))
    b = numeric(robot.base, subs)
    if base is not None:
        b = np.asarray(base, dtype=float) @ b
    tool = numeric(robot.tool, subs)
    if target is not None:
        tool = tool @ trans(*target)
    return Robot(name=f"{robot.name}_true", joints=tuple(joints), links=robot.links, base=sym(b),
                 tool=sym(tool), gravity=robot.gravity, parameters=dict(robot.parameters),
                 source=f"perturbed from {robot.source}")


#: PUMA 560 readings the circle-point sweeps start from (each joint then sweeps +-1 rad), rad.
HOME = np.array([0.0, 0.5, -0.5, 0.3, 0.6, 0.2])


def circle_sets(true: Robot, home: np.ndarray, rng: np.random.Generator, sigma: float,
                count: int = 12, sweep: float = 1.0) -> list[tuple[np.ndarray, np.ndarray]]:
    """Circle-point data of ``true``: each joint in turn sweeps ``home[j] +- sweep`` (``count`` points).

    Returns one ``(q (count, n), points (count, 3))`` per joint, with Gaussian noise ``sigma`` (m).
    """
    sets = []
    for j in range(true.dof):
        qs = np.tile(home, (count, 1))
        qs[:, j] = home[j] + np.linspace(-sweep, sweep, count)
        pts = robot_positions(true, qs)
        sets.append((qs, pts + rng.normal(0, sigma, pts.shape)))
    return sets


@dataclass(frozen=True, eq=False)
class StudyCase:
    """One calibration of the study.

    Attributes
    ----------
    model : str
    initial : str
        ``"nominal"`` or ``"circle-point"``.
    sigma : float
        Tracker noise per coordinate, m.
    n_poses : int
    train_before, train_after : ErrorStats
        On the calibration poses (against the measurements).
    test_before, test_after : ErrorStats
        On held-out poses, against the (noisy) measurements.
    test_after_true : ErrorStats
        On held-out poses, against the noise-free true positions.
    test_errors_before, test_errors_after : numpy.ndarray, shape (n_test,)
        Held-out distance errors, m.
    calibration : Calibration
    true_params : numpy.ndarray or None, shape (P,)
        The model's parameters that reproduce the true robot exactly (fitted to noise-free data
        with the same parameters held), when the model can (None for standard DH).
    """

    model: str
    initial: str
    sigma: float
    n_poses: int
    train_before: ErrorStats
    train_after: ErrorStats
    test_before: ErrorStats
    test_after: ErrorStats
    test_after_true: ErrorStats
    test_errors_before: np.ndarray
    test_errors_after: np.ndarray
    calibration: Calibration
    true_params: np.ndarray | None


@dataclass(frozen=True, eq=False)
class StudyResult:
    """The simulation study's numbers and figures.

    Attributes
    ----------
    cases : tuple of StudyCase
    true_robot : Robot
        The perturbed PUMA 560 in the tracker frame (its tool is the target).
    test_q : numpy.ndarray, shape (n_test, n)
    test_points : numpy.ndarray, shape (n_test, 3)
        Noise-free held-out positions, m.
    figures : tuple of Path
    notes : tuple of str
        Findings in words (what standard DH does at the parallel joints, and so on).
    """

    cases: tuple[StudyCase, ...]
    true_robot: Robot
    test_q: np.ndarray
    test_points: np.ndarray
    figures: tuple[Path, ...]
    notes: tuple[str, ...]

    def table(self) -> str:
        """Held-out errors per model and noise level, mm."""
        rows = [f"{'model':<9}{'initial':<14}{'noise':>6}{'poses':>7}{'before RMS':>12}{'after RMS':>11}"
                f"{'after max':>11}{'vs truth':>10}{'after/noise':>13}"]
        for c in self.cases:
            noise_rms = c.sigma * math.sqrt(3)
            rows.append(f"{c.model:<9}{c.initial:<14}{c.sigma * 1e3:>6.3f}{c.n_poses:>7}"
                        f"{c.test_before.rms * 1e3:>12.4f}{c.test_after.rms * 1e3:>11.4f}"
                        f"{c.test_after.max * 1e3:>11.4f}"
                        f"{c.test_after_true.rms * 1e3:>10.4f}{c.test_after.rms / noise_rms:>13.3f}")
        return "\n".join(rows)


def puma_study(
    out_dir: str | Path | None = None,
    *,
    runs: Sequence[tuple[str, str]] = RUNS,
    noises: Sequence[float] = (5e-5, 1e-4),
    n_poses: int = 100,
    n_test: int = 200,
    seed: int = 0,
    robot: Robot | None = None,
) -> StudyResult:
    """Run the PUMA 560 calibration study; save figures into ``out_dir`` when given.

    Parameters
    ----------
    out_dir : str or Path, optional
        Directory for the PNG figures (created).
    runs : sequence of (str, str)
        Error model and initial estimate (``"nominal"`` or ``"circle-point"``) of each calibration.
    noises : sequence of float
        Tracker noise per coordinate, m (0.05 mm: a laser tracker; 0.1 mm: the thesis' Optotrac).
    n_poses, n_test : int
        Calibration and held-out pose counts.
    seed : int
    robot : Robot, optional
        Default: the built-in ``puma560``.

    Returns
    -------
    StudyResult
    """
    import warnings

    from robodyn.robot.load import load

    if robot is None:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            robot = load("puma560")
    rng = np.random.default_rng(seed)
    tracker = trans(2.2, -0.8, -0.4) @ rot("z", math.radians(35)) @ rot("x", math.radians(0.3))
    true = perturbed_robot(robot, rng, base=tracker, target=(0.031, -0.018, 0.076))
    q = random_configurations(robot, n_poses, rng)
    q_test = random_configurations(robot, n_test, rng)
    clean = robot_positions(true, q)
    clean_test = robot_positions(true, q_test)
    cases = []
    for sigma in noises:
        sets = circle_sets(true, HOME, rng, sigma)
        y = clean + rng.normal(0, sigma, clean.shape)
        y_test = clean_test + rng.normal(0, sigma, clean_test.shape)
        geometry = robot_geometry(robot)
        _, _, placed, placed_p = nominal_placement(geometry, q, y, None, np.full(y.shape, sigma), 1e-4)
        before_test = y_test - placed.evaluate(placed_p, q_test, derivatives=False).position
        for name, initial in runs:
            cal = calibrate(robot, q, y, name, sigma=sigma, initial=initial, circle_data=sets)
            after_test = y_test - cal.predict(q_test)
            true_params = None
            if name != "dh":
                free = [cal.model.index(n) for n in cal.parameter_names]
                true_params = fit(cal.model, cal.params, free, q, clean, sigma=sigma).params
            cases.append(StudyCase(
                model=name, initial=initial, sigma=sigma, n_poses=n_poses,
                train_before=cal.before, train_after=cal.after,
                test_before=ErrorStats.from_residuals(before_test),
                test_after=ErrorStats.from_residuals(after_test),
                test_after_true=ErrorStats.from_residuals(clean_test - cal.predict(q_test)),
                test_errors_before=np.linalg.norm(before_test, axis=1),
                test_errors_after=np.linalg.norm(after_test, axis=1),
                calibration=cal, true_params=true_params,
            ))
    notes = _notes(cases)
    figures: tuple[Path, ...] = ()
    if out_dir is not None:
        from robodyn.studies.calibration_figures import save_figures

        figures = save_figures(cases, q_test, clean_test, Path(out_dir))
    return StudyResult(tuple(cases), true, q_test, clean_test, figures, notes)


def _notes(cases: Sequence[StudyCase]) -> tuple[str, ...]:
    """Findings in words."""
    notes = []
    for c in cases:
        if c.model != "dh":
            continue
        others = [o for o in cases if o.sigma == c.sigma and o.model != "dh"]
        best = min(others, key=lambda o: o.test_after.rms) if others else None
        head = (f"standard DH from the {c.initial} estimate at {c.sigma * 1e3:.3g} mm noise: held-out RMS "
                f"{c.test_after.rms * 1e3:.3f} mm (noise RMS {c.sigma * math.sqrt(3) * 1e3:.3f} mm"
                + (f"; {best.model}: {best.test_after.rms * 1e3:.3f} mm)" if best else ")"))
        if c.initial == "nominal":
            dependent = [f"{u.name} and {u.combination[0][0]}" for u in c.calibration.unidentifiable
                         if u.name.endswith(".d") and len(u.combination) == 1
                         and u.combination[0][0].endswith(".d")]
            text = (head + ": at the parallel joints 2 and 3 the DH link has no rotation about the "
                    "axis perpendicular to the common normal, so a tilt of joint 3's axis that way "
                    "cannot be represented from the nominal (exactly parallel) model")
            if dependent:
                text += f"; {', '.join(dependent)} only enter as their sum"
        else:
            cal = c.calibration
            d2 = next((p for p in cal.parameters if p.name == "q2.d"), None)
            text = head + (": started from the measured (not quite parallel) axes, DH reaches them by "
                           "moving the common normal of joints 2 and 3 far away")
            if d2 is not None:
                text += f" (q2.d = {d2.value:.4g} m, nominal 0)"
            text += f"; condition number {cal.observability.condition:.3g}"
        notes.append(text)
    return tuple(notes)
