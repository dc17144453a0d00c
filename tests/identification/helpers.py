"""Simulated identification data: random Fourier joint trajectories and their exact torques."""

from __future__ import annotations

import warnings

import numpy as np

import robodyn as rd


def load_quiet(name: str) -> rd.Robot:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return rd.load(name)


def fourier(t: np.ndarray, n: int, rng: np.random.Generator, harmonics: int = 5, f0: float = 0.1,
            amplitude: float = 1.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Random finite Fourier series ``q, qd, qdd`` (N, n) with exact derivatives."""
    q = np.zeros((t.size, n))
    qd = np.zeros_like(q)
    qdd = np.zeros_like(q)
    q += rng.uniform(-1, 1, n)
    for k in range(1, harmonics + 1):
        w = 2 * np.pi * f0 * k
        a, b = rng.normal(0, amplitude / k, (2, n))
        s, c = np.sin(w * t)[:, None], np.cos(w * t)[:, None]
        q += a * s + b * c
        qd += w * (a * c - b * s)
        qdd += -w * w * (a * s + b * c)
    return q, qd, qdd


def simulated(model: rd.Model, seconds: float = 10.0, dt: float = 0.01, seed: int = 0,
              noise: np.ndarray | float = 0.0) -> tuple[rd.Recording, np.ndarray]:
    """A recording with exact ``q, qd, qdd`` and ``tau`` = inverse dynamics + white noise of std
    ``noise`` (N m, per joint or common), and the noise-free torque."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, seconds, dt)
    q, qd, qdd = fourier(t, model.dof, rng)
    tau = model.inverse_dynamics(q, qd, qdd)
    noisy = tau + rng.standard_normal(tau.shape) * np.asarray(noise, float)
    return rd.Recording(t=t, q=q, qd=qd, qdd=qdd, tau=noisy,
                        joint_names=model.robot.joint_names, source=f"sim{seed}"), tau
