"""Helpers shared by the exporter tests: numeric frames and dynamics of a robodyn robot."""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import sympy as sp

import robodyn as rd
from robodyn.robot.errors import DescriptionWarning
from robodyn.robot.model import Robot
from tests.numeric_eval import evaluator, program_evaluator


def quiet_load(source: str | Path) -> Robot:
    """``rd.load`` with the physical-plausibility warnings of the description silenced."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DescriptionWarning)
        return rd.load(source)


def as_array(m: sp.MatrixBase, robot: Robot) -> np.ndarray:
    """A robot matrix at the default parameter values, as floats."""
    return np.array(sp.Matrix(m).xreplace(robot.defaults()).evalf(30).tolist(), dtype=float)


def motion(kind: str, axis: np.ndarray, q: float) -> np.ndarray:
    """Rotation about / translation along the unit ``axis`` by ``q``, shape (4, 4) (Rodrigues)."""
    t = np.eye(4)
    if kind == "prismatic":
        t[:3, 3] = axis * q
        return t
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    t[:3, :3] = np.eye(3) + np.sin(q) * k + (1 - np.cos(q)) * k @ k
    return t


@dataclass(frozen=True)
class Frames:
    """World poses at one ``q``, each (4, 4): per joint the frame after ``pre @ motion`` (before
    ``post``) and the link frame; and the tool frame."""

    moved: list[np.ndarray]
    links: list[np.ndarray]
    tool: np.ndarray


def frames(robot: Robot, q: np.ndarray) -> Frames:
    """Forward kinematics in NumPy, independent of the symbolic code."""
    t = as_array(robot.base, robot)
    moved, links = [], []
    for joint, qi in zip(robot.joints, q, strict=True):
        axis = as_array(joint.axis, robot).ravel()
        axis = axis / np.linalg.norm(axis)
        t = t @ as_array(joint.pre, robot) @ motion(joint.type, axis, qi)
        moved.append(t)
        t = t @ as_array(joint.post, robot)
        links.append(t)
    return Frames(moved, links, t @ as_array(robot.tool, robot))


class Dynamics:
    """Numeric ``M`` (rotor inertia included), ``g`` and ``tau`` (rigid body + rotor + friction) of
    a robot, from its Newton-Euler equations at the default parameter values."""

    def __init__(self, robot: Robot) -> None:
        eom = rd.derive(robot, method="newton_euler")
        self.robot = robot
        self.n = robot.dof
        self._m = program_evaluator(eom, eom.M_rigid_form)
        self._g = program_evaluator(eom, eom.g_form)
        self._tau = program_evaluator(eom, eom.program)
        self._extra = evaluator(eom, sp.Matrix.hstack(eom.rotor, eom.friction))
        self.rotor = np.array([float(as_array(sp.Matrix([j.drive.gear_ratio**2 * j.drive.rotor_inertia]),
                                              robot)[0, 0]) for j in robot.joints])
        self.viscous = np.array([float(as_array(sp.Matrix([j.friction.viscous]), robot)[0, 0])
                                 for j in robot.joints])

    def M(self, q: np.ndarray) -> np.ndarray:  # noqa: N802
        """Mass matrix with reflected rotor inertia, (n, n)."""
        return self._m(q) + np.diag(self.rotor)

    def M_rigid(self, q: np.ndarray) -> np.ndarray:  # noqa: N802
        """Rigid-body mass matrix, (n, n)."""
        return self._m(q)

    def g(self, q: np.ndarray) -> np.ndarray:
        """Gravity torques, (n,)."""
        return self._g(q).ravel()

    def tau_rigid(self, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> np.ndarray:
        """Rigid-body inverse dynamics, (n,)."""
        return self._tau(q, qd, qdd).ravel()

    def friction(self, qd: np.ndarray) -> np.ndarray:
        """Friction torques, (n,)."""
        return self._extra(np.zeros(self.n), qd, np.zeros(self.n))[:, 1]

    def tau(self, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> np.ndarray:
        """Full inverse dynamics: rigid body + rotor inertia + friction, (n,)."""
        return self.tau_rigid(q, qd, qdd) + self._extra(q, qd, qdd).sum(axis=1)


def relative_error(a: np.ndarray, b: np.ndarray) -> float:
    """``max |a - b|`` over ``max |b|`` (over 1 when ``b`` is all zero)."""
    scale = float(np.abs(b).max()) or 1.0
    return float(np.abs(np.asarray(a) - np.asarray(b)).max() / scale)
