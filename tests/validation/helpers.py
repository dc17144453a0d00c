"""Shared data for the validation tests: simulated recordings with a known ground truth."""

from __future__ import annotations

from pathlib import Path

import numpy as np

import robodyn as rd

SLIDER_YAML = """
name: slider
gravity: [0, 0, -9.81]
joints:
  - name: x
    type: prismatic
    origin: {xyz: [0, 0, 0], rpy: [0, 0, 0]}
    axis: [1, 0, 0]
    link:
      name: cart
      mass: 2.0
      com: [0, 0, 0]
      inertia: {ixx: 0.01, iyy: 0.01, izz: 0.01, ixy: 0, ixz: 0, iyz: 0}
"""
SLIDER_MASS = 2.0


def slider(tmp_path: Path) -> rd.Robot:
    """A 2 kg cart on a horizontal prismatic joint: ``F = m x''``."""
    path = tmp_path / "slider.yaml"
    path.write_text(SLIDER_YAML)
    return rd.load(str(path))


def recording(**fields):
    """A :class:`robodyn.measure.Recording` from arrays."""
    from robodyn.measure import Recording

    return Recording(**fields)


def puma_run(duration: float = 1.0, dt: float = 1e-3, seed: int = 0):
    """The PUMA 560 moving under a gravity-compensated sinusoidal torque (RK4, torque held).

    Returns the robot, its compiled model and the simulated trajectory: ``tau[k]`` is held over
    ``[t_k, t_k+1)`` and ``qdd[k]`` is the acceleration at ``(q[k], qd[k], tau[k])``, so the
    model's inverse dynamics reproduce ``tau`` at every sample.
    """
    robot = rd.load("puma560")
    model = rd.compile_model(robot)
    n = robot.dof
    rng = np.random.default_rng(seed)
    amp = np.array([40.0, 60.0, 25.0, 3.0, 3.0, 2.0]) * rng.uniform(0.8, 1.2, n)
    phase = rng.uniform(0, 2 * np.pi, n)

    def law(t, q, qd):
        return model.gravity(q) + amp * np.sin(2 * np.pi * 1.3 * t + phase) - 3.0 * qd

    sim = rd.simulate(model, np.zeros(n), None, duration, dt, controller=law)
    return robot, model, sim
