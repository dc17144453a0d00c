"""Kinematic calibration speed, against SciPy with finite-difference Jacobians in the same run.

Prints, for a "true" PUMA 560 with millimetre-level manufacturing errors measured at 200 poses
by a tracker with 0.05 mm noise (target: a whole calibration under 2 s):

  1. ``robodyn.calibration.calibrate`` end to end (placement, identifiability, Levenberg-Marquardt
     with the analytic Jacobian, covariance, calibrated Robot), per error model;
  2. the same Levenberg-Marquardt problem (same model, parameters, start, weights and
     tolerances) solved by ``scipy.optimize.least_squares(method="lm")`` with the analytic
     Jacobian and with a 2-point finite-difference Jacobian; the ratios and the agreement of
     the solutions.

  3. 1000 poses x 3 targets with joint compliance and transmission errors in the truth:
     S-model + compliance + harmonics end to end (target: under 3 s), its least-squares step
     with the analytic and with a 2-point finite-difference Jacobian, and the CLI's total wall
     time (``robodyn calibrate`` in a fresh process) against the solve time, split into the
     part before solving (target: under 1 s) and the outputs written after it.

Run: ``.venv/bin/python benchmarks/bench_calibration.py [--repeat N]``.
"""

from __future__ import annotations

import argparse
import warnings

import numpy as np
from timing import best_of_with_result as best_of

import robodyn as rd
from robodyn.calibration import calibrate, random_configurations
from robodyn.calibration.kinematics import rot, trans
from robodyn.calibration.solve import fit
from robodyn.studies.calibration_study import perturbed_robot, robot_positions

SIGMA = 5e-5
POSES = 200


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5, help="timing repeats (best is kept)")
    args = parser.parse_args()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = rd.load("puma560")
    tracker = trans(2.2, -0.8, -0.4) @ rot("z", 0.6) @ rot("x", 0.005)
    true = perturbed_robot(robot, 0, base=tracker, target=(0.031, -0.018, 0.076))
    rng = np.random.default_rng(1)
    q = random_configurations(robot, POSES, rng)
    y = robot_positions(true, q) + rng.normal(0, SIGMA, (POSES, 3))
    print(f"PUMA 560, {POSES} poses, tracker noise {SIGMA * 1e3:.3g} mm per coordinate")
    print(f"{'model':<9}{'calibrate/s':>13}{'params':>8}{'nfev':>6}{'after RMS/mm':>14}")
    cals = {}
    for model in ("dh", "hayati", "s-model", "poe"):
        calibrate(robot, q, y, model, sigma=SIGMA)  # warm up
        t, cal = best_of(lambda m=model: calibrate(robot, q, y, m, sigma=SIGMA), args.repeat)
        cals[model] = cal
        print(f"{model:<9}{t:>13.3f}{len(cal.parameters):>8}{cal.nfev:>6}{cal.after.rms * 1e3:>14.4f}")
        if t > 2.0:
            print(f"  ** {model}: over the 2 s target")

    print("\nthe least-squares step alone (s-model, identifiable parameters from the same start):")
    cal = cals["s-model"]
    em = cal.model
    free = [em.index(n) for n in cal.parameter_names]
    runs = {}
    for jac in ("analytic", "2-point"):
        t, res = best_of(lambda j=jac: fit(em, em.initial, free, q, y, sigma=SIGMA, jacobian=j), args.repeat)
        runs[jac] = (t, res)
        print(f"  scipy least_squares(method='lm'), {jac:>8} Jacobian: {t:.4f} s, {res.nfev} evaluations")
    t_cal = best_of(lambda: calibrate(robot, q, y, "s-model", sigma=SIGMA), args.repeat)[0]
    t_an, res_an = runs["analytic"]
    t_fd, res_fd = runs["2-point"]
    diff = np.abs(res_an.params - res_fd.params).max()
    print(f"  ratio finite-difference / analytic (same solver): {t_fd / t_an:.1f}x")
    print(f"  ratio finite-difference LM / whole rd calibrate:  {t_fd / t_cal:.2f}x")
    print(f"  largest parameter difference between the two solutions: {diff:.2e}")
    combined(robot, true, args.repeat)


