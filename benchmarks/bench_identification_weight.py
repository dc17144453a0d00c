"""The Tikhonov weight of the default identification on every row of the quality table.

``rd.identify`` chooses the weight of its pull towards the description's parameters by held-out
time blocks of the identification data (``regularization="auto"``, docs/identification.md). This
benchmark shows what that choice costs or gains on data it did not see: on each row of
``bench_identification_quality.py`` (same data sets and splits, same error), the default beside
the same call with the weight fixed, and the textbook script. It answers whether another rule
for the weight would meet a target the default misses without losing a row elsewhere.

Run: ``python benchmarks/bench_identification_weight.py [--quick] [--only kuka,kinova,virtual]
[--results PATH | --no-results]``; merges entry ``identification_weight`` into the results file.
"""

from __future__ import annotations

import argparse
import sys
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).parent))
sys.path.insert(0, str(Path(__file__).parents[1]))
import bench_identification_quality as quality  # noqa: E402
import results  # noqa: E402
import textbook  # noqa: E402

import robodyn as rd  # noqa: E402

#: Fixed weights tried beside the default's choice (the default's grid spans 0 and 1e-10..1e2).
WEIGHTS = (0.0, 0.01, 0.1, 1.0, 10.0, 100.0)


def run_case(case: quality.Case, option: str = "regularization", values: tuple = WEIGHTS,
             label: str = "weight") -> dict[str, Any]:
    """Raw held-out error of the textbook, the default and each fixed value of ``option`` (a
    keyword of ``rd.identify``, printed as ``label``) on one case."""
    model = rd.compile_model(case.robot)
    pm = (textbook.pinocchio_model(case.urdf, case.robot.joint_names) if case.urdf is not None
          else textbook.pinocchio_model_of(case.robot))
    raw = {"textbook": quality._score(case, textbook.fit(pm, case.fit, case.target).predict)[0]}
    ident = rd.identify(case.robot, case.fit, target=case.target, model=model)
    raw["default"] = quality._score(case, ident.predict)[0]
    chosen = ident.choices.regularization if ident.choices is not None else None
    for v in values:
        fixed = rd.identify(case.robot, case.fit, target=case.target, model=model, **{option: v})
        raw[f"{label} {v:g}"] = quality._score(case, fixed.predict)[0]
    cells = "  ".join(f"{k} {v:.4f}" for k, v in raw.items())
    print(f"{case.name}: default weight {chosen}; {cells}", flush=True)
    return {"data_set": case.name, "default_weight": chosen,
            "raw": {k: float(f"{v:.5g}") for k, v in raw.items()}}


def main(script: str = "bench_identification_weight.py", entry: str = "identification_weight",
         option: str = "regularization", values: tuple = WEIGHTS, label: str = "weight",
         what: str = "the default rd.identify (weight chosen by held-out time blocks of the fit "
                     "data) beside the same call with regularization fixed, and the textbook",
         doc: str = __doc__, options: Callable[[argparse.ArgumentParser], None] | None = None,
         after: Callable[[argparse.Namespace, Path | None], None] | None = None) -> None:
    """Command line: every case of the chosen groups, then the entry ``entry`` (``option`` fixed
    at each of ``values`` beside the default); ``options`` adds a caller's own arguments and
    ``after(args, results_path)`` runs its own section last."""
    parser = argparse.ArgumentParser(description=doc.splitlines()[0])
    parser.add_argument("--only", default="", help="comma-separated: kuka, kinova, virtual")
    parser.add_argument("--quick", action="store_true",
                        help="only the quality benchmark's --quick rows (writes no results)")
    results.add_options(parser)
    if options is not None:
        options(parser)
    args = parser.parse_args()
    warnings.simplefilter("ignore")
    load_at_start = results.load_average()
    chosen = [g for g in (args.only.split(",") if args.only else ["kuka", "kinova", "virtual"]) if g]
    rows = [run_case(case, option, values, label) for case in quality._cases(chosen, args.quick)]
    path = results.target(args)
    if path is not None:
        command = " ".join(["python", f"benchmarks/{script}", *sys.argv[1:]])
        results.merge(path, entry, {
            "command": command, "load_average_at_start": load_at_start,
            "error": "raw ||pred - y|| / ||y|| pooled over the held-out samples and joints, as in "
                     "identification_quality",
            "what": what, "rows": rows})
        print(f"results: {path}")
    if after is not None:
        after(args, path)


if __name__ == "__main__":
    main()
