"""Kinematic calibration speed, against SciPy with finite-difference Jacobians in the same run.

Prints, for a "true" PUMA 560 with millimetre-level manufacturing errors measured at 200 poses
by a tracker with 0.05 mm noise (target: a whole calibration under 2 s):

  1. ``robodyn.calibrate.calibrate`` end to end (placement, identifiability, Levenberg-Marquardt
     with the analytic Jacobian, covariance, calibrated Robot), per error model;
  2. the same Levenberg-Marquardt problem (same model, parameters, start, weights and
     tolerances) solved by ``scipy.optimize.least_squares(method="lm")`` with the analytic
     Jacobian and with a 2-point finite-difference Jacobian; the ratios and the agreement of
     the solutions.

Run: ``.venv/bin/python benchmarks/bench_calibration.py [--repeat N]``.
"""

from __future__ import annotations

import argparse
import time
import warnings

import numpy as np

import robodyn as rd
from robodyn.calibrate import calibrate, random_configurations
from robodyn.calibrate.kinematics import rot, trans
from robodyn.calibrate.simulate_study import perturbed_robot, robot_positions
from robodyn.calibrate.solve import fit

SIGMA = 5e-5
POSES = 200


def best_of(fn, repeat: int):
    """Smallest wall time of ``repeat`` calls, and the last result."""
    best, out = float("inf"), None
    for _ in range(repeat):
        start = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - start)
    return best, out


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


if __name__ == "__main__":
    main()
