"""Compiled inverse dynamics of underwater_2r with its hydrodynamic terms against the same robot
dry (fluid and hydro blocks removed), measured in the same run; prints the cost ratio (issue 11
target: at most 2.5x).

Then the drag against the common lumped alternative: a straightforward NumPy loop over the links
and 20 strips per cylinder (midpoint sum of per-strip drag forces, the planar kinematics of
underwater_2r written out here), vectorised over the states. Both are timed in the same run and
compared for accuracy against a 4000-strip sum of the same integrand (the reference), with a
0.3 m/s current so that the normal velocity changes sign inside the links (the hard case).
Last, 10 s of the underwater two-link arm (every effect on, 0.3 m/s current) released from rest,
RK4 at 1 ms: robodyn (``rd.simulate`` and ``rd.rollout``, generated C) against SciPy
``solve_ivp`` (RK45) on a lambdified model: ``sympy.lambdify`` of robodyn's OWN symbolic M(q) and
tau(q, qd, 0) (Lagrange form; the rhs solves M qdd = -h), the usual Python route, and against
SciPy at its best, ``solve_ivp`` DOP853 over robodyn's compiled ``Model.state_derivative``
(``scipy_peer.py``). Accuracy of all is measured against a fine reference (robodyn's RK4 at
dt / 20, checked against SciPy DOP853 at rtol = atol = 1e-12 on the same compiled state
derivative), and each solve_ivp route's rtol is chosen from a sweep as the loosest whose error
is within 2x of robodyn's (matched accuracy); the matched settings are then timed in turns with
robodyn (min / median over the rounds).

Full runs merge the figures into ``benchmarks/results/<machine>.json`` (benchmark ``hydro``).
Run: ``.venv/bin/python benchmarks/bench_hydro.py [--quick] [--results PATH | --no-results]``
(``--quick``: only the last part, 3 rounds; written only with ``--results``).
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

import robodyn as rd

sys.path.insert(0, str(Path(__file__).resolve().parent))
import results  # noqa: E402
import scipy_peer  # noqa: E402
import timing  # noqa: E402
from peers import lambdified_rhs  # noqa: E402

REPEATS = 5


def wet_dry() -> dict[str, Any]:
    """Inverse and forward dynamics of underwater_2r wet against dry; the ``wet_dry`` entry."""
    wet = rd.load("underwater_2r")
    dry = dataclasses.replace(wet, fluid=None,
                              links=tuple(dataclasses.replace(lk, hydro=None) for lk in wet.links))
    m_wet, m_dry = rd.compile_model(wet), rd.compile_model(dry)
    rng = np.random.default_rng(0)
    n = 100_000
    q, qd, qdd = (rng.uniform(-2, 2, (n, 2)) for _ in range(3))
    t = timing.interleaved({"ID wet": lambda: m_wet.inverse_dynamics(q, qd, qdd),
                            "ID dry": lambda: m_dry.inverse_dynamics(q, qd, qdd),
                            "FD wet": lambda: m_wet.forward_dynamics(q, qd, qdd),
                            "FD dry": lambda: m_dry.forward_dynamics(q, qd, qdd)}, REPEATS)
    entry = {"states": n, "repeats": REPEATS, "target": 2.5,
             "ns_per_state": {k: results.summary(v, 1e9 / n) for k, v in t.items()},
             "ratio": {"ID": results.ratio(t["ID wet"], t["ID dry"]),
                       "FD": results.ratio(t["FD wet"], t["FD dry"])}}
    ns, r = entry["ns_per_state"], entry["ratio"]
    print(f"inverse dynamics, {n} states, C backend: wet {ns['ID wet']['min']:.0f} ns/state, "
          f"dry {ns['ID dry']['min']:.0f} ns/state, ratio wet/dry {r['ID']['min']:.2f} "
          f"(median {r['ID']['median']:.2f}; target <= 2.5)")
    print(f"forward dynamics: ratio wet/dry {r['FD']['min']:.2f} (median {r['FD']['median']:.2f})")
    return entry


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


def strips_benchmark() -> dict[str, Any]:
    """robodyn's wet inverse dynamics against NumPy strip sums of the drag; the ``drag`` entry."""
    wet = rd.compile_model(rd.load("underwater_2r"), parameters={"vc": float(CURRENT[0])})
    no_drag = rd.compile_model(rd.load("underwater_2r"), parameters={"vc": float(CURRENT[0]),
                                                                      "Cd": 0.0})
    rng = np.random.default_rng(1)
    n = 20_000
    q, qd, qdd = (rng.uniform(-2, 2, (n, 2)) for _ in range(3))
    exact = strip_drag(q, qd, 4000)
    scale = np.abs(exact).max()
    ours = wet.inverse_dynamics(q, qd, qdd) - no_drag.inverse_dynamics(q, qd, qdd)
    fns = {"robodyn": lambda: wet.inverse_dynamics(q, qd, qdd)}
    errors = {"robodyn": float(np.abs(ours - exact).max() / scale)}
    for strips in (1, 2, 4, 20):
        fns[f"NumPy {strips} strips"] = lambda s=strips: strip_drag(q, qd, s)
        errors[f"NumPy {strips} strips"] = float(np.abs(strip_drag(q, qd, strips) - exact).max() / scale)
    t = timing.interleaved(fns, 3)
    rows = [{"label": k, "ns_per_state": results.summary(v, 1e9 / n), "max_error": errors[k],
             "vs_robodyn": results.ratio(v, t["robodyn"], 1)} for k, v in t.items()]
    entry = {"states": n, "repeats": 3, "current_m_s": float(CURRENT[0]), "rows": rows,
             "settings": "robodyn: the whole wet inverse dynamics (6-point Gauss-Legendre drag, "
                         "compiled); NumPy: a loop over links and strips, vectorised over the "
                         "states, drag only; errors: max |drag - 4000-strip sum| / its peak"}
    print(f"drag, {n} states, {CURRENT[0]} m/s current ({entry['settings']}):")
    for r in rows:
        print(f"  {r['label']:16s}{r['ns_per_state']['min']:9.0f} ns/state "
              f"({r['vs_robodyn']['min']:.1f}x robodyn), max error {r['max_error']:.1e}")
    return entry


