"""Does a calibration's non-geometric model earn its parameters, and what does its description say alone?

Two checks for a calibration with non-geometric terms (joint compliance, harmonics):

* :func:`terms_cross_validation`: K-fold cross-validation over poses. Each fold's poses are
  predicted by calibrations on the others, for each nested term set (geometry alone, then the
  terms added one family at a time in the order given); the held-out RMS position error of each
  set says whether a family helps on poses it has not seen. A family that fits its own poses
  better but predicts held-out poses worse overfits (25 tracker poses with compliance and
  harmonics: held-out 0.31 -> 0.49 mm).
* :func:`description_alone`: what the written files predict loaded alone (the way a controller
  or a simulator takes them). The YAML description carries the terms as joint-reading
  corrections (``cal.robot.corrections``, :mod:`robodyn.robot.corrections`) and reproduces
  ``cal.predict``; a URDF cannot hold them, and its geometry alone, estimated together with the
  terms, predicts differently. The RMS of each on given poses is what the files' headers and the
  command line state.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from robodyn.robot.numbers import RobotNumbers, robot_numbers

if TYPE_CHECKING:
    from robodyn.robot.model import Robot

__all__ = ["TermsCheck", "description_alone", "terms_cross_validation"]


@dataclass(frozen=True)
class TermsCheck:
    """Held-out RMS position error (m) of each nested term set over ``folds`` folds of poses.

    Attributes
    ----------
    term_sets : tuple of tuple of str
        ``()``, then each family added in turn.
    rms : tuple of float
        Held-out RMS position error of each set over all poses, m.
    folds : int
    poses : int
    """

    term_sets: tuple[tuple[str, ...], ...]
    rms: tuple[float, ...]
    folds: int
    poses: int

    @property
    def overfitting(self) -> tuple[str, ...]:
        """The families whose addition made the held-out error worse."""
        return tuple(s[-1] for k, s in enumerate(self.term_sets[1:], 1) if self.rms[k] > self.rms[k - 1])

    def text(self) -> str:
        """One line per term set, mm."""
        lines = [f"held-out RMS over {self.folds} folds of {self.poses} poses (cross-validation):"]
        for terms, rms in zip(self.term_sets, self.rms, strict=True):
            lines.append(f"  {' + '.join(('geometry',) + terms):<40} {rms * 1e3:.4f} mm")
        return "\n".join(lines)


def terms_cross_validation(calibrate: Callable[..., Any], robot: Robot | RobotNumbers, q: np.ndarray,
                           points: np.ndarray, terms: Sequence[str], folds: int = 5,
                           seed: int = 0, **options: Any) -> TermsCheck:
    """K-fold cross-validation over poses of the nested term sets (module docstring).

    Parameters
    ----------
    calibrate : callable
        ``rd.calibrate`` (passed in: this module sits below it).
    robot : Robot or RobotNumbers
    q : numpy.ndarray, shape (N, n)
        Joint readings, in ``options``' ``angle_unit``.
    points : numpy.ndarray, shape (N, 3) or (N, K, 3)
        Measured positions, in ``options``' ``length_unit``; the first target is scored.
    terms : sequence of str
        Non-geometric families in the order they are added.
    folds : int
        At most the number of poses; poses are dealt to folds in a seeded random order.
    **options
        Passed to every ``calibrate`` call (model, sigma, units, payload, ...).

    Returns
    -------
    TermsCheck
        RMS in the unit of ``points`` converted to m when ``length_unit="mm"``.
    """
    q, points = np.asarray(q, float), np.asarray(points, float)
    n = q.shape[0]
    folds = max(2, min(int(folds), n))
    order = np.random.default_rng(seed).permutation(n)
    fold_of = np.empty(n, int)
    fold_of[order] = np.arange(n) % folds
    scale = 1e-3 if options.get("length_unit", "m") == "mm" else 1.0
    sets = [tuple(terms[:k]) for k in range(len(terms) + 1)]
    rms = []
    for ng in sets:
        sq = 0.0
        for f in range(folds):
            train, test = fold_of != f, fold_of == f
            with warnings.catch_warnings():  # a fold's own warnings (fewer poses) are not the run's
                warnings.simplefilter("ignore", RuntimeWarning)
                cal = calibrate(robot, q[train], points[train], nongeometric=ng,
                                **_trained(_for_terms(options, ng), train))
            first = points[test] if points.ndim == 2 else points[test][:, 0]
            pred = cal.predict(_si_angles(robot, q[test], options))
            pred = pred if pred.ndim == 2 else pred[:, 0]  # several targets: the first
            sq += float(np.sum((first * scale - pred) ** 2))
        rms.append(float(np.sqrt(sq / n)))
    return TermsCheck(tuple(sets), tuple(rms), folds, n)


def _for_terms(options: dict[str, Any], terms: tuple[str, ...]) -> dict[str, Any]:
    """``options`` without those that need the compliance term when ``terms`` lacks it."""
    if "compliance" in terms:
        return options
    return {k: v for k, v in options.items() if k not in ("payload", "identify_payload", "deflection")}


def _trained(options: dict[str, Any], train: np.ndarray) -> dict[str, Any]:
    """``options`` with a per-pose ``sigma`` cut to the training poses."""
    out = dict(options)
    sigma = out.get("sigma")
    if sigma is not None and np.ndim(sigma) >= 1 and np.shape(sigma)[0] == train.size:
        out["sigma"] = np.asarray(sigma)[train]
    return out


def _si_angles(robot: Robot | RobotNumbers, q: np.ndarray, options: dict[str, Any]) -> np.ndarray:
    """Readings in rad for ``cal.predict`` (revolute joints converted from degrees)."""
    if options.get("angle_unit", "rad") != "deg":
        return q
    out = q.copy()
    for j, kind in enumerate(robot_numbers(robot).joint_types):
        if kind == "revolute":
            out[:, j] = np.radians(out[:, j])
    return out


def description_alone(cal: Any, q: np.ndarray, points: np.ndarray) -> tuple[float, float, float]:
    """RMS position errors (m) on poses ``q`` (N, n, rad) against ``points`` (N, 3) or (N, K, 3)
    (m, first target).

    Returns
    -------
    description, geometry, predict : float
        The written description ``cal.robot`` with its joint-reading corrections, the same
        geometry without them (what a URDF holds), and ``cal.predict``.
    """
    from dataclasses import replace

    from robodyn.calibration.frames import robot_positions

    first = points if points.ndim == 2 else points[:, 0]
    full = cal.predict(q)
    preds = (robot_positions(cal.robot, q), robot_positions(replace(cal.robot, corrections=None), q),
             full if full.ndim == 2 else full[:, 0])
    rms = [float(np.sqrt(np.mean(np.sum((first - p) ** 2, axis=1)))) for p in preds]
    return rms[0], rms[1], rms[2]
