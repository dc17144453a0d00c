"""Simulation speed against peers measured in the same run.

Prints (and, on full runs, merges into ``benchmarks/results/<machine>.json`` as benchmark
``simulation``: ``trolley``, ``puma`` and ``compile``):
  1. The thesis' benchmark (Table 3.1): the trolley with a double inverted pendulum, 5 s of
     motion under its own weight, RK4 at 1 ms: robodyn (generated C, one call; and
     ``rd.simulate``) against MuJoCo stepping the same system (its own RK4 at 1 ms, contacts
     disabled, looped from Python with ``mj_step`` and with ``mujoco.rollout`` in C), against
     the usual Python route, SciPy ``solve_ivp`` RK45 over SymPy ``lambdify`` of the equations,
     against SciPy at its best, ``solve_ivp`` DOP853 over robodyn's compiled
     ``Model.state_derivative`` (``scipy_peer.py``; both at matched accuracy: the loosest
     tolerance of a sweep whose error against a DOP853 rtol 1e-13 reference is within 2x of
     robodyn's), and against a Python RK4 loop over ``lambdify`` (targets: >= 5x MuJoCo,
     >= 100x solve_ivp + lambdify). Rows timed in turns, min / median over the rounds; the
     thesis' CPU seconds printed for the record.
  2. PUMA 560 batched kernels on 10^5 states (inverse dynamics, mass matrix, gravity, C qd,
     forward dynamics), ns per state, robodyn on one thread, against Pinocchio's rnea / crba /
     computeGeneralizedGravity / rnea without gravity at qdd = 0 / aba looped from Python (the
     Python loop's own cost per call is measured and printed: it is part of that ratio) and
     ``rneaInParallel`` / ``abaInParallel`` on ONE thread (a batch call with no Python per state:
     the like-for-like comparison) and on all cores. Not identical work: robodyn's tau includes
     the joint friction (viscous and Coulomb) of the PUMA description, Pinocchio's rnea does not;
     robodyn's C is compiled for this CPU (``-O3 -march=native``), Pinocchio is the installed
     wheel (``bench_kernels.py`` compares against Pinocchio compiled natively).
  3. Time to generate and compile the PUMA 560 model from scratch (fresh cache), one run.

Run: ``.venv/bin/python benchmarks/bench_simulation.py [--quick] [--results PATH | --no-results]``
(``--quick``: 3 rounds, 10,000 PUMA states; written only with ``--results``).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import sympy as sp

import robodyn as rd

sys.path.insert(0, str(Path(__file__).resolve().parent))
import results  # noqa: E402
import scipy_peer  # noqa: E402
import timing  # noqa: E402
from peers import lambdified_rhs, pinocchio_loop  # noqa: E402

#: The thesis' Table 3.1 (CPU s for 5 s of the trolley double pendulum, 1990s workstations) and the a2m
#: MEX figure from the text of section 3.7.
THESIS_TABLE_3_1 = {"AUTOLEV": 84.9, "DADS-3D": 319.26, "DADS-2D": 65.28, "SD/FAST": 21.83,
                  "a2m MEX under Simulink": 8.99}


# --- 1. trolley double pendulum ----------------------------------------------------------------
def trolley_mjcf(robot: rd.Robot) -> tuple[str, str]:
    """MJCF of the trolley double pendulum: robodyn's exporter when present, else by hand."""
    try:
        from robodyn.export.mjcf import to_mjcf

        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return to_mjcf(robot, timestep=0.001, integrator="RK4"), "robodyn.export.mjcf.to_mjcf"
    except ImportError:
        pass
    p = {k: float(v) for k, v in robot.parameters.items()}
    i1, i2 = p["m1"] * p["l1"] ** 2 / 12, p["m2"] * p["l2"] ** 2 / 12
    # rods along z, hinges about y; tiny inertias where the true ones are zero (MuJoCo needs > 0)
    text = f"""<mujoco model="trolley_double_pendulum">
  <option timestep="0.001" integrator="RK4" gravity="0 0 {-p['g']}"><flag contact="disable"/></option>
  <worldbody>
    <body name="trolley">
      <joint name="x" type="slide" axis="1 0 0"/>
      <inertial pos="0 0 0" mass="{p['M']}" diaginertia="1e-9 1e-9 1e-9"/>
      <body name="rod1">
        <joint name="theta1" type="hinge" axis="0 1 0"/>
        <inertial pos="0 0 {p['l1'] / 2}" mass="{p['m1']}" diaginertia="{i1} {i1} 1e-12"/>
        <body name="rod2" pos="0 0 {p['l1']}">
          <joint name="theta2" type="hinge" axis="0 1 0"/>
          <inertial pos="0 0 {p['l2'] / 2}" mass="{p['m2']}" diaginertia="{i2} {i2} 1e-12"/>
        </body>
      </body>
    </body>
  </worldbody>
  <actuator><motor joint="x"/><motor joint="theta1"/><motor joint="theta2"/></actuator>
</mujoco>"""
    return text, "hand-written MJCF (robodyn.export.mjcf not importable)"


