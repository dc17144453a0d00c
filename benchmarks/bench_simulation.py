"""Simulation speed against peers measured in the same run.

Prints:
  1. The thesis' benchmark (Table 3.1): the trolley with a double inverted pendulum, 5 s of
     motion under its own weight, RK4 at 1 ms: robodyn (generated C, one call) against MuJoCo
     stepping the same system (its own RK4 at 1 ms, looped from Python and with
     ``mujoco.rollout`` in C) and against the usual Python route, SciPy ``solve_ivp`` over SymPy
     ``lambdify`` of the equations (targets: >= 5x MuJoCo, >= 100x solve_ivp + lambdify); the
     thesis' CPU seconds beside ours, for the record.
  2. PUMA 560 batched kernels on 10^5 states (inverse dynamics, mass matrix, gravity, C qd,
     forward dynamics), ns per state, robodyn on one thread, against Pinocchio's rnea / crba /
     computeGeneralizedGravity / rnea without gravity at qdd = 0 / aba looped from Python (the
     Python loop's own cost per call is measured and printed: it is part of that ratio) and
     ``rneaInParallel`` / ``abaInParallel`` on ONE thread (a batch call with no Python per state:
     the like-for-like comparison) and on all cores. Not identical work: robodyn's tau includes
     the joint friction (viscous and Coulomb) of the PUMA description, Pinocchio's rnea does not;
     robodyn's C is compiled for this CPU (``-O3 -march=native``), Pinocchio is the installed wheel.
  3. Time to generate and compile the PUMA 560 model from scratch (fresh cache).

Run: ``.venv/bin/python benchmarks/bench_simulation.py [--quick]``.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
import warnings

import numpy as np
import sympy as sp
from peers import lambdified_rhs, pinocchio_loop  # noqa: E402
from timing import best_of  # noqa: E402

import robodyn as rd
from robodyn.simulate import simulate

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


def bench_trolley(quick: bool) -> None:
    import mujoco
    from scipy.integrate import solve_ivp

    robot = rd.load("trolley_double_pendulum")
    model = rd.compile_model(robot)
    q0 = np.array([0.0, 0.3, -0.2])
    x0 = np.concatenate([q0, np.zeros(3)])
    steps, dt = 5000, 1e-3
    print("== 1. Trolley + double inverted pendulum (thesis Fig. 3.1), 5 s, RK4 at 1 ms ==")
    t_c = best_of(lambda: model.integrate(x0, steps, dt, "rk4"), 20)
    t_sim = best_of(lambda: simulate(model, q0, None, 5.0, dt, "rk4"), 5)
    print(f"robodyn  Model.integrate (one C call)          {t_c * 1e3:9.3f} ms")
    print(f"robodyn  rd.simulate (+ qdd, energy, result)   {t_sim * 1e3:9.3f} ms")

    xml, source = trolley_mjcf(robot)
    mj = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(mj)

    def mj_loop():
        mujoco.mj_resetData(mj, data)
        data.qpos[:] = q0
        for _ in range(steps):
            mujoco.mj_step(mj, data)

    mujoco.mj_resetData(mj, data)
    data.qpos[:] = q0
    check = 500
    ref, _ = model.integrate(x0, check, dt, "rk4")
    mj_q = np.empty((check, 3))
    for k in range(check):
        mujoco.mj_step(mj, data)
        mj_q[k] = data.qpos
    agree = np.max(np.abs(mj_q - ref[1:, :3]))
    t_mj = best_of(mj_loop, 3)
    print(f"MuJoCo {mujoco.__version__} mj_step loop from Python       {t_mj * 1e3:9.3f} ms   "
          f"(model: {source}; |q_mujoco - q_robodyn| over 0.5 s = {agree:.1e} rad)")
    t_roll = None
    try:
        from mujoco import rollout

        mujoco.mj_resetData(mj, data)
        data.qpos[:] = q0
        spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
        state0 = np.empty(mujoco.mj_stateSize(mj, spec))
        mujoco.mj_getState(mj, data, state0, spec)
        rollout.rollout(mj, data, state0[None], nstep=steps)
        t_roll = best_of(lambda: rollout.rollout(mj, data, state0[None], nstep=steps), 5)
        print(f"MuJoCo mujoco.rollout (C loop)                 {t_roll * 1e3:9.3f} ms")
    except (ImportError, AttributeError, TypeError) as exc:
        print(f"MuJoCo rollout unavailable: {exc}")

    # accuracy: every result against DOP853 at rtol 1e-13 on the compiled model
    ref = simulate(model, q0, None, 5.0, dt, "DOP853", rtol=1e-13, atol=1e-13).x
    x_c, _ = model.integrate(x0, steps, dt, "rk4")
    print(f"  robodyn RK4 1 ms: max |x - x_ref| over the 5 s = {np.max(np.abs(x_c - ref)):.1e} "
          f"(chaotic motion: errors grow with time)")
    rhs = lambdified_rhs(robot)
    t_eval = np.arange(steps + 1) * dt
    ivp = {}
    # rtol 1e-8 is about the accuracy of robodyn's RK4 at 1 ms on this chaotic motion
    for rtol in ((1e-6, 1e-8, 1e-9) if quick else (1e-3, 1e-6, 1e-8, 1e-9)):
        start = time.perf_counter()
        sol = solve_ivp(rhs, (0.0, 5.0), x0, method="RK45", t_eval=t_eval, rtol=rtol, atol=rtol * 1e-2)
        ivp[rtol] = time.perf_counter() - start
        err = np.max(np.abs(sol.y.T - ref))
        print(f"SciPy solve_ivp RK45 + lambdify, rtol {rtol:.0e}   {ivp[rtol] * 1e3:9.1f} ms   "
              f"({sol.nfev} rhs calls, max |x - x_ref| = {err:.1e}; {ivp[rtol] / t_c:5.0f}x robodyn)")
    start = time.perf_counter()
    x = x0.copy()
    for _ in range(steps):
        k1 = rhs(0, x)
        k2 = rhs(0, x + dt / 2 * k1)
        k3 = rhs(0, x + dt / 2 * k2)
        k4 = rhs(0, x + dt * k3)
        x = x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    t_py_rk4 = time.perf_counter() - start
    print(f"Python RK4 loop at 1 ms + lambdify             {t_py_rk4 * 1e3:9.1f} ms   "
          f"(same scheme as robodyn: |x - x_robodyn| at 5 s = {np.max(np.abs(x - x_c[-1])):.1e})")
    print("ratios (robodyn one call):")
    print(f"  vs MuJoCo mj_step loop      {t_mj / t_c:8.1f}x   (target >= 5x)")
    if t_roll is not None:
        print(f"  vs MuJoCo rollout           {t_roll / t_c:8.1f}x   (target >= 5x)")
    for rtol, t_ivp in ivp.items():
        print(f"  vs solve_ivp + lambdify     {t_ivp / t_c:8.0f}x   (rtol {rtol:.0e}; target >= 100x)")
    print(f"  vs Python RK4 + lambdify    {t_py_rk4 / t_c:8.0f}x")
    print("thesis Table 3.1, CPU seconds for the same 5 s (1990s hardware, for the record only):")
    for name, secs in THESIS_TABLE_3_1.items():
        print(f"  {name:24s}{secs:10.2f} s")
    print(f"  {'robodyn (this machine)':24s}{t_c:10.5f} s")
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


def bench_puma(quick: bool) -> None:
    import pinocchio as pin

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = rd.load("puma560")
    model = rd.compile_model(robot)
    n_states = 10_000 if quick else 100_000
    rng = np.random.default_rng(0)
    q, qd, qdd = rng.uniform(-np.pi, np.pi, (3, n_states, 6))
    tau = model.inverse_dynamics(q, qd, qdd)
    print(f"== 2. PUMA 560 kernels, {n_states} states (ns per state) ==")
    ours = {
        "inverse dynamics": best_of(lambda: model.inverse_dynamics(q, qd, qdd), 5),
        "mass matrix": best_of(lambda: model.mass_matrix(q), 5),
        "gravity": best_of(lambda: model.gravity(q), 5),
        "coriolis C qd": best_of(lambda: model.coriolis(q, qd), 5),
        "forward dynamics": best_of(lambda: model.forward_dynamics(q, qd, tau), 5),
    }
    pmodel, source = pinocchio_puma(robot)
    pdata = pmodel.createData()
    # C(q, qd) qd is Pinocchio's RNEA at qdd = 0 without gravity
    pmodel_c = pin.Model(pmodel)
    pmodel_c.gravity.linear = np.zeros(3)
    pdata_c = pmodel_c.createData()
    zero = np.zeros(6)

    def pin_coriolis(_model, _data, qk, qdk):
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

    def loop(fn, *arrays):
        return pinocchio_loop(fn, pmodel, pdata, loops, *arrays)

    theirs = {
        "inverse dynamics": best_of(loop(pin.rnea, q, qd, qdd), 3) * n_states / loops,
        "mass matrix": best_of(loop(pin.crba, q), 3) * n_states / loops,
        "gravity": best_of(loop(pin.computeGeneralizedGravity, q), 3) * n_states / loops,
        "coriolis C qd": best_of(loop(pin_coriolis, q, qd), 3) * n_states / loops,
        "forward dynamics": best_of(loop(pin.aba, q, qd, tau), 3) * n_states / loops,
    }
    # the Python loop alone: the same iteration and indexing around a call that does nothing
    def nothing(_model, _data, *_states):
        return None

    overhead = best_of(loop(nothing, q, qd, qdd), 3) * n_states / loops
    one, parallel = {}, {}
    threads = os.cpu_count() or 1
    if hasattr(pin, "rneaInParallel"):
        qt, qdt, qddt, taut = (np.asfortranarray(a.T) for a in (q, qd, qdd, tau))
        out = np.empty((6, n_states), order="F")
        for k, into in ((1, one), (threads, parallel)):
            pool = pin.ModelPool(pmodel, k)
            into["inverse dynamics"] = best_of(
                lambda k=k, pool=pool: pin.rneaInParallel(k, pool, qt, qdt, qddt, out), 5)
            into["forward dynamics"] = best_of(
                lambda k=k, pool=pool: pin.abaInParallel(k, pool, qt, qdt, taut, out), 5)
    print("robodyn: one thread, C compiled with -O3 -march=native, tau includes joint friction; "
          "Pinocchio: installed wheel, rigid body + armature (no friction)")
    print(f"pin loop = Pinocchio called once per state from Python; {overhead / n_states * 1e9:.0f} ns "
          "of each call is the Python loop itself (measured around a no-op), included in 'loop ratio'")
    print(f"pin 1 thr / pin {threads} thr = rneaInParallel / abaInParallel on 1 / {threads} threads "
          "(one call for the whole batch)")
    print(f"{'kernel':20s}{'robodyn':>9s}{'pin loop':>10s}{'loop ratio':>12s}{'minus loop':>12s}"
          f"{'pin 1 thr':>11s}{'ratio':>7s}{f'pin {threads} thr':>12s}{'ratio':>7s}")
    for name, t in ours.items():
        ns = t / n_states * 1e9
        pl = theirs[name] / n_states * 1e9
        bare = (theirs[name] - overhead) / n_states * 1e9
        line = f"{name:20s}{ns:9.1f}{pl:10.1f}{pl / ns:11.1f}x{bare / ns:11.1f}x"
        if name in one:
            p1, pp = one[name] / n_states * 1e9, parallel[name] / n_states * 1e9
            line += f"{p1:11.1f}{p1 / ns:6.1f}x{pp:12.1f}{pp / ns:6.1f}x"
        print(line)
    print()


# --- 3. generation + compilation ---------------------------------------------------------------
def bench_compile() -> None:
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
    print(f"first time {build:.2f} s (after {imp:.2f} s of imports); from the cache {cached:.2f} s")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="fewer repetitions and states")
    args = parser.parse_args()
    bench_trolley(args.quick)
    bench_puma(args.quick)
    bench_compile()


if __name__ == "__main__":
    main()