def solve_ivp_benchmark(repeats: int = REPEATS) -> dict[str, Any]:
    """10 s of underwater_2r: robodyn against SciPy at matched accuracy; the ``simulation`` entry.

    Parameters
    ----------
    repeats : int
        Rounds of the timed rows.

    Returns
    -------
    dict
        ``rows`` (label, ms min/median, max error, settings, ratio to ``rd.simulate`` and to
        ``rd.rollout``), the two sweeps, robodyn's error, the reference's check.
    """
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
    ref = np.asarray(rd.rollout(model, x0, rd.RolloutOptions(20 * steps, dt / 20))[0])[::20]
    dop = scipy_peer.solver(scipy_peer.compiled_rhs(model), "DOP853", x0, t_eval, 1e-12)
    check = float(np.abs(dop().y.T - ref).max())  # (its atol: 1e-14)
    run = rd.simulate(model, q0, None, 10.0, dt, "rk4")
    err_rd = float(np.abs(np.concatenate([run.q, run.qd], 1) - ref).max())
    print(f"reference: RK4 at {dt / 20:g} s; it differs from SciPy DOP853 (rtol 1e-12) by "
          f"{check:.1e}; robodyn RK4 at 1 ms: max |x - x_ref| = {err_rd:.1e}")
    start = time.perf_counter()
    lamb = lambdified_rhs(robot, values)
    t_lamb = time.perf_counter() - start
    target = scipy_peer.MATCH_FACTOR * err_rd
    fns = {"robodyn rd.rollout": lambda: rd.rollout(model, x0, rd.RolloutOptions(steps, dt)),
           "robodyn rd.simulate": lambda: rd.simulate(model, q0, None, 10.0, dt, "rk4")}
    errors = {"robodyn rd.rollout": err_rd, "robodyn rd.simulate": err_rd}
    settings = {"robodyn rd.rollout": "RK4 at 1 ms in robodyn's generated C, one call",
                "robodyn rd.simulate": "the same, plus qdd, energy and the Trajectory result"}
    sweeps = {}
    for label, rhs, method, text in (
            ("RK45 + lambdify", lamb, "RK45", "sympy.lambdify of robodyn's own Lagrange M(q) "
             f"and h(q, qd) with np.linalg.solve per call (lambdify itself {t_lamb:.1f} s, not "
             "timed)"),
            ("DOP853 + compiled RHS", scipy_peer.compiled_rhs(model), "DOP853",
             "robodyn's compiled Model.state_derivative, one state per call from Python")):
        trials, matched = scipy_peer.sweep(rhs, method, x0, t_eval, ref, target, label=label)
        sweeps[label] = scipy_peer.sweep_record(trials, matched, method, label.split(" + ")[1],
                                                target)
        timed, status = scipy_peer.timed_setting(trials, matched)
        fns[f"SciPy {label}"] = scipy_peer.solver(rhs, method, x0, t_eval, timed.rtol)
        errors[f"SciPy {label}"] = timed.max_error
        settings[f"SciPy {label}"] = (f"{scipy_peer.describe(method, timed, matched is not None)}"
                                      f": {text}")
    times = timing.interleaved(fns, repeats)
    rows = [{"label": k, "ms": results.summary(v, 1e3, 2), "max_error": errors[k],
             "vs_simulate": results.ratio(v, times["robodyn rd.simulate"], 1),
             "vs_rollout": results.ratio(v, times["robodyn rd.rollout"], 1),
             "settings": settings[k]} for k, v in times.items()]
    print(f"{'':34s}{'min ms':>9s}{'median':>9s}{'max err':>10s}  / rd.simulate  / rd.rollout")
    for r in rows:
        print(f"  {r['label']:32s}{r['ms']['min']:9.2f}{r['ms']['median']:9.2f}"
              f"{r['max_error']:10.1e}  {r['vs_simulate']['min']:8.1f}x {r['vs_rollout']['min']:12.1f}x")
    for r in rows:
        print(f"  {r['label']}: {r['settings']}")
    return {"steps": steps, "dt": dt, "repeats": repeats, "robodyn_error": err_rd,
            "reference": f"robodyn RK4 at {dt / 20:g} s",
            "reference_vs_dop853_1e-12": check, "rows": rows, "sweeps": sweeps}


def main() -> None:
    """Command line: run the parts, merge their figures into the results file."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="only the simulation part, 3 rounds")
    results.add_options(parser)
    args = parser.parse_args()
    path = results.target(args)
    entry: dict[str, Any] = {
        "command": "python benchmarks/bench_hydro.py" + (" --quick" if args.quick else ""),
        "load_average_at_start": results.load_average()}
    if not args.quick:
        entry["wet_dry"] = wet_dry()
        entry["drag"] = strips_benchmark()
    entry["simulation"] = solve_ivp_benchmark(3 if args.quick else REPEATS)
    if path is not None:
        print(f"figures written to {results.merge(path, 'hydro', entry)}")


if __name__ == "__main__":
    main()