def _mujoco_trolley(robot: rd.Robot, q0: np.ndarray, steps: int,
                    ) -> tuple[dict[str, Callable[[], Any]], np.ndarray, str]:
    """MuJoCo's two routes for the trolley: a Python loop over ``mj_step`` and ``rollout``.

    Returns
    -------
    fns : dict
        Row label to a callable running the 5 s.
    x : ndarray (steps, 6)
        MuJoCo's state (qpos, qvel) after each step (from ``rollout``).
    source : str
        Where the MJCF came from.
    """
    import mujoco
    from mujoco import rollout

    xml, source = trolley_mjcf(robot)
    mj = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(mj)

    def mj_loop() -> None:
        mujoco.mj_resetData(mj, data)
        data.qpos[:] = q0
        for _ in range(steps):
            mujoco.mj_step(mj, data)

    mujoco.mj_resetData(mj, data)
    data.qpos[:] = q0
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    state0 = np.empty(mujoco.mj_stateSize(mj, spec))
    mujoco.mj_getState(mj, data, state0, spec)
    states, _ = rollout.rollout(mj, data, state0[None], nstep=steps)
    fns = {"MuJoCo mj_step loop": mj_loop,
           "MuJoCo rollout": lambda: rollout.rollout(mj, data, state0[None], nstep=steps)}
    return fns, states[0, :, 1:1 + 2 * len(q0)], source


def _python_rk4(rhs: Callable[[float, np.ndarray], np.ndarray], x0: np.ndarray, steps: int,
                dt: float) -> np.ndarray:
    """RK4 at a fixed step in a Python loop over ``rhs``: the trajectory (steps + 1, n)."""
    xs = np.empty((steps + 1, len(x0)))
    xs[0] = x = x0.copy()
    for k in range(steps):
        k1 = rhs(0, x)
        k2 = rhs(0, x + dt / 2 * k1)
        k3 = rhs(0, x + dt / 2 * k2)
        k4 = rhs(0, x + dt * k3)
        xs[k + 1] = x = x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    return xs


