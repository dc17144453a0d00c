"""Compiled inverse dynamics of underwater_2r with its hydrodynamic terms against the same robot
dry (fluid and hydro blocks removed), measured in the same run; prints the cost ratio (issue 11
target: at most 2.5x).

Then the drag against the common lumped alternative: a straightforward NumPy loop over the links
and 20 strips per cylinder (midpoint sum of per-strip drag forces, the planar kinematics of
underwater_2r written out here), vectorised over the states. Both are timed in the same run and
compared for accuracy against a 4000-strip sum of the same integrand (the reference), with a
0.3 m/s current so that the normal velocity changes sign inside the links (the hard case).
Run: ``.venv/bin/python benchmarks/bench_hydro.py``.
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
    strips_benchmark()


RHO, CD, L, R = 1000.0, 1.2, (1.0, 0.8), (0.06, 0.05)
CURRENT = np.array([0.3, 0.0])


def strip_drag(q: np.ndarray, qd: np.ndarray, strips: int) -> np.ndarray:
    """Drag torques (N, 2) of underwater_2r by a midpoint sum over ``strips`` strips per link."""
    c1, s1 = np.cos(q[:, 0]), np.sin(q[:, 0])
    c12, s12 = np.cos(q[:, 0] + q[:, 1]), np.sin(q[:, 0] + q[:, 1])
    e = (np.stack([c1, s1], 1), np.stack([c12, s12], 1))  # link axes
    n = (np.stack([-s1, c1], 1), np.stack([-s12, c12], 1))  # their normals in the plane
    tau = np.zeros_like(q)
    for link in (0, 1):
        ds = L[link] / strips
        for k in range(strips):
            xi = (k + 0.5) * ds
            # partial velocities dx/dq1, dx/dq2 of the strip centre
            if link == 0:
                j1, j2 = xi * n[0], np.zeros_like(n[0])
            else:
                j1, j2 = L[0] * n[0] + xi * n[1], xi * n[1]
            u = j1 * qd[:, :1] + j2 * qd[:, 1:] - CURRENT  # relative velocity
            un = u - np.sum(u * e[link], 1, keepdims=True) * e[link]  # normal part
            # force on the fluid's side f = -1/2 rho Cd D |u_n| u_n ds; tau = -J^T f
            f = 0.5 * RHO * CD * 2 * R[link] * np.linalg.norm(un, axis=1, keepdims=True) * un * ds
            tau[:, 0] += np.sum(j1 * f, 1)
            tau[:, 1] += np.sum(j2 * f, 1)
    return tau


def strips_benchmark() -> None:
    wet = rd.compile_model(rd.load("underwater_2r"), parameters={"vc": float(CURRENT[0])})
    no_drag = rd.compile_model(rd.load("underwater_2r"), parameters={"vc": float(CURRENT[0]),
                                                                      "Cd": 0.0})
    rng = np.random.default_rng(1)
    n = 20_000
    q, qd, qdd = (rng.uniform(-2, 2, (n, 2)) for _ in range(3))
    exact = strip_drag(q, qd, 4000)
    ours = wet.inverse_dynamics(q, qd, qdd) - no_drag.inverse_dynamics(q, qd, qdd)
    twenty = strip_drag(q, qd, 20)
    scale = np.abs(exact).max()
    t_ours = best_of(lambda: wet.inverse_dynamics(q, qd, qdd))
    t_strip = best_of(lambda: strip_drag(q, qd, 20), repeats=3)
    print(f"drag, {n} states, 0.3 m/s current: robodyn (6-point Gauss-Legendre, compiled, whole "
          f"wet inverse dynamics) {t_ours / n * 1e9:.0f} ns/state, max error "
          f"{np.abs(ours - exact).max() / scale:.1e} of the peak drag torque")
    print(f"  NumPy 20-strip loop (drag only) {t_strip / n * 1e9:.0f} ns/state, max error "
          f"{np.abs(twenty - exact).max() / scale:.1e}; ratio NumPy/robodyn {t_strip / t_ours:.1f}")
    for strips in (1, 2, 4):
        t = best_of(lambda s=strips: strip_drag(q, qd, s), repeats=3)
        err = np.abs(strip_drag(q, qd, strips) - exact).max() / scale
        print(f"  NumPy {strips}-strip loop: {t / n * 1e9:.0f} ns/state ({t / t_ours:.2f}x robodyn), "
              f"max error {err:.1e}")


if __name__ == "__main__":
    main()
