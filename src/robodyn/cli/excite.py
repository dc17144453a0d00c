"""``robodyn excite`` and ``robodyn testprog``: excitation design and the thesis' test programs.

Thin: parse, call :func:`robodyn.excitation` / :mod:`robodyn.studies.testprog`, write CSV, print.
Bad input raises ``ValueError`` (or a description error), which ``robodyn.cli.main`` turns into
one line and exit code 2.
"""

from __future__ import annotations

import argparse
import os
import warnings
from pathlib import Path
from typing import Any

import robodyn as rd
from robodyn.cli.args import ROBOT_HELP
from robodyn.robot.errors import InputError


def _output_file(text: str) -> Path:
    """The ``-o`` trajectory file, checked before the design runs (minutes): a folder is refused
    (exit 2), a missing parent folder is created, as for every command's ``-o``."""
    out = Path(text)
    if not text.strip() or out.is_dir() or text.endswith(("/", os.sep)):
        raise InputError(f"-o {text!r} names a folder, not a file; give the CSV file to write, "
                         f"e.g. {out / 'excitation.csv'}")
    if out.parent.exists() and not out.parent.is_dir():
        raise InputError(f"-o {text}: {out.parent} is a file, not a folder")
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(f"-o {text}: cannot create its folder {out.parent}: "
                         f"{exc.strerror or exc}") from None
    return out


def _cmd_excite(args: argparse.Namespace) -> int:
    from robodyn.studies.excitation import excitation_limits

    output = _output_file(args.output)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = rd.load(args.robot)
    limits = excitation_limits(robot, velocity=args.velocity, acceleration=args.acceleration)
    ex = rd.excitation(robot, harmonics=args.harmonics, base_frequency=args.frequency,
                       duration=args.duration, limits=limits, criterion=args.criterion,
                       starts=args.starts, seed=args.seed, dt=args.dt, gradient=args.gradient,
                       progress=True)
    path = ex.to_csv(output)
    print(f"{robot.name}: {ex.series.harmonics} harmonics at {ex.series.base_frequency:g} Hz, "
          f"{ex.duration:g} s, {len(ex.columns)} base columns")
    print(f"condition number {ex.condition_number:.1f} (starts: "
          f"{', '.join(f'{c:.1f}' for c in ex.history)}); {ex.elapsed:.1f} s")
    print(f"wrote {path} ({ex.t.size} rows)")
    return 0


def _check_testprog_options(args: argparse.Namespace) -> None:
    """The numeric options of ``testprog``, refused by their option names before anything runs."""
    from robodyn.studies.testprog import MAX_CYCLES, MIN_SPEED

    if not 0 < args.dt < float("inf"):
        raise InputError(f"--dt: the sample step must be a positive number of seconds, got {args.dt:g}")
    if args.kind == "jointwise":
        bad = [s for s in args.speeds if not MIN_SPEED <= s <= 1.0]
        if bad:
            raise InputError(f"--speeds: each must be a fraction in [{MIN_SPEED:g}, 1] of the velocity "
                             f"limit, got {', '.join(f'{s:g}' for s in bad)}")
        return
    if not 0 < args.size < float("inf"):
        raise InputError(f"--size: the cube edge must be a positive number of metres, got {args.size:g}")
    if not 1 <= args.cycles <= MAX_CYCLES:
        raise InputError(f"--cycles: must be an integer in [1, {MAX_CYCLES}] (ISO 9283 uses 30), "
                         f"got {args.cycles}")


def _cmd_testprog(args: argparse.Namespace) -> int:
    from robodyn.studies.testprog import jointwise

    _check_testprog_options(args)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = rd.load(args.robot)
    if args.kind == "jointwise":
        prog = jointwise(robot, speeds=args.speeds, dt=args.dt)
    else:
        prog = _iso_cube(robot, args)
    traj, segs = prog.to_csv(Path(args.output))
    moves = sum(s.kind == "move" for s in prog.segments)
    print(f"{robot.name}: {prog.name} program, {moves} moves, {prog.duration:.1f} s")
    print(f"wrote {traj} and {segs}")
    return 0