def combined(robot, true, repeat: int) -> None:
    """Section 3: 1000 poses x 3 targets, S-model + compliance + harmonics."""
    import subprocess
    import sys
    import tempfile
    from pathlib import Path

    from robodyn.calibration.io import write_calibration_csv  # noqa: F401 (format reference)
    from robodyn.studies.calibration_study import robot_frames

    n, targets = 1000, np.array([[0.031, -0.018, 0.076], [-0.045, 0.052, 0.060], [0.06, 0.04, 0.03]])
    rng = np.random.default_rng(3)
    q = random_configurations(robot, n, rng)
    g = rd.compile_model(robot).gravity(q)
    q_link = q - 4e-6 * g + 1e-4 * np.cos(q) - 5e-5 * np.sin(q)  # compliance and a harmonic
    frames = robot_frames(true, q_link)
    y = np.einsum("nij,kj->nki", frames[:, :3, :3], targets) + frames[:, None, :3, 3]
    y = y + rng.normal(0, SIGMA, y.shape)
    terms = ("compliance", "harmonics")
    import os
    import resource

    print(f"\n{n} poses x {len(targets)} targets, S-model + compliance + harmonics "
          f"(load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} CPUs):")
    run = lambda: calibrate(robot, q, y, "s-model", sigma=SIGMA, nongeometric=terms)  # noqa: E731
    run()
    t_cal, cal = best_of(run, repeat)
    print(f"  rd.calibrate end to end: {t_cal:.3f} s ({len(cal.parameters)} parameters, {cal.nfev} "
          f"evaluations, after RMS {cal.after.rms * 1e3:.4f} mm){'  ** over 3 s' if t_cal > 3 else ''}")
    em = cal.model
    free = [em.index(k) for k in cal.parameter_names]
    pts, sig = y.reshape(-1, 3), SIGMA
    times = {}
    for jac in ("analytic", "2-point"):
        times[jac] = best_of(lambda j=jac: fit(em, em.initial, free, q, pts, sigma=sig, jacobian=j),
                             max(1, repeat // 2))[0]
        print(f"  least-squares step, {jac:>8} Jacobian: {times[jac]:.3f} s")
    print(f"  ratio finite-difference / analytic: {times['2-point'] / times['analytic']:.1f}x")
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "poses.csv"
        cols = [*robot.joint_names] + [f"{a}{k if k > 1 else ''}" for k in (1, 2, 3) for a in "xyz"]
        np.savetxt(path, np.hstack((q, y.reshape(n, -1))), delimiter=",", header=",".join(cols),
                   comments="")
        cmd = [sys.executable, "-m", "robodyn.cli", "calibrate", "puma560", "--data", str(path),
               "--nongeometric", "compliance", "--nongeometric", "harmonics", "-o", str(Path(tmp) / "o")]
        # every process below runs as Python does by default, caching compiled bytecode (this
        # machine sets PYTHONDONTWRITEBYTECODE, which recompiles robodyn's ~60 modules on every
        # start, about 0.1 s); the first run writes the cache
        env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
        subprocess.run([*cmd, "--no-report"], check=True, capture_output=True, env=env)
        t_cli = best_of(lambda: subprocess.run(cmd, check=True, capture_output=True, env=env), 2)[0]
        t_quiet = best_of(lambda: subprocess.run([*cmd, "--no-report"], check=True,
                                                 capture_output=True, env=env), 2)[0]
        # everything the command does before it starts solving, in a fresh process: start the
        # interpreter, import the CLI, build the parser, load the robot, import the calibration
        # code, read the CSV
        before = [sys.executable, "-c", STARTUP_PROBE, str(path)]
        cpu0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        t_proc, probe = best_of(lambda: subprocess.run(before, check=True, capture_output=True,
                                                       text=True, env=env), 1)
        cpu1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        # CPU seconds of that process: what it costs without the other processes' competition
        cpu_before = (cpu1.ru_utime - cpu0.ru_utime) + (cpu1.ru_stime - cpu0.ru_stime)
        # the command reaches the solver after the interpreter's start plus the probe's own
        # elapsed time; the probe process's exit (freeing SymPy's and SciPy's modules) comes
        # after the solve in the real command, so it is not counted before it
        t_start = best_of(lambda: subprocess.run([sys.executable, "-c", "pass"], check=True,
                                                 env=env), 3)[0]
        # the floor robodyn cannot go below: its dependencies' own imports (SymPy for the robot
        # description, SciPy's optimizer for the solve, NumPy) in a fresh process, same timing
        floor = [sys.executable, "-c", "import time; t = time.perf_counter(); import numpy, sympy, "
                 "scipy.optimize; print(time.perf_counter() - t)"]
        t_floor = t_start + min(float(subprocess.run(floor, check=True, capture_output=True,
                                                     text=True, env=env).stdout) for _ in range(3))
        t_probe = [float(subprocess.run(before, check=True, capture_output=True, text=True,
                                        env=env).stdout.split()[-1]) for _ in range(2)]
        t_before = t_start + min([float(probe.stdout.split()[-1]), *t_probe])
        t_help = best_of(lambda: subprocess.run([sys.executable, "-m", "robodyn.cli", "--help"],
                                                check=True, capture_output=True, env=env),
                         max(1, repeat // 2))[0]
    print(f"  CLI total wall time {t_cli:.2f} s = {t_cli / t_cal:.2f}x the solve "
          f"(total minus solve {t_cli - t_cal:.2f} s: before + after below)")
    print(f"  before solving (start, imports incl. the solver's, parser, robot, CSV; fresh process): "
          f"{t_before:.2f} s wall (interpreter start {t_start:.3f} s + {t_before - t_start:.2f} s "
          f"in the process) = {t_before / t_cal:.2f}x the solve"
          f"{'  ** over 1 s' if t_before > 1 else ''}; the probe process in all, with its exit, "
          f"{t_proc:.2f} s wall, {cpu_before:.2f} s CPU")
    print(f"  the dependencies' bare imports (interpreter start + numpy, sympy, scipy.optimize; "
          f"best of 3): {t_floor:.2f} s; robodyn's own share before solving "
          f"{t_before - t_floor:.2f} s ({t_before / t_floor:.2f}x the floor)")
    print(f"  after solving (YAML, URDF, JSON, residual CSV, HTML report with figures, exit): "
          f"{t_cli - t_before - t_cal:.2f} s; 'robodyn --help' alone {t_help:.2f} s")
    print(f"  with --no-report (no HTML figure): CLI total {t_quiet:.2f} s = {t_quiet / t_cal:.2f}x "
          f"the solve, after solving {t_quiet - t_before - t_cal:.2f} s")


#: What ``robodyn calibrate`` runs before ``rd.calibrate``, for a fresh-process timing.
STARTUP_PROBE = """
import time
start = time.perf_counter()
import sys
import robodyn.cli
args = robodyn.cli._parser().parse_args(["calibrate", "puma560", "--data", sys.argv[1], "-o", "o"])
import robodyn as rd
from robodyn.calibration.io import read_calibration_csv
from robodyn.calibration.data_checks import convert_units
robot = rd.load(args.robot)
data = read_calibration_csv(args.data, robot)
import scipy.optimize  # the solver's import, made on the first solve: overhead, not solving
print(time.perf_counter() - start)
"""

if __name__ == "__main__":
    main()