def bench_trolley(quick: bool) -> dict[str, Any]:
    """The thesis' trolley benchmark against MuJoCo and SciPy; the ``trolley`` results entry.

    Parameters
    ----------
    quick : bool
        3 rounds instead of 5.

    Returns
    -------
    dict
        ``rows`` (label, ms min/median, max error against the reference, settings), ratios to
        ``rd.rollout``, the two SciPy sweeps, robodyn's error and the reference's check.
    """
    robot = rd.load("trolley_double_pendulum")
    model = rd.compile_model(robot)
    q0 = np.array([0.0, 0.3, -0.2])
    x0 = np.concatenate([q0, np.zeros(3)])
    steps, dt, repeats = 5000, 1e-3, (3 if quick else 5)
    t_eval = np.arange(steps + 1) * dt
    print("== 1. Trolley + double inverted pendulum (thesis Fig. 3.1), 5 s, RK4 at 1 ms ==")
    # reference: DOP853 at rtol = atol = 1e-13 on the compiled model, checked against RK4 at dt / 20
    ref = rd.simulate(model, q0, None, 5.0, dt, "DOP853", rtol=1e-13, atol=1e-13).x
    fine = rd.rollout(model, x0, rd.RolloutOptions(20 * steps, dt / 20))[0][::20]
    check = float(np.max(np.abs(fine - ref)))
    err_rd = float(np.max(np.abs(rd.rollout(model, x0, rd.RolloutOptions(steps, dt))[0] - ref)))
    print(f"reference: DOP853 rtol = atol = 1e-13 (compiled model); RK4 at {dt / 20:g} s differs "
          f"by {check:.1e}; robodyn RK4 at 1 ms: max |x - x_ref| over 5 s = {err_rd:.1e} "
          "(chaotic motion: errors grow with time)")
    target = scipy_peer.MATCH_FACTOR * err_rd
    lamb = lambdified_rhs(robot)
    sweeps = {}
    for label, rhs, method in (("RK45 + lambdify", lamb, "RK45"),
                               ("DOP853 + compiled RHS", scipy_peer.compiled_rhs(model), "DOP853")):
        trials, matched = scipy_peer.sweep(rhs, method, x0, t_eval, ref, target, label=label)
        sweeps[label] = scipy_peer.sweep_record(trials, matched, method, label.split(" + ")[1],
                                                target)
        sweeps[label]["run"] = (rhs, *scipy_peer.timed_setting(trials, matched))
    fns, mj_x, source = _mujoco_trolley(robot, q0, steps)
    fns = {"robodyn rd.rollout": lambda: rd.rollout(model, x0, rd.RolloutOptions(steps, dt)),
           "robodyn rd.simulate": lambda: rd.simulate(model, q0, None, 5.0, dt, "rk4"), **fns}
    errors = {"robodyn rd.rollout": err_rd, "robodyn rd.simulate": err_rd,
              "MuJoCo mj_step loop": float(np.max(np.abs(mj_x - ref[1:])))}
    errors["MuJoCo rollout"] = errors["MuJoCo mj_step loop"]
    for label, s in sweeps.items():
        rhs, timed, _ = s.pop("run")
        fns[f"SciPy {label}"] = scipy_peer.solver(rhs, s["method"], x0, t_eval, timed.rtol)
        errors[f"SciPy {label}"] = timed.max_error
    fns["Python RK4 loop + lambdify"] = lambda: _python_rk4(lamb, x0, steps, dt)
    errors["Python RK4 loop + lambdify"] = float(np.max(np.abs(_python_rk4(lamb, x0, steps, dt) - ref)))
    times = timing.interleaved(fns, repeats)
    rows = _trolley_rows(times, errors, sweeps, source)
    entry = {"steps": steps, "dt": dt, "repeats": repeats, "robodyn_error": err_rd,
             "reference": "DOP853 rtol = atol = 1e-13 on robodyn's compiled model",
             "reference_vs_rk4_dt_over_20": check, "match_factor": scipy_peer.MATCH_FACTOR,
             "rows": rows, "sweeps": sweeps, "mujoco_model": source,
             # the targets: robodyn's one call at least this many times faster
             "targets": {"MuJoCo mj_step loop": 5.0, "MuJoCo rollout": 5.0,
                         "SciPy RK45 + lambdify": 100.0}}
    _print_trolley(entry)
    return entry


def _trolley_rows(times: dict[str, list[float]], errors: dict[str, float],
                  sweeps: dict[str, dict[str, Any]], source: str) -> list[dict[str, Any]]:
    """Rows of the trolley entry: times, errors, ratio to ``rd.rollout``, what differs."""
    import mujoco

    settings = {
        "robodyn rd.rollout": "RK4 at 1 ms in robodyn's generated C, one call, the state "
                                   "and torque recorded every step",
        "robodyn rd.simulate": "the same call, plus qdd, energy and the Trajectory result",
        "MuJoCo mj_step loop": f"MuJoCo {mujoco.__version__}: its RK4 at 1 ms, contacts disabled, "
                               "the full mj_step pipeline, one mj_step per step from a Python "
                               f"loop, nothing recorded (model: {source})",
        "MuJoCo rollout": "the same model stepped by mujoco.rollout (its C loop, 1 thread), "
                          "full-physics state recorded every step",
        "Python RK4 loop + lambdify": "the same RK4 at 1 ms as robodyn, written in Python over "
                                      "lambdify (M, h; np.linalg.solve per call)",
    }
    for label, s in sweeps.items():
        rhs = ("sympy.lambdify of robodyn's own M(q), h(q, qd) and np.linalg.solve per call"
               if s["rhs"] == "lambdify" else
               "robodyn's compiled Model.state_derivative, one state per call from Python")
        trial = scipy_peer.Trial(**s["timed"])
        settings[f"SciPy {label}"] = (
            f"{scipy_peer.describe(s['method'], trial, s['matched'] is not None)}: {rhs}")
    base = times["robodyn rd.rollout"]
    rows = []
    for name, t in times.items():
        rows.append({"label": name, "ms": results.summary(t, 1e3, 3),
                     "max_error": errors[name], "vs_rollout": results.ratio(t, base, 1),
                     "settings": settings[name]})
    return rows


