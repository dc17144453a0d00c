"""Kinematic calibration speed, against SciPy with finite-difference Jacobians in the same run.

For a "true" PUMA 560 with millimetre-level manufacturing errors measured by a tracker with
0.05 mm noise, in one run (rows that are compared take turns, min / median over the rounds):

  1. ``robodyn.calibration.calibrate`` end to end (placement, identifiability, Levenberg-Marquardt
     with the analytic Jacobian, covariance, calibrated Robot) from 200 poses, per error model
     (target: a whole calibration under 2 s);
  2. the same Levenberg-Marquardt problem (S-model, its identifiable parameters, same start,
     weights and tolerances) solved by ``scipy.optimize.least_squares(method="lm")`` with the
     analytic Jacobian and with a 2-point finite-difference Jacobian; the ratios and the
     agreement of the two solutions;
  3. 1000 poses x 3 targets with joint compliance and transmission errors in the truth:
     S-model + compliance + harmonics end to end (target: under 3 s), and its least-squares
     step with the analytic and with a 2-point finite-difference Jacobian;
  4. ``robodyn calibrate`` on that data in fresh processes (the robot's compiled model cached,
     Python's bytecode cache on): the whole command with and without its HTML report, what it
     does before the solve (a probe process that runs the command's steps up to the solver,
     the solver's ``import scipy.optimize`` included, and exits as the command does, without
     the interpreter's teardown; issue 22's target: at most 0.5 s), against, in the same
     rounds, ``python -c "import numpy"`` (the issue's pairing), the bare imports of
     the dependencies it needs by then (NumPy, ``scipy.optimize``: the robot's numbers come from
     robodyn's cache, without SymPy), ``import scipy.optimize`` and ``import sympy`` alone
     once NumPy is loaded, ``robodyn --help`` and an empty interpreter. The command's own
     progress lines give its solve and its cross-validation of the non-geometric terms; what
     comes after the solve (files, report, exit) is the rest of its wall time, per round.

Full runs merge the figures into ``benchmarks/results/<machine>.json`` (benchmark
``calibration``). Run: ``.venv/bin/python benchmarks/bench_calibration.py [--quick]
[--repeat N] [--results PATH | --no-results]`` (``--quick``: 3 rounds everywhere, written only
with ``--results``; a full run takes about 1.5-2 minutes on 2 cores).
"""

from __future__ import annotations

import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path
from typing import Any

import numpy as np

import robodyn as rd
from robodyn.calibration import calibrate, random_configurations
from robodyn.calibration.kinematics import rot, trans
from robodyn.calibration.solve import fit
from robodyn.studies.calibration_study import perturbed_robot, robot_frames, robot_positions

sys.path.insert(0, str(Path(__file__).resolve().parent))
import results  # noqa: E402
import timing  # noqa: E402

SIGMA = 5e-5
POSES = 200
MODELS = ("dh", "hayati", "s-model", "poe")
TARGETS = np.array([[0.031, -0.018, 0.076], [-0.045, 0.052, 0.060], [0.06, 0.04, 0.03]])
TERMS = ("compliance", "harmonics")
#: Targets (s): a whole 200-pose calibration, the 1000-pose combined one, before the CLI's solve
#: (issue 22 item 4; the earlier target was 1 s).
TARGET_MODEL_S, TARGET_COMBINED_S, TARGET_BEFORE_S, EARLIER_BEFORE_S = 2.0, 3.0, 0.5, 1.0


