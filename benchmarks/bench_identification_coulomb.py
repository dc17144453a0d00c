"""The prediction's smoothed Coulomb step on every row of the quality table, and on simulated runs.

``rd.identify(..., coulomb_width=w)`` keeps the fit and smooths the linear law's Coulomb step in
the predictions (``robodyn.identification.coulomb_width``): the expected friction where the
estimated velocity's sign is uncertain (joints held still, slow reversals). Two sections:

1. on each row of ``bench_identification_quality.py`` (same data sets and splits, same error),
   the default (``"auto"``: the width from the velocity noise) beside the same call with each
   fixed width and the textbook script (entry ``identification_coulomb``);
2. simulated runs (``--simulated N``, default 48): noisy PUMA 560 logs (1800 samples at 11 ms,
   uniform or 10-12 ms stamps in turn, 1e-4 rad of position noise, torque noise 2 % of each
   joint's peak), identified once with the step, then predicted with the width at several
   multiples of each run's velocity noise: the squared error against the noise-free torque
   relative to the step's, pooled over the runs, as the mean of the runs' ratios and as the
   share of runs it lowers (entry ``identification_coulomb_simulated``): what the smoothing
   does where only the few samples near reversals are touched.

Run: ``python benchmarks/bench_identification_coulomb.py [--quick] [--only kuka,kinova,virtual]
[--simulated N] [--results PATH | --no-results]``.
"""

from __future__ import annotations

import sys
from dataclasses import replace
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).parent))
sys.path.insert(0, str(Path(__file__).parents[1]))
# first: the quality benchmark it imports limits BLAS and OpenMP to one thread before NumPy
# loads, as for the table's own figures (2 BLAS threads moved the Kinova torque row's 4th digit)
import bench_identification_weight as weight  # noqa: E402
import numpy as np  # noqa: E402
import results  # noqa: E402

import robodyn as rd  # noqa: E402
from robodyn.identification.coulomb_width import WIDTH_PER_NOISE, velocity_noise  # noqa: E402

#: Widths tried beside the default (0: the step itself), rad/s.
WIDTHS = (0.002, 0.005, 0.01, 0.02)
#: Widths per standard deviation of the velocity noise tried on the simulated runs.
FACTORS = (0.0, 0.6, WIDTH_PER_NOISE, 2.5)


def simulated(runs: int) -> dict[str, Any]:
    """Section 2: squared error of each width factor relative to the step's, over ``runs``."""
    from tests.identification.helpers import fourier

    robot = rd.load("puma560")
    model = rd.compile_model(robot)
    sq = np.zeros((runs, len(FACTORS)))
    for k in range(runs):
        rng = np.random.default_rng(1000 + k)
        t = np.cumsum(rng.uniform(0.010, 0.012, 1800)) if k % 2 else np.arange(1800) * 0.011
        q, qd, qdd = fourier(t, robot.dof, rng)
        tau = model.inverse_dynamics(q, qd, qdd)
        rec = rd.Recording(t=t, q=q + rng.normal(0.0, 1e-4, q.shape), source=f"run {k}",
                           tau=tau + rng.standard_normal(tau.shape) * 0.02 * np.abs(tau).max(axis=0))
        ident = rd.identify(robot, rec, model=model, coulomb_width=0.0, resonance=False)
        noise = velocity_noise(rec, ident.preprocess)
        inner = slice(t.size // 20, -t.size // 20)  # away from the filter's ends
        for i, f in enumerate(FACTORS):
            pred = replace(ident, coulomb_width=f * noise).predict(rec)
            sq[k, i] = float(np.sum((pred[inner] - tau[inner]) ** 2))
    pooled = sq.sum(axis=0) / sq[:, 0].sum()
    ratios = sq / sq[:, :1]
    mean, lower = ratios.mean(axis=0), (ratios < 1.0).mean(axis=0)
    for f, p, m, low in zip(FACTORS, pooled, mean, lower, strict=True):
        print(f"  width {f:.3g} x velocity noise: squared error / the step's: pooled {p:.3f}, "
              f"mean of the runs' ratios {m:.3f}, median {np.median(ratios[:, FACTORS.index(f)]):.3f}, "
              f"lower in {low:.0%} of the runs")
    return {"runs": runs, "factors": [float(f"{f:.4g}") for f in FACTORS],
            "default_factor": float(f"{WIDTH_PER_NOISE:.4g}"),
            "pooled_ratio": [float(f"{p:.4g}") for p in pooled],
            "mean_ratio": [float(f"{m:.4g}") for m in mean],
            "median_ratio": [float(f"{m:.4g}") for m in np.median(ratios, axis=0)],
            "share_lower": [float(f"{x:.3g}") for x in lower]}


def _simulated_section(args: Any, path: Path | None) -> None:
    """Section 2, its entry merged into ``path`` (None: not written)."""
    print(f"simulated runs ({args.simulated}):")
    entry = simulated(args.simulated)
    if path is not None:
        results.merge(path, "identification_coulomb_simulated", {
            "command": " ".join(["python", "benchmarks/bench_identification_coulomb.py",
                                 *sys.argv[1:]]),
            "what": "noisy simulated PUMA 560 logs identified with the step, predicted with the "
                    "Coulomb step smoothed over factor x the run's velocity noise; squared error "
                    "against the noise-free torque relative to the step's", **entry})
        print(f"results: {path}")


def main() -> None:
    """Section 1 (through the weight benchmark's runner), then section 2."""
    weight.main("bench_identification_coulomb.py", "identification_coulomb", "coulomb_width",
                WIDTHS, "width",
                "the default rd.identify (the predictions' Coulomb step smoothed over a width "
                "from the velocity noise) beside the same call with each fixed width (rad/s), "
                "and the textbook", __doc__,
                options=lambda p: p.add_argument("--simulated", type=int, default=48, metavar="N",
                                                 help="simulated runs (default: %(default)s)"),
                after=_simulated_section)


if __name__ == "__main__":
    main()