def _print_trolley(entry: dict[str, Any]) -> None:
    """Print the trolley rows: ms min / median, error, ratio to ``rd.rollout``."""
    print(f"{'':34s}{'min ms':>9s}{'median':>9s}{'max err':>10s}  time / rd.rollout")
    for r in entry["rows"]:
        print(f"  {r['label']:32s}{r['ms']['min']:9.3f}{r['ms']['median']:9.3f}"
              f"{r['max_error']:10.1e}  {r['vs_rollout']['min']:7.1f}x "
              f"({r['vs_rollout']['median']:.1f}x)")
    for r in entry["rows"]:
        print(f"  {r['label']}: {r['settings']}")
    print("thesis Table 3.1, CPU seconds for the same 5 s (1990s hardware, for the record only):")
    for name, secs in THESIS_TABLE_3_1.items():
        print(f"  {name:24s}{secs:10.2f} s")
    print()


# --- 2. PUMA 560 kernels -----------------------------------------------------------------------
def pinocchio_puma(robot: rd.Robot):
    """Pinocchio model of the PUMA: from robodyn's URDF exporter when present, else built here."""
    import pinocchio as pin

    try:
        from robodyn.export.urdf import to_urdf

        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            model = pin.buildModelFromXML(to_urdf(robot))
        source = "robodyn.export.urdf.to_urdf"
    except ImportError:
        model, source = _pinocchio_from_robot(robot), "built from robodyn's Robot"
    values = robot.defaults()
    for j, joint in enumerate(robot.joints):
        # reflected rotor inertia G^2 Jm (URDF has no place for it)
        model.armature[j] = float((joint.drive.gear_ratio**2 * joint.drive.rotor_inertia).xreplace(values))
    model.gravity.linear = np.array(robot.gravity.xreplace(values), dtype=float).ravel()
    return model, source


def _pinocchio_from_robot(robot: rd.Robot):
    """Joint i sits at ``post_{i-1} pre_i`` in the frame of joint i-1 (``base pre_1`` for i = 1);
    link i's inertia is placed at ``post_i`` in joint i's frame."""
    import pinocchio as pin

    values = robot.defaults()

    def mat(m):
        return np.array(sp.Matrix(m).xreplace(values), dtype=float)

    model = pin.Model()
    parent, prev_post = 0, mat(robot.base)
    for joint, link in zip(robot.joints, robot.links, strict=True):
        place = prev_post @ mat(joint.pre)
        axis = mat(joint.axis).ravel()
        jm = (pin.JointModelRevoluteUnaligned(axis) if joint.type == "revolute"
              else pin.JointModelPrismaticUnaligned(axis))
        parent = model.addJoint(parent, jm, pin.SE3(place[:3, :3], place[:3, 3]), joint.name)
        post = mat(joint.post)
        inertia = pin.Inertia(float(link.mass.xreplace(values)), mat(link.com).ravel(), mat(link.inertia))
        model.appendBodyToJoint(parent, inertia, pin.SE3(post[:3, :3], post[:3, 3]))
        prev_post = post
    return model


