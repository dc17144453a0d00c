"""Picklable study tasks for the tests (module level, so Dask workers import them by name)."""

from __future__ import annotations

import os
import time
from dataclasses import dataclass

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
    """``x**2`` after 20 ms; for ``x == 5`` the worker process dies at once, as in a crash in
    compiled code (the pause keeps other cases running beside it)."""
    if case["x"] == 5:
        os._exit(1)
    time.sleep(0.02)
    return {"y": float(case["x"]) ** 2}


@dataclass(frozen=True)
class GatedSquare:
    """``noisy_square`` on a Dask worker once the Dask event ``event`` is set; adds the worker's
    name (so that a test can hold every batch until the workers it expects have joined)."""

    event: str

    def __call__(self, case: dict) -> dict:
        from distributed import Event, get_worker

        Event(self.event).wait(timeout=60)
        return {**noisy_square(case), "worker": str(get_worker().name)}


def has_compiler() -> bool:
    """Whether this process finds a C compiler."""
    from robodyn.codegen.build import CompilerNotFoundError, find_compiler

    try:
        find_compiler()
    except CompilerNotFoundError:
        return False
    return True
