"""``robodyn sweep STUDY.yaml -o DIR``: run a study file on Dask, write the table, figures, report.

Kept apart from :mod:`robodyn.cli` (which registers it); it parses, calls the public study API
and prints. Bad study files are :class:`~robodyn.robot.errors.StudyError` (exit 2, one line);
Ctrl-C keeps the finished cases in ``results.partial.parquet``/``.csv`` (exit 130).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from robodyn.cli.args import positive_int

__all__ = ["register"]

#: ``--ship`` choices and ``sweep(ship=...)``.
_SHIP = {"auto": None, "always": True, "never": False}


def _cmd_sweep(args: argparse.Namespace) -> int:
    from robodyn.report.html import page
    from robodyn.report.study_report import study_figures, study_section
    from robodyn.studies.study_file import read_study
    from robodyn.studies.sweeps import SweepInterrupted, sweep, write_table

    study = read_study(args.study)
    out = Path(args.output)
    try:
        table = sweep(study.task, study.cases, scheduler=args.scheduler, workers=args.workers,
                      batch=args.batch or study.batch, seed=study.seed, progress=True,
                      timeout=args.timeout, ship=_SHIP[args.ship])
    except SweepInterrupted as stop:
        parquet, csv = write_table(stop.table, out, "results.partial")
        print(f"interrupted: {len(stop.table)} finished cases kept in {parquet} and {csv}",
              file=sys.stderr)
        return 130
    parquet, csv = write_table(table, out)
    figures = study_figures(table, study.varying, out, study.plot)
    title = f"Study {study.path.stem}"
    report = out / "study.html"
    report.write_text(page(title, study_section(table, title=title, varying=study.varying,
                                                figures=figures, source=str(study.path))),
                      encoding="utf-8")
    failed = int(table["error"].notna().sum())
    print(f"{len(table)} cases, {failed} failed")
    written = [parquet, csv, *figures, report]
    if failed:
        failures = out / "failures.csv"
        table.loc[table["error"].notna(), ["error"]].to_csv(failures)
        written.append(failures)
    for path in written:
        print(path)
    if len(table) and failed == len(table):
        first = str(table["error"].dropna().iloc[0]).splitlines()[0]
        print(f"robodyn: error: every case failed (the first: {first}); the table lists each "
              "case's message", file=sys.stderr)
        return 1
    return 0


def register(sub: argparse._SubParsersAction, fmt: type) -> None:
    """Register ``robodyn sweep`` on the main parser's subcommands."""
    p = sub.add_parser(
        "sweep", help="run a parameter study (study file) on Dask", formatter_class=fmt,
        description="Run the cases of a study file (robot, task, parameters and ranges, sampler, "
                    "seed; see docs/studies.md) on a Dask cluster: a local cluster with one worker "
                    "process per core unless --scheduler names a running one. Writes "
                    "results.parquet and results.csv (one row per case: parameters, results, "
                    "error message of a failed case), figures and study.html to DIR. The same file "
                    "and seed give the same table whatever the workers or batch size. Ctrl-C keeps "
                    "the finished cases in results.partial.parquet/.csv; failed cases are also "
                    "listed in failures.csv. The compiled models the cases use are built here and "
                    "sent to the workers with the tasks (--ship), so workers need no compiler. "
                    "Exit code 1 when every case failed.",
        epilog="examples:\n  robodyn sweep examples/studies/aa300_sizing.yaml -o out/sweep\n"
               "  robodyn sweep study.yaml --scheduler tcp://10.0.0.5:8786 -o out/sweep")
    p.add_argument("study", metavar="STUDY.yaml", help="study file")
    p.add_argument("-o", "--output", required=True, metavar="DIR", help="output folder (created)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="address of a running Dask scheduler, e.g. tcp://host:8786")
    p.add_argument("--workers", type=positive_int, metavar="N",
                   help="worker processes of the local cluster (default: the CPU cores)")
    p.add_argument("--batch", type=positive_int, metavar="N",
                   help="cases per Dask task (default: the study file's, else at least 256 tasks, "
                        "4 per worker thread on a bigger cluster)")
    p.add_argument("--ship", choices=tuple(_SHIP), default="auto",
                   help="send the compiled models the cases use to the workers with the tasks, so "
                        "that workers need no compiler: auto (up to 16 distinct models), always, "
                        "never (default: %(default)s)")
    p.add_argument("--timeout", type=float, default=10.0, metavar="S",
                   help="seconds to wait for --scheduler (default: %(default)s)")
    p.set_defaults(func=_cmd_sweep)