def bench_puma(quick: bool) -> dict[str, Any]:
    """PUMA 560 kernels against Pinocchio's wheel from Python; the ``puma`` results entry.

    Parameters
    ----------
    quick : bool
        10,000 states and 3 rounds instead of 100,000 and 5.

    Returns
    -------
    dict
        ``rows``: per kernel, ns per state (min/median) of robodyn, of the Pinocchio loop, of
        the loop minus the Python loop's own cost, and of ``*InParallel`` on 1 and all threads.
    """
    import pinocchio as pin

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = rd.load("puma560")
    model = rd.compile_model(robot)
    n_states, repeats = (10_000, 3) if quick else (100_000, 5)
    rng = np.random.default_rng(0)
    q, qd, qdd = rng.uniform(-np.pi, np.pi, (3, n_states, 6))
    tau = model.inverse_dynamics(q, qd, qdd)
    print(f"== 2. PUMA 560 kernels, {n_states} states (ns per state) ==")
    ours = {"inverse dynamics": lambda: model.inverse_dynamics(q, qd, qdd),
            "mass matrix": lambda: model.mass_matrix(q), "gravity": lambda: model.gravity(q),
            "coriolis C qd": lambda: model.coriolis(q, qd),
            "forward dynamics": lambda: model.forward_dynamics(q, qd, tau)}
    pmodel, source = pinocchio_puma(robot)
    pdata = pmodel.createData()
    # C(q, qd) qd is Pinocchio's RNEA at qdd = 0 without gravity
    pmodel_c = pin.Model(pmodel)
    pmodel_c.gravity.linear = np.zeros(3)
    pdata_c = pmodel_c.createData()
    zero = np.zeros(6)

    def pin_coriolis(_model: Any, _data: Any, qk: np.ndarray, qdk: np.ndarray) -> np.ndarray:
        return pin.rnea(pmodel_c, pdata_c, qk, qdk, zero)

    # same model? M (rotor inertia included), g and C qd against Pinocchio at a few states
    dm = max(np.max(np.abs(pin.crba(pmodel, pdata, q[k]) - model.mass_matrix(q[k]))) for k in range(20))
    dg = max(np.max(np.abs(pin.computeGeneralizedGravity(pmodel, pdata, q[k]) - model.gravity(q[k])))
             for k in range(20))
    dc = max(np.max(np.abs(pin_coriolis(None, None, q[k], qd[k]) - model.coriolis(q[k], qd[k])))
             for k in range(20))
    print(f"Pinocchio {pin.__version__} model: {source}; max |M - M_pin| = {dm:.1e}, "
          f"|g - g_pin| = {dg:.1e}, |C qd - (C qd)_pin| = {dc:.1e}")
    loops = min(n_states, 20_000)

    def loop(fn: Callable[..., Any], *arrays: np.ndarray) -> Callable[[], None]:
        return pinocchio_loop(fn, pmodel, pdata, loops, *arrays)

    theirs = {"inverse dynamics": loop(pin.rnea, q, qd, qdd), "mass matrix": loop(pin.crba, q),
              "gravity": loop(pin.computeGeneralizedGravity, q),
              "coriolis C qd": loop(pin_coriolis, q, qd),
              "forward dynamics": loop(pin.aba, q, qd, tau),
              # the Python loop alone: the same iteration and indexing around a no-op
              "python loop": loop(lambda *_: None, q, qd, qdd)}
    threads = os.cpu_count() or 1
    qt, qdt, qddt, taut = (np.asfortranarray(a.T) for a in (q, qd, qdd, tau))
    out = np.empty((6, n_states), order="F")
    batch = {}
    for k in (1, threads):
        pool = pin.ModelPool(pmodel, k)
        batch[f"inverse dynamics {k}"] = (
            lambda k=k, pool=pool: pin.rneaInParallel(k, pool, qt, qdt, qddt, out))
        batch[f"forward dynamics {k}"] = (
            lambda k=k, pool=pool: pin.abaInParallel(k, pool, qt, qdt, taut, out))
    t_ours = timing.interleaved(ours, repeats)
    t_loop = timing.interleaved(theirs, repeats)
    t_batch = timing.interleaved(batch, repeats)
    entry = _puma_entry(t_ours, t_loop, t_batch, n_states, loops, threads, repeats)
    entry.update(pinocchio=f"{pin.__version__} wheel, model from {source} with armature",
                 agreement={"M": float(dm), "g": float(dg), "C qd": float(dc)})
    _print_puma(entry)
    return entry


