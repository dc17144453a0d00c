"""Timing helpers shared by the benchmarks (run as scripts: ``benchmarks/`` is on ``sys.path``)."""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any


def best_of(fn: Callable[[], Any], repeat: int = 5) -> float:
    """Smallest wall time of ``repeat`` calls of ``fn``, s (the least disturbed by other load)."""
    return best_of_with_result(fn, repeat)[0]


def best_of_with_result(fn: Callable[[], Any], repeat: int = 5) -> tuple[float, Any]:
    """Smallest wall time of ``repeat`` calls of ``fn``, s, and the last call's result."""
    best, out = float("inf"), None
    for _ in range(repeat):
        start = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - start)
    return best, out


def interleaved(fns: dict[str, Callable[[], Any]], repeat: int = 5) -> dict[str, list[float]]:
    """Wall times of ``repeat`` calls of each function, s, the functions taking turns.

    Taking turns (one call of each per round) spreads a burst of load from other processes over
    all of them alike, so that ratios of one run stay comparable on a shared machine.

    Parameters
    ----------
    fns : dict
        Name to a callable without arguments.
    repeat : int
        Rounds.

    Returns
    -------
    dict
        Name to the list of its ``repeat`` wall times.
    """
    times: dict[str, list[float]] = {name: [] for name in fns}
    for _ in range(repeat):
        for name, fn in fns.items():
            start = time.perf_counter()
            fn()
            times[name].append(time.perf_counter() - start)
    return times
