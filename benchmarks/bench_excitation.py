"""Excitation design for the PUMA 560 (6 joints, 5 harmonics): condition number, time, baselines.

Prints the optimised condition number beside the best of 100 random Fourier trajectories of the
same size and limits (measured in the same run), the wall and CPU time of the design (one run:
it takes about a minute), and the time of one criterion and gradient with the compiled regressor
derivatives against central differences of the regressor (same problem, same point, same run;
min / median over rounds in which the two take turns; ratio and agreement printed). The range of
condition numbers quoted for optimised 7-joint designs (about 90-120) is the figure given in
issue 9 of this project; it is not checked against a cited paper here, so treat it as an order
of magnitude, not a published reference. Condition numbers depend on the parameter units, the
limits and the friction columns, so only same-run comparisons are like for like.

Full runs merge the figures into ``benchmarks/results/<machine>.json`` (benchmark
``excitation``). Run: ``.venv/bin/python benchmarks/bench_excitation.py [--quick]
[--results PATH | --no-results]`` (``--quick``: one start of 5 iterations, 20 random designs,
3 rounds; written only with ``--results``).
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
import warnings
from pathlib import Path
from typing import Any

import numpy as np

import robodyn as rd
from robodyn.studies.excitation import (
    _Layout,
    _null_bases,
    _Problem,
    condition_number,
    excitation_limits,
    random_fourier,
)

sys.path.insert(0, str(Path(__file__).resolve().parent))
import results  # noqa: E402
import timing  # noqa: E402

REPEATS = 5
#: Calls of the criterion and gradient per timed repeat (their mean is the repeat's time).
CALLS = 20
TARGETS = {"condition_number": 100.0, "design_s": 60.0}
#: A figure NOT measured in this run, with its source.
QUOTED = {"7-joint designs": {
    "low": 90, "high": 120, "what": "condition numbers of optimised 7-joint excitation designs",
    "source": "stated in issue 9 of this project, not checked against a cited paper and not "
              "measured in this run: an order of magnitude, not a published reference"}}


def gradient_times(model: rd.Model, columns: tuple[int, ...], harmonics: int = 5,
                   repeats: int = REPEATS) -> dict[str, Any]:
    """Criterion and gradient, analytic against central differences, rows taking turns.

    Parameters
    ----------
    model : Model
        The compiled robot.
    columns : tuple of int
        Regressor columns of the design.
    harmonics : int
        Harmonics per joint.
    repeats : int
        Rounds; each times the mean of :data:`CALLS` calls of each row.

    Returns
    -------
    dict
        ``samples``, ``calls_per_repeat``, ``ms`` (min / median per row), ``ratio`` (central
        differences / analytic) and ``max_rel_difference`` of the two gradients.
    """
    f, k = 0.1, 20 * harmonics
    lim = excitation_limits(model.robot)
    layout = _Layout(model.dof, harmonics, *_null_bases(harmonics, f))
    x = layout.pack(random_fourier(lim, harmonics, f, np.random.default_rng(7), samples=k))
    problems, grads = {}, {}
    for label, how in (("analytic", "analytic"), ("central differences", "finite_difference")):
        problems[label] = _Problem(model, layout, f, k, columns, lim, "cond", how)
        grads[label] = problems[label].objective(x)[1]  # warm-up (the analytic kernel loads here)

    def calls(problem: _Problem) -> None:
        for _ in range(CALLS):
            problem.objective(x)

    t = timing.interleaved({label: (lambda p=p: calls(p)) for label, p in problems.items()},
                           repeats)
    diff = grads["analytic"] - grads["central differences"]
    return {"samples": k, "calls_per_repeat": CALLS, "repeats": repeats,
            "ms": {label: results.summary(v, 1e3 / CALLS, 2) for label, v in t.items()},
            "ratio": results.ratio(t["central differences"], t["analytic"]),
            "max_rel_difference": float(np.max(np.abs(diff))
                                        / np.max(np.abs(grads["central differences"])))}


def design(model: rd.Model, quick: bool) -> tuple[Any, dict[str, Any]]:
    """The optimised design (one run) with its settings, wall and CPU time."""
    options = {"starts": 1, "max_iterations": 5} if quick else {}
    wall, cpu = time.perf_counter(), time.process_time()
    ex = rd.excitation(model, harmonics=5, seed=0, **options)
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    settings = ("rd.excitation defaults: criterion cond, gradient by central differences of the "
                "regressor, SLSQP, 40 iterations per start" if not quick else
                "rd.excitation with one start of 5 SLSQP iterations (quick mode)")
    return ex, {"joints": model.dof, "harmonics": 5, "columns": len(ex.columns),
                "starts": ex.starts, "samples": ex.design_samples,
                "condition_number": round(float(ex.condition_number), 2),
                "wall_s": round(wall, 2), "cpu_s": round(cpu, 2), "settings": settings}


def random_designs(model: rd.Model, ex: Any, count: int) -> dict[str, Any]:
    """Condition numbers of ``count`` random Fourier designs of the same size and limits."""
    rng = np.random.default_rng(2024)
    t = np.arange(ex.design_samples) * ex.series.period / ex.design_samples
    start = time.perf_counter()
    conds = [condition_number(model, *random_fourier(ex.limits, 5, ex.series.base_frequency,
                                                     rng).evaluate(t), ex.columns)
             for _ in range(count)]
    seconds = time.perf_counter() - start
    return {"designs": count, "best": round(float(min(conds)), 1),
            "median": round(float(statistics.median(conds)), 1), "seconds": round(seconds, 3),
            "best_over_optimised": round(float(min(conds) / ex.condition_number), 2)}


def main() -> None:
    """Command line: design, baselines, gradient timing; merge the figures into the results."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true",
                        help="one start of 5 iterations, 20 random designs, 3 rounds")
    results.add_options(parser)
    args = parser.parse_args()
    path = results.target(args)
    entry: dict[str, Any] = {
        "command": "python benchmarks/bench_excitation.py" + (" --quick" if args.quick else ""),
        "load_average_at_start": results.load_average(), "quoted": QUOTED, "targets": TARGETS}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = rd.compile_model(rd.load("puma560"))
    ex, entry["design"] = design(model, args.quick)
    entry["random"] = random_designs(model, ex, 20 if args.quick else 100)
    entry["gradient"] = gradient_times(model, ex.columns, repeats=3 if args.quick else REPEATS)
    d, r, g = entry["design"], entry["random"], entry["gradient"]
    entry["met"] = {"condition_number": d["condition_number"] < TARGETS["condition_number"],
                    "design_s": d["wall_s"] < TARGETS["design_s"]}
    met = {k: "met" if v else "not met" for k, v in entry["met"].items()}
    q = QUOTED["7-joint designs"]
    print(f"PUMA 560, 6 joints x 5 harmonics, {d['columns']} base columns, {d['starts']} starts")
    print(f"  optimised condition number   {d['condition_number']:8.1f}   (target < "
          f"{TARGETS['condition_number']:g}: {met['condition_number']})")
    print(f"  best of {r['designs']} random designs   {r['best']:8.1f}   (median {r['median']:.0f}; "
          f"ratio best-random / optimised {r['best_over_optimised']:.2f})")
    print(f"  optimised 7-joint designs    ~{q['low']}-{q['high']}   ({q['source']})")
    print(f"  design time (one run)        {d['wall_s']:8.1f} s wall, {d['cpu_s']:.1f} s CPU "
          f"(target < {TARGETS['design_s']:g} s: {met['design_s']}); {r['designs']} random "
          f"evaluations {r['seconds']:.2f} s")
    ms, ratio = g["ms"], g["ratio"]
    print(f"  criterion + gradient, {g['samples']} samples (min / median of {g['repeats']} rounds "
          f"of {CALLS} calls): analytic regressor derivatives {ms['analytic']['min']:.2f} / "
          f"{ms['analytic']['median']:.2f} ms, central differences "
          f"{ms['central differences']['min']:.2f} / {ms['central differences']['median']:.2f} ms "
          f"(ratio {ratio['min']:.2f}x / {ratio['median']:.2f}x; gradients agree to "
          f"{g['max_rel_difference']:.1e} relative)")
    if path is not None:
        print(f"figures written to {results.merge(path, 'excitation', entry)}")


if __name__ == "__main__":
    main()