def _puma_entry(t_ours: dict[str, list[float]], t_loop: dict[str, list[float]],
                t_batch: dict[str, list[float]], n_states: int, loops: int, threads: int,
                repeats: int) -> dict[str, Any]:
    """The ``puma`` entry from the three groups of timings (ns per state, ratios to robodyn)."""
    ns_loop = results.summary(t_loop["python loop"], 1e9 / loops)
    rows = []
    for name, t in t_ours.items():
        # per state: the loop covers `loops` states, the others all `n_states`
        loop_t = [x * n_states / loops for x in t_loop[name]]
        bare = [x - min(t_loop["python loop"]) * n_states / loops for x in loop_t]
        row = {"kernel": name, "robodyn": results.summary(t, 1e9 / n_states),
               "pinocchio_loop": results.summary(loop_t, 1e9 / n_states),
               "loop_ratio": results.ratio(loop_t, t, 1),
               "minus_loop_ratio": results.ratio(bare, t, 1)}
        for k, key in ((1, "one_thread"), (threads, "all_threads")):
            if f"{name} {k}" in t_batch:
                row[key] = results.summary(t_batch[f"{name} {k}"], 1e9 / n_states)
                row[key + "_ratio"] = results.ratio(t_batch[f"{name} {k}"], t, 1)
        rows.append(row)
    return {"states": n_states, "repeats": repeats, "loop_states": loops, "threads": threads,
            "python_loop_ns": ns_loop, "rows": rows,
            "settings": "robodyn: one thread, generated C (-O3 -march=native), tau includes the "
                        "PUMA's joint friction; Pinocchio: the installed wheel (generic build), "
                        "rigid body + armature, no friction; 'loop': one call per state from "
                        "Python (the loop's own cost included; 'minus loop' takes it out); "
                        f"rneaInParallel / abaInParallel: one call for the batch on 1 and "
                        f"{threads} threads"}


def _print_puma(entry: dict[str, Any]) -> None:
    """Print the PUMA table (minima; ratios of minima)."""
    print(entry["settings"])
    print(f"the Python loop alone: {entry['python_loop_ns']['min']:.0f} ns per call (min)")
    th = entry["threads"]
    print(f"{'kernel':20s}{'robodyn':>9s}{'pin loop':>10s}{'loop ratio':>12s}{'minus loop':>12s}"
          f"{'pin 1 thr':>11s}{'ratio':>7s}{f'pin {th} thr':>12s}{'ratio':>7s}")
    for r in entry["rows"]:
        line = (f"{r['kernel']:20s}{r['robodyn']['min']:9.1f}{r['pinocchio_loop']['min']:10.1f}"
                f"{r['loop_ratio']['min']:11.1f}x{r['minus_loop_ratio']['min']:11.1f}x")
        if "one_thread" in r:
            line += (f"{r['one_thread']['min']:11.1f}{r['one_thread_ratio']['min']:6.1f}x"
                     f"{r['all_threads']['min']:12.1f}{r['all_threads_ratio']['min']:6.1f}x")
        print(line)
    print()


# --- 3. generation + compilation ---------------------------------------------------------------
def bench_compile() -> dict[str, float]:
    """Load, derive, generate and compile the PUMA 560 in a fresh process with an empty cache.

    Returns
    -------
    dict
        ``imports_s``, ``first_s`` and ``cached_s`` (one run each).
    """
    code = ("import time, warnings; warnings.simplefilter('ignore'); t0 = time.perf_counter(); "
            "import robodyn as rd; t1 = time.perf_counter(); r = rd.load('puma560'); "
            "m = rd.compile_model(r); t2 = time.perf_counter(); "
            "print(f'{t1 - t0:.3f} {t2 - t1:.3f}')")
    with tempfile.TemporaryDirectory() as cache:
        env = {**os.environ, "ROBODYN_CACHE": cache}
        out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                             check=True)
        imp, build = (float(v) for v in out.stdout.split())
        again = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                               check=True)
        _, cached = (float(v) for v in again.stdout.split())
    print("== 3. PUMA 560: load + derive + generate + compile C, fresh ROBODYN_CACHE ==")
    print(f"first time {build:.2f} s (`import robodyn` before it: {imp:.2f} s); from the cache "
          f"{cached:.2f} s")
    return {"imports_s": imp, "first_s": build, "cached_s": cached}


def main() -> None:
    """Command line: run the three parts, merge their figures into the results file."""
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="fewer repetitions and states")
    results.add_options(parser)
    args = parser.parse_args()
    path = results.target(args)
    start_load = results.load_average()
    entry: dict[str, Any] = {"command": " ".join(["python benchmarks/bench_simulation.py",
                                                  *(["--quick"] if args.quick else [])]),
                             "load_average_at_start": start_load}
    entry["trolley"] = bench_trolley(args.quick)
    entry["puma"] = bench_puma(args.quick)
    entry["compile"] = bench_compile()
    if path is not None:
        print(f"figures written to {results.merge(path, 'simulation', entry)}")


if __name__ == "__main__":
    main()
