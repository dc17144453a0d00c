"""Picklable study tasks for the tests (module level, so Dask workers import them by name)."""

from __future__ import annotations

import os
import time

import numpy as np


def noisy_square(case: dict) -> dict:
    """``x**2`` plus a normal draw from the case's own seed; raises for ``x == 3``."""
    if case["x"] == 3:
        raise ValueError(f"x = {case['x']} is not allowed here")
    rng = np.random.default_rng(case["seed"])
    return {"y": float(case["x"]) ** 2, "noise": rng.normal(), "pair": np.array([case["x"], -1.0])}


def slow_square(case: dict) -> dict:
    """``noisy_square`` taking a while (so that a worker can be killed mid-study)."""
    time.sleep(0.05)
    return {**noisy_square(case), "pid": os.getpid()}


def crashing_square(case: dict) -> dict:
    """``x**2``; for ``x == 5`` the worker process dies, as in a crash in compiled code."""
    if case["x"] == 5:
        os._exit(1)
    return {"y": float(case["x"]) ** 2}