def error_models(robot: rd.Robot, q: np.ndarray, y: np.ndarray, repeats: int,
                 ) -> tuple[dict[str, Any], dict[str, Any]]:
    """Section 1: ``calibrate`` per error model, the models taking turns.

    Returns
    -------
    entry : dict
        ``rows`` (model, seconds, parameters, evaluations, RMS after), poses, noise, target.
    cals : dict
        Model name to its calibration.
    """
    with warnings.catch_warnings():  # DH's variance factor: its parallel axes (reported below)
        warnings.simplefilter("ignore")
        cals = {m: calibrate(robot, q, y, m, sigma=SIGMA) for m in MODELS}  # warm-up, results
        t = timing.interleaved({m: lambda m=m: calibrate(robot, q, y, m, sigma=SIGMA)
                                for m in MODELS}, repeats)
    rows = [{"model": m, "seconds": results.summary(t[m], 1, 4), "parameters": len(c.parameters),
             "evaluations": int(c.nfev), "after_rms_mm": round(c.after.rms * 1e3, 4)}
            for m, c in cals.items()]
    print(f"PUMA 560, {POSES} poses, tracker noise {SIGMA * 1e3:.3g} mm per coordinate, "
          f"{repeats} rounds")
    print(f"{'model':<9}{'min s':>9}{'median s':>10}{'params':>8}{'nfev':>6}{'after RMS/mm':>14}")
    for r in rows:
        s = r["seconds"]
        over = "  ** over the 2 s target" if s["min"] > TARGET_MODEL_S else ""
        print(f"{r['model']:<9}{s['min']:>9.4f}{s['median']:>10.4f}{r['parameters']:>8}"
              f"{r['evaluations']:>6}{r['after_rms_mm']:>14.4f}{over}")
    return {"poses": POSES, "noise_mm": SIGMA * 1e3, "repeats": repeats,
            "target_s": TARGET_MODEL_S, "rows": rows}, cals


def jacobians(robot: rd.Robot, cal: Any, q: np.ndarray, y: np.ndarray, repeats: int,
              ) -> dict[str, Any]:
    """Section 2: the S-model least-squares step, analytic against 2-point Jacobian, and the
    whole ``calibrate``, taking turns."""
    em = cal.model
    free = [em.index(n) for n in cal.parameter_names]
    step = {j: (lambda j=j: fit(em, em.initial, free, q, y, sigma=SIGMA, jacobian=j))
            for j in ("analytic", "2-point")}
    res = {j: f() for j, f in step.items()}
    t = timing.interleaved({**step, "calibrate": lambda: calibrate(robot, q, y, "s-model",
                                                                   sigma=SIGMA)}, repeats)
    entry = {"model": "s-model", "parameters": len(free), "repeats": repeats,
             "seconds": {k: results.summary(v, 1, 4) for k, v in t.items()},
             "evaluations": {j: int(r.nfev) for j, r in res.items()},
             "ratio_fd_vs_analytic": results.ratio(t["2-point"], t["analytic"]),
             "ratio_fd_vs_calibrate": results.ratio(t["2-point"], t["calibrate"]),
             "max_parameter_difference": float(np.abs(res["analytic"].params
                                                      - res["2-point"].params).max())}
    print("\nthe least-squares step alone (s-model, identifiable parameters, same start):")
    for j in ("analytic", "2-point"):
        s = entry["seconds"][j]
        print(f"  scipy least_squares(method='lm'), {j:>8} Jacobian: {s['min']:.4f} s "
              f"(median {s['median']:.4f}), {entry['evaluations'][j]} evaluations")
    r, w = entry["ratio_fd_vs_analytic"], entry["ratio_fd_vs_calibrate"]
    print(f"  ratio finite-difference / analytic (same solver): {r['min']:.1f}x "
          f"(median {r['median']:.1f}x)")
    print(f"  ratio finite-difference LM / whole rd.calibrate:  {w['min']:.2f}x")
    print(f"  largest parameter difference between the two solutions: "
          f"{entry['max_parameter_difference']:.2e}")
    return entry