def _iso_cube(robot: rd.Robot, args: argparse.Namespace) -> Any:
    """The ISO 9283 cube program, ``--size`` named when a test point is out of reach
    (:class:`~robodyn.simulation.UnreachableError`, bad input: exit 2)."""
    from robodyn.simulation.ik import UnreachableError
    from robodyn.studies.testprog import iso_cube

    try:
        return iso_cube(robot, size=args.size, cycles=args.cycles, dt=args.dt)
    except UnreachableError as exc:
        raise InputError(f"--size {args.size:g}: {exc} (choose a smaller cube)") from None


def register(sub: argparse._SubParsersAction, fmt: type) -> None:
    """Register ``excite`` and ``testprog`` on the ``robodyn`` sub-parsers."""
    robot_help = ROBOT_HELP
    p = sub.add_parser("excite", help="design an optimal excitation trajectory (CSV a controller can play)",
                       formatter_class=fmt,
                       epilog="example:\n  robodyn excite puma560 -o traj.csv")
    p.add_argument("robot", metavar="ROBOT", help=robot_help)
    p.add_argument("-o", "--output", required=True, metavar="FILE.csv", help="trajectory CSV")
    p.add_argument("--harmonics", type=int, default=5, help="harmonics per joint")
    p.add_argument("--frequency", type=float, default=0.1, help="base frequency, Hz")
    p.add_argument("--duration", type=float, default=None,
                   help="s, whole periods (default one); duration / dt samples of 1 + 3 n values "
                        "are at most 3e7 values (1.36e6 samples of 7 joints; "
                        "$ROBODYN_MAX_GRID_SAMPLES sets another bound)")
    p.add_argument("--velocity", type=float, default=None, help="speed limit, rad/s (all joints)")
    p.add_argument("--acceleration", type=float, default=None, help="acceleration limit, rad/s^2")
    p.add_argument("--criterion", choices=("cond", "logdet"), default="cond")
    p.add_argument("--gradient", choices=("finite_difference", "analytic"),
                   default="finite_difference",
                   help="joint-state part of the gradient: central differences of the regressor, "
                        "or compiled analytic regressor derivatives (faster per iteration; the "
                        "first design for a robot compiles them, minutes for six joints) "
                        "(default: %(default)s)")
    p.add_argument("--starts", type=int, default=6, help="optimiser starts")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--dt", type=float, default=1e-3,
                   help="sample step of the CSV, s (bounded with --duration)")
    p.set_defaults(func=_cmd_excite)

    p = sub.add_parser("testprog", help="thesis test programs: one joint at a time, ISO 9283 cube",
                       formatter_class=fmt,
                       epilog="examples:\n  robodyn testprog puma560 --kind jointwise -o prog/\n"
                              "  robodyn testprog kinova_gen3 --kind iso-cube --size 0.4 -o cube/")
    p.add_argument("robot", metavar="ROBOT", help=robot_help)
    p.add_argument("--kind", required=True, choices=("jointwise", "iso-cube"))
    p.add_argument("-o", "--output", required=True, metavar="DIR", help="output directory")
    p.add_argument("--speeds", type=float, nargs="+", default=[0.5, 1.0],
                   help="jointwise: speed fractions")
    p.add_argument("--size", type=float, default=0.5, help="iso-cube: cube edge, m")
    p.add_argument("--cycles", type=int, default=1,
                   help="iso-cube: P1..P5 cycles; the program's samples (1 + 3 n values each) are "
                        "at most 3e7 values, e.g. about 108 cycles of puma560 at 1 ms "
                        "($ROBODYN_MAX_GRID_SAMPLES sets another bound)")
    p.add_argument("--dt", type=float, default=1e-3, help="sample step, s (bounded as for --cycles)")
    p.set_defaults(func=_cmd_testprog)
