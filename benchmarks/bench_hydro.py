"""Compiled inverse dynamics of underwater_2r with its hydrodynamic terms against the same robot
dry (fluid and hydro blocks removed), measured in the same run; prints the cost ratio (issue 11
target: at most 2.5x).

Then the drag against the common lumped alternative: a straightforward NumPy loop over the links
and 20 strips per cylinder (midpoint sum of per-strip drag forces, the planar kinematics of
underwater_2r written out here), vectorised over the states. Both are timed in the same run and
compared for accuracy against a 4000-strip sum of the same integrand (the reference), with a
0.3 m/s current so that the normal velocity changes sign inside the links (the hard case).
Last, 10 s of the underwater two-link arm (every effect on, 0.3 m/s current) released from rest,
RK4 at 1 ms: robodyn (``rd.simulate`` and ``Model.integrate``, generated C) against SciPy
``solve_ivp`` (RK45) on a lambdified model: ``sympy.lambdify`` of robodyn's OWN symbolic M(q) and
tau(q, qd, 0) (Lagrange form; the rhs solves M qdd = -h), the usual Python route. Accuracy of
both is measured against a fine reference (robodyn's RK4 at dt / 20, checked against SciPy
DOP853 at rtol = atol = 1e-12 on the same compiled state derivative), and solve_ivp's rtol is
chosen from a sweep as the loosest whose error is within 2x of robodyn's (matched accuracy); the
time ratio is printed.
Run: ``.venv/bin/python benchmarks/bench_hydro.py [--quick]`` (``--quick``: only the last part).
"""

from __future__ import annotations

import dataclasses
import sys
import time

import numpy as np
from peers import lambdified_rhs  # noqa: E402
from timing import best_of  # noqa: E402

import robodyn as rd


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
    t_strip = best_of(lambda: strip_drag(q, qd, 20), repeat=3)
    print(f"drag, {n} states, 0.3 m/s current: robodyn (6-point Gauss-Legendre, compiled, whole "
          f"wet inverse dynamics) {t_ours / n * 1e9:.0f} ns/state, max error "
          f"{np.abs(ours - exact).max() / scale:.1e} of the peak drag torque")
    print(f"  NumPy 20-strip loop (drag only) {t_strip / n * 1e9:.0f} ns/state, max error "
          f"{np.abs(twenty - exact).max() / scale:.1e}; ratio NumPy/robodyn {t_strip / t_ours:.1f}")
    for strips in (1, 2, 4):
        t = best_of(lambda s=strips: strip_drag(q, qd, s), repeat=3)
        err = np.abs(strip_drag(q, qd, strips) - exact).max() / scale
        print(f"  NumPy {strips}-strip loop: {t / n * 1e9:.0f} ns/state ({t / t_ours:.2f}x robodyn), "
              f"max error {err:.1e}")


def solve_ivp_benchmark() -> None:
    from scipy.integrate import solve_ivp

    from robodyn.simulate import simulate

    values = {"vc": float(CURRENT[0])}
    robot = rd.load("underwater_2r")
    model = rd.compile_model(robot, parameters=values)
    q0 = np.array([0.3, -0.5])
    x0 = np.concatenate([q0, np.zeros(2)])
    steps, dt = 10_000, 1e-3
    t_eval = dt * np.arange(steps + 1)
    print("\n== 10 s of underwater_2r (every effect, 0.3 m/s current), from rest, output every 1 ms ==")
    # reference: RK4 at dt / 20 (4th order: ~1e5 times more accurate than at dt), checked
    # against SciPy DOP853 at rtol = atol = 1e-12 on the same compiled derivative
    fine = model.integrate(x0, 20 * steps, dt / 20, "rk4")[0]
    ref = np.asarray(fine)[::20]
    dop = solve_ivp(lambda t, y: model.state_derivative(y, np.zeros(2)), (0.0, 10.0), x0,
                    method="DOP853", t_eval=t_eval, rtol=1e-12, atol=1e-12).y.T
    t_int = best_of(lambda: model.integrate(x0, steps, dt, "rk4"), 7)
    t_sim = best_of(lambda: simulate(model, q0, None, 10.0, dt, "rk4"), 5)
    run = simulate(model, q0, None, 10.0, dt, "rk4")
    err_rd = np.abs(np.concatenate([run.q, run.qd], 1) - ref).max()
    print(f"reference: RK4 at {dt / 20:g} s; it differs from SciPy DOP853 (rtol = atol = 1e-12) "
          f"by {np.abs(dop - ref).max():.1e}; swing q1 in [{ref[:, 0].min():.2f}, "
          f"{ref[:, 0].max():.2f}] rad")
    print(f"robodyn  Model.integrate RK4 1 ms (one C call)   {t_int * 1e3:8.2f} ms")
    print(f"robodyn  rd.simulate RK4 1 ms                    {t_sim * 1e3:8.2f} ms   "
          f"max |x - x_ref| = {err_rd:.1e}")
    start = time.perf_counter()
    rhs = lambdified_rhs(robot, values)
    print(f"lambdify of robodyn's own M and h (Lagrange): {time.perf_counter() - start:.1f} s "
          "(not in the times below)")
    matched = None
    for rtol in (1e-6, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12):
        start = time.perf_counter()
        sol = solve_ivp(rhs, (0.0, 10.0), x0, method="RK45", t_eval=t_eval, rtol=rtol,
                        atol=rtol * 1e-2)
        elapsed = time.perf_counter() - start
        err = np.abs(sol.y.T - ref).max()
        print(f"SciPy solve_ivp RK45 + lambdify, rtol {rtol:.0e}  {elapsed * 1e3:8.1f} ms   "
              f"max |x - x_ref| = {err:.1e}  ({sol.nfev} rhs calls)")
        if err <= 2 * err_rd:
            matched = (rtol, elapsed, err)
            break
    if matched is None:
        print("solve_ivp did not come within 2x of robodyn's accuracy in the sweep")
        return
    rtol, elapsed, err = matched
    print(f"matched accuracy (first rtol within 2x of robodyn's error: solve_ivp rtol {rtol:.0e}, "
          f"{err:.1e}; robodyn {err_rd:.1e}): "
          f"solve_ivp + lambdify / rd.simulate = {elapsed / t_sim:.0f}x, "
          f"/ Model.integrate = {elapsed / t_int:.0f}x")


if __name__ == "__main__":
    if "--quick" in sys.argv[1:]:
        solve_ivp_benchmark()
    else:
        main()
        solve_ivp_benchmark()