def combined_data(robot: rd.Robot, true: rd.Robot) -> tuple[np.ndarray, np.ndarray]:
    """1000 poses x 3 targets measured on ``true`` with compliance and a harmonic error."""
    rng = np.random.default_rng(3)
    q = random_configurations(robot, 1000, rng)
    g = rd.compile_model(robot).gravity(q)
    q_link = q - 4e-6 * g + 1e-4 * np.cos(q) - 5e-5 * np.sin(q)  # compliance and a harmonic
    frames = robot_frames(true, q_link)
    y = np.einsum("nij,kj->nki", frames[:, :3, :3], TARGETS) + frames[:, None, :3, 3]
    return q, y + rng.normal(0, SIGMA, y.shape)


def combined(robot: rd.Robot, q: np.ndarray, y: np.ndarray, repeats: int) -> dict[str, Any]:
    """Section 3: S-model + compliance + harmonics, end to end and its least-squares step."""
    run = lambda: calibrate(robot, q, y, "s-model", sigma=SIGMA, nongeometric=TERMS)  # noqa: E731
    cal = run()
    em = cal.model
    free = [em.index(k) for k in cal.parameter_names]
    pts = y.reshape(-1, 3)
    fns = {"calibrate": run}
    for j in ("analytic", "2-point"):
        fns[j] = lambda j=j: fit(em, em.initial, free, q, pts, sigma=SIGMA, jacobian=j)
    t = timing.interleaved(fns, repeats)
    entry = {"poses": len(q), "targets": len(TARGETS), "terms": list(TERMS), "repeats": repeats,
             "parameters": len(cal.parameters), "evaluations": int(cal.nfev),
             "after_rms_mm": round(cal.after.rms * 1e3, 4), "target_s": TARGET_COMBINED_S,
             "seconds": {k: results.summary(v, 1, 3) for k, v in t.items()},
             "ratio_fd_vs_analytic": results.ratio(t["2-point"], t["analytic"])}
    s = entry["seconds"]
    print(f"\n{len(q)} poses x {len(TARGETS)} targets, S-model + compliance + harmonics, "
          f"{repeats} rounds:")
    print(f"  rd.calibrate end to end: {s['calibrate']['min']:.3f} s (median "
          f"{s['calibrate']['median']:.3f}; {entry['parameters']} parameters, "
          f"{entry['evaluations']} evaluations, after RMS {entry['after_rms_mm']:.4f} mm)"
          f"{'  ** over 3 s' if s['calibrate']['min'] > TARGET_COMBINED_S else ''}")
    for j in ("analytic", "2-point"):
        print(f"  least-squares step, {j:>8} Jacobian: {s[j]['min']:.3f} s (median "
              f"{s[j]['median']:.3f})")
    print(f"  ratio finite-difference / analytic: {entry['ratio_fd_vs_analytic']['min']:.1f}x")
    return entry


#: What ``robodyn calibrate`` runs before the solve, up to the solver's import (which the
#: command makes inside ``rd.calibrate``), then the command's own fast exit (``cli.run``).
#: Prints whether SymPy was loaded by then.
STARTUP_PROBE = """
import os
import sys
import robodyn.cli
from robodyn.cli.workflows import calibration_inputs
args = robodyn.cli._parser().parse_args(["calibrate", "puma560", "--data", sys.argv[1], "-o", "o",
                                         "--nongeometric", "compliance", "--nongeometric",
                                         "harmonics"])
calibration_inputs(args)
import scipy.optimize
print("sympy" in sys.modules, flush=True)
os._exit(0)
"""

#: A fresh process that imports ``{pre}`` and prints how long ``import {timed}`` then takes.
IMPORT_PROBE = ("import os, time\nimport {pre}\nt = time.perf_counter()\nimport {timed}\n"
                "print(time.perf_counter() - t, flush=True)\nos._exit(0)")


