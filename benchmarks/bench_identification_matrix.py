"""The default identification against the textbook on a matrix of virtual-lab configurations.

The quality table (``bench_identification_quality.py``) holds a dozen fixed rows; this script
looks for configurations where the default ``rd.identify`` loses to the textbook script
(``benchmarks/textbook.py``), as issue 20 asks: "build for the general case". Each configuration
is one arm (``lwr4``: the KUKA LWR4+ URDF; ``gen3``; ``puma``; ``aa300``: the built-in AA300, a
revolute-prismatic-revolute cylindrical robot; ``alpha5``: the built-in Reach Alpha 5, a small
four-joint arm, in air), one logging rate, one target
(``current``: motor currents, drives the description lacks on the LWR4+ and the Gen3, values
printed to 4 decimals; ``tau``: joint torque sensors, 0.08 N m noise, 20 gaps of 15 samples),
one plant draw (``quality_cases._perturbed`` with that seed) and one validation (``jointwise``:
another excitation run and a jointwise run with static holds; ``other``: another excitation run;
``period``: the last quarter of the fit run). Printed: raw and filtered held-out error of the
textbook and of the default, and the noise floor; nothing is written to the results file (the
figures quoted in docs/identification.md from it name their configuration).
``--stamp-tick SECONDS`` rounds every recording's stamps to a logger clock of that tick while
the samples were taken as the sensors say (``0.002`` at 94 Hz: stamps 10 or 12 ms apart, as
issue 20's cobot logs them, on samples taken every 10.6 ms).

Run: ``python benchmarks/bench_identification_matrix.py lwr4:1000:tau:1:jointwise
[ARM:RATE:TARGET:SEED:VALIDATION ...] [--stamp-tick SECONDS]`` (no configuration: those of
:data:`DEFAULT_CONFIGURATIONS`).
"""

from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
sys.path.insert(0, str(Path(__file__).parents[1]))
import bench_identification_quality as quality  # noqa: E402
import quality_cases as qc  # noqa: E402

import robodyn as rd  # noqa: E402

#: The configurations run without arguments (those quoted in docs/identification.md).
DEFAULT_CONFIGURATIONS = ("lwr4:1000:tau:1:jointwise", "lwr4:1000:tau:2:jointwise",
                          "lwr4:1000:tau:1:period", "lwr4:4000:tau:1:other",
                          "lwr4:50:current:1:jointwise", "gen3:94:current:1:jointwise",
                          "gen3:50:tau:1:other", "puma:250:current:1:jointwise")
ARMS = {"lwr4": (qc.KUKA / "kuka_lwr4.urdf", None), "gen3": (qc.KINOVA / "gen3.urdf", "kinova_gen3"),
        "puma": (None, "puma560"), "aa300": (None, "aa300"), "alpha5": (None, "reach_alpha5")}
VALIDATIONS = ("jointwise", "other", "period")


def configuration(text: str) -> tuple[str, float, str, int, str]:
    """``ARM:RATE:TARGET:SEED:VALIDATION`` checked, as a tuple."""
    parts = text.split(":")
    if (len(parts) != 5 or parts[0] not in ARMS or parts[2] not in ("current", "tau")
            or parts[4] not in VALIDATIONS or not parts[3].isdigit()):
        raise argparse.ArgumentTypeError(
            f"{text!r}: expected ARM:RATE:TARGET:SEED:VALIDATION with ARM in {sorted(ARMS)}, "
            f"TARGET current or tau, SEED an integer and VALIDATION in {VALIDATIONS}")
    try:
        rate = float(parts[1])
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: the rate {parts[1]!r} is not a number (Hz)") from None
    if not 10.0 <= rate <= 10_000.0:
        raise argparse.ArgumentTypeError(f"{text!r}: the rate must be 10-10000 Hz")
    return parts[0], rate, parts[2], int(parts[3]), parts[4]


