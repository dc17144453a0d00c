"""Compiled inverse dynamics of underwater_2r with its hydrodynamic terms against the same robot
dry (fluid and hydro blocks removed), measured in the same run; prints the cost ratio (issue 11
target: at most 2.5x). Run: ``.venv/bin/python benchmarks/bench_hydro.py``.
"""

from __future__ import annotations

import dataclasses
import time

import numpy as np

import robodyn as rd


def best_of(fn, repeats: int = 7) -> float:
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return min(times)


def main() -> None:
    wet = rd.load("underwater_2r")
    dry = dataclasses.replace(wet, fluid=None, description_hash="",
                              links=tuple(dataclasses.replace(lk, hydro=None) for lk in wet.links))
    m_wet, m_dry = rd.compile_model(wet), rd.compile_model(dry)
    rng = np.random.default_rng(0)
    n = 100_000
    q, qd, qdd = (rng.uniform(-2, 2, (n, 2)) for _ in range(3))
    t_wet = best_of(lambda: m_wet.inverse_dynamics(q, qd, qdd))
    t_dry = best_of(lambda: m_dry.inverse_dynamics(q, qd, qdd))
    print(f"inverse dynamics, {n} states, C backend: wet {t_wet / n * 1e9:.0f} ns/state, "
          f"dry {t_dry / n * 1e9:.0f} ns/state, ratio wet/dry {t_wet / t_dry:.2f} (target <= 2.5)")
    t_wet = best_of(lambda: m_wet.forward_dynamics(q, qd, qdd))
    t_dry = best_of(lambda: m_dry.forward_dynamics(q, qd, qdd))
    print(f"forward dynamics: ratio wet/dry {t_wet / t_dry:.2f}")


if __name__ == "__main__":
    main()