def fresh_rounds(rows: dict[str, tuple[list[str], bool]], rounds: int, env: dict[str, str],
                 ) -> tuple[dict[str, list[float]], dict[str, list[str]]]:
    """Run fresh processes, the rows taking turns, ``rounds`` times.

    Parameters
    ----------
    rows : dict
        Name to (argv, in_process): with ``in_process`` the figure is the float the process
        prints last on stdout; otherwise its wall time from start to exit, s.
    rounds : int
    env : dict
        The processes' environment.

    Returns
    -------
    times : dict
        Name to its figure per round, s.
    stderr : dict
        Name to its last round's standard error (the command's progress lines).
    """
    times: dict[str, list[float]] = {k: [] for k in rows}
    err: dict[str, list[str]] = {k: [] for k in rows}
    for _ in range(rounds):
        for name, (argv, in_process) in rows.items():
            start = time.perf_counter()
            out = subprocess.run(argv, check=True, capture_output=True, text=True, env=env)
            wall = time.perf_counter() - start
            times[name].append(float(out.stdout.split()[-1]) if in_process else wall)
            err[name].append(out.stderr)
    return times, err


def _progress(stderr: list[str], label: str) -> list[float]:
    """The seconds of the command's progress line ``label... X s``, per round."""
    found = [re.search(rf"^{label}.*?\.\.\. ([\d.]+) s", e, re.M) for e in stderr]
    if not all(found):
        raise RuntimeError(f"robodyn calibrate printed no '{label}... X s' line: {stderr[0]!r}")
    return [float(m[1]) for m in found if m]


def cli(robot: rd.Robot, q: np.ndarray, y: np.ndarray, rounds: int) -> dict[str, Any]:
    """Section 4: ``robodyn calibrate`` and its start-up in fresh processes, rows taking turns."""
    py = sys.executable
    # every process caches compiled bytecode, as Python does by default (this machine sets
    # PYTHONDONTWRITEBYTECODE, which recompiles robodyn's modules on every start)
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "poses.csv"
        cols = [*robot.joint_names] + [f"{a}{k if k > 1 else ''}" for k in (1, 2, 3) for a in "xyz"]
        np.savetxt(path, np.hstack((q, y.reshape(len(q), -1))), delimiter=",",
                   header=",".join(cols), comments="")
        cmd = [py, "-m", "robodyn.cli", "calibrate", "puma560", "--data", str(path),
               "--nongeometric", "compliance", "--nongeometric", "harmonics",
               "-o", str(Path(tmp) / "o")]
        rows = {"command": (cmd, False), "command --no-report": ([*cmd, "--no-report"], False),
                "before the solve": ([py, "-c", STARTUP_PROBE, str(path)], False),
                "import numpy process": ([py, "-c", "import numpy"], False),
                "numpy + scipy.optimize": (
                    [py, "-c", "import numpy, scipy.optimize, os; os._exit(0)"], False),
                "import scipy.optimize after numpy": (
                    [py, "-c", IMPORT_PROBE.format(pre="numpy", timed="scipy.optimize")], True),
                "import sympy after numpy": (
                    [py, "-c", IMPORT_PROBE.format(pre="numpy", timed="sympy")], True),
                "robodyn --help": ([py, "-m", "robodyn.cli", "--help"], False),
                "empty interpreter": ([py, "-c", "pass"], False)}
        # one command first: writes the bytecode caches and the robot's compiled model
        fresh_rounds({"command": rows["command"]}, 1, env)
        t, err = fresh_rounds(rows, rounds, env)
        sympy_loaded = subprocess.run(rows["before the solve"][0], check=True, text=True, env=env,
                                      capture_output=True).stdout.split()[0] == "True"
    return _cli_entry(t, err, rounds, sympy_loaded)


