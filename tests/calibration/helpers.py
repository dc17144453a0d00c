"""Shared helpers of the calibration tests: robots, oracles and synthetic data."""

from __future__ import annotations

import warnings
from functools import cache

import numpy as np
import sympy as sp

import robodyn as rd
from robodyn.calibration import build_model, random_configurations, robot_geometry
from robodyn.calibration.kinematics import rot, trans
from robodyn.calibration.pipeline import identifiable_parameters
from robodyn.symbolic.kinematics import forward_kinematics

#: An instrument placement: the robot world frame in the tracker frame (metres away, turned, tilted).
TRACKER = trans(2.2, -0.8, -0.4) @ rot("z", 0.6) @ rot("x", 0.004)
#: A target offset on the flange, m.
TARGET = (0.031, -0.018, 0.076)


@cache
def robot(name: str) -> rd.Robot:
    """A built-in robot (plausibility warnings silenced)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return rd.load(name)


def symbolic_fk(r: rd.Robot):
    """Oracle: ``q (N, n) -> (N, 4, 4)`` from :func:`robodyn.symbolic.kinematics.forward_kinematics`.

    Each configuration is evaluated by SymPy with 30-digit numbers substituted.
    """
    subs = {k: sp.Float(v, 30) for k, v in r.defaults().items()}

    def fk(q):
        out = []
        for x in np.atleast_2d(q):
            m = forward_kinematics(r, [sp.Float(float(v), 30) for v in x]).end_effector
            out.append(np.array(m.xreplace(subs).evalf(30), dtype=float))
        return np.array(out)

    return fk


def in_model_truth(name: str, model: str, q: np.ndarray, seed: int = 0):
    """A true robot inside ``model``: its identifiable joint and tool parameters perturbed.

    Returns the true model, its parameters (P,), and the noise-free measurements of ``q``.
    """
    r = robot(name)
    g = robot_geometry(r)
    truth = build_model(model, g, base=TRACKER, target=TRACKER @ g.target @ trans(*TARGET))
    free, _ = identifiable_parameters(r, truth, truth.initial, q)
    rng = np.random.default_rng(seed)
    p = truth.initial.copy()
    for k in free:
        if not truth.names[k].startswith("base"):
            p[k] += rng.normal(0, 1e-3 if truth.units[k] == "m" else np.radians(0.1))
    return truth, p, truth.evaluate(p, q, derivatives=False).position


def poses(name: str, count: int, seed: int) -> np.ndarray:
    """Random readings within the joint limits, (count, n)."""
    return random_configurations(robot(name), count, seed)