def _plant(desc: rd.Robot, arm: str, target: str, seed: int) -> rd.Robot:
    """The description perturbed (seed), with drives it lacks for currents (LWR4+, Gen3)."""
    plant = qc._perturbed(desc, seed)
    return plant if target != "current" or arm == "puma" else qc.with_drives(plant, 100 + seed)


def case(arm: str, rate: float, target: str, seed: int, validation: str,
         stamp_tick: float = 0.0) -> quality.Case:
    """The fit and held-out recordings of one configuration (module docstring); ``stamp_tick``
    > 0: the stamps rounded to that clock (:func:`quality_cases.ticked`)."""
    from robodyn.studies.testprog import jointwise
    from robodyn.studies.virtual_lab import Sensors, virtual_lab

    urdf, builtin = ARMS[arm]
    desc = rd.load(builtin if builtin else str(urdf))
    plant, model = rd.compile_model(_plant(desc, arm, target, seed)), rd.compile_model(desc)
    dt = 1.0 / rate
    sens = (Sensors(sample_period=dt, jitter=0.1 * dt, counts_per_rev=4096.0, current_noise=0.03,
                    current_offset=0.02, torque_constant_error=0.03, torque_noise=None,
                    tracker_period=0.0) if target == "current" else
            Sensors(sample_period=dt, jitter=0.02 * dt, counts_per_rev=2**18, torque_noise=0.08,
                    tracker_period=0.0))
    programs = [rd.excitation(model, harmonics=4, base_frequency=1.0 / 40.0, starts=1, seed=s,
                              max_iterations=10, dt=min(dt, 0.01)) for s in (1, 2)]
    if validation == "jointwise":
        programs.append(jointwise(model, speeds=(0.5,), stroke=0.8))
    recs = [virtual_lab(plant, p, sensors=sens, seed=s).recording for s, p in enumerate(programs, 1)]
    if stamp_tick > 0:
        recs = [qc.ticked(r, stamp_tick) for r in recs]
    recs = ([qc._rounded(r, 4) for r in recs] if target == "current" else
            [qc._gapped(r, np.random.default_rng(s), gaps=20, length=15) for s, r in enumerate(recs)])
    if validation == "period":
        k = int(0.75 * recs[0].n_samples)
        recs = [recs[0].slice(recs[0].t[0], recs[0].t[k - 1]), recs[0].slice(recs[0].t[k], recs[0].t[-1])]
    name = f"{arm} {rate:g} Hz {target} seed {seed} {validation}" + (
        f" stamps to {stamp_tick * 1e3:g} ms" if stamp_tick > 0 else "")
    return quality.Case(name, desc, None if urdf is None else str(urdf), recs[:1], recs[1:], target)


def main() -> None:
    """Command line: run each configuration, print the textbook's and the default's errors."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("configurations", nargs="*", type=configuration,
                        help="ARM:RATE:TARGET:SEED:VALIDATION (default: the documented set)")
    parser.add_argument("--stamp-tick", type=float, default=0.0, metavar="SECONDS",
                        help="round the stamps to a logger clock of this tick (0.002: 10/12 ms "
                             "steps at 94 Hz); the samples stay where they were taken")
    args = parser.parse_args()
    if args.stamp_tick < 0:
        parser.error("--stamp-tick must be 0 (off) or a positive number of seconds")
    warnings.simplefilter("ignore")
    chosen = args.configurations or [configuration(c) for c in DEFAULT_CONFIGURATIONS]
    quality.METHODS = [m for m in quality.METHODS if m[0] == "robodyn default"]
    for conf in chosen:
        rows: list[list[str]] = []
        entry = quality.run_case(case(*conf, stamp_tick=args.stamp_tick), rows)
        m = entry["models"]
        print(f"{entry['data_set']}: textbook {m['textbook']['raw']:.4f} / "
              f"{m['textbook']['filtered']:.4f}, default {m['robodyn default']['raw']:.4f} / "
              f"{m['robodyn default']['filtered']:.4f} (raw / filtered), floor {entry['floor']:.4f}",
              flush=True)


if __name__ == "__main__":
    main()