def _cli_entry(t: dict[str, list[float]], err: dict[str, list[str]], rounds: int,
               sympy_loaded: bool) -> dict[str, Any]:
    """The ``cli`` entry from the rounds' figures; prints it."""
    for k in ("command", "command --no-report"):
        t[f"{k}: solve"] = _progress(err[k], "calibrating")
        t[f"{k}: terms"] = _progress(err[k], "cross-validating")
    # after the solve, per round: the command's wall time less the probe's (before the solve),
    # less its own solve and terms-check lines; the optimizer's import is in both the probe and
    # the solve line, so it is added back once
    after = {k: [c - b - s - x + i for c, b, s, x, i in zip(
        t[k], t["before the solve"], t[f"{k}: solve"], t[f"{k}: terms"],
        t["import scipy.optimize after numpy"], strict=True)] for k in ("command", "command --no-report")}
    before, numpy = t["before the solve"], t["import numpy process"]
    floor = t["numpy + scipy.optimize"]
    entry = {"rounds": rounds, "poses": 1000, "targets": 3, "terms": list(TERMS),
             "command_line": "python -m robodyn.cli calibrate puma560 --data poses.csv "
                             "--nongeometric compliance --nongeometric harmonics -o DIR",
             "sympy_loaded_before_solve": sympy_loaded,
             "target_before_s": TARGET_BEFORE_S, "earlier_target_before_s": EARLIER_BEFORE_S,
             "seconds": {k: results.summary(v, 1, 3) for k, v in t.items()},
             "after_solve_s": {k: {"min": round(min(v), 3), "median": round(statistics.median(v), 3)}
                               for k, v in after.items()},
             "before_vs_import_numpy": results.ratio(before, numpy),
             "before_vs_floor": results.ratio(before, floor),
             "before_minus_floor_s": {"min": round(min(before) - min(floor), 3),
                                      "median": round(statistics.median(before)
                                                      - statistics.median(floor), 3)}}
    s = entry["seconds"]
    print(f"\nrobodyn calibrate on the same data, fresh processes, {rounds} rounds "
          "(min / median, s):")
    for k, v in s.items():
        print(f"  {k:<40}{v['min']:7.3f}{v['median']:8.3f}")
    b = s["before the solve"]["min"]
    print(f"  before the solve {b:.3f} s: target <= {TARGET_BEFORE_S} s "
          f"{'met' if b <= TARGET_BEFORE_S else 'NOT met'}; "
          f"{entry['before_vs_import_numpy']['min']:.2f}x python -c 'import numpy', "
          f"{entry['before_vs_floor']['min']:.2f}x the bare imports "
          f"(SymPy loaded before the solve: {sympy_loaded})")
    for k, v in entry["after_solve_s"].items():
        print(f"  after the solve ({k}): {v['min']:.2f} s (median {v['median']:.2f})")
    return entry


def main() -> None:
    """Command line: run the four parts, merge their figures into the results file."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="3 rounds everywhere")
    parser.add_argument("--repeat", type=int, default=5, help="rounds (at least 3; default 5)")
    results.add_options(parser)
    args = parser.parse_args()
    repeats = 3 if args.quick else max(3, args.repeat)
    path = results.target(args)
    command = "python benchmarks/bench_calibration.py" + (" --quick" if args.quick else "")
    if not args.quick and repeats != 5:
        command += f" --repeat {repeats}"
    entry: dict[str, Any] = {"command": command, "load_average_at_start": results.load_average()}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = rd.load("puma560")
    tracker = trans(2.2, -0.8, -0.4) @ rot("z", 0.6) @ rot("x", 0.005)
    true = perturbed_robot(robot, 0, base=tracker, target=tuple(TARGETS[0]))
    rng = np.random.default_rng(1)
    q = random_configurations(robot, POSES, rng)
    y = robot_positions(true, q) + rng.normal(0, SIGMA, (POSES, 3))
    entry["models"], cals = error_models(robot, q, y, repeats)
    entry["jacobian"] = jacobians(robot, cals["s-model"], q, y, repeats)
    q3, y3 = combined_data(robot, true)
    entry["combined"] = combined(robot, q3, y3, repeats)
    entry["cli"] = cli(robot, q3, y3, repeats)
    if path is not None:
        print(f"figures written to {results.merge(path, 'calibration', entry)}")


if __name__ == "__main__":
    main()
