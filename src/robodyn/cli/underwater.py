"""``robodyn underwater ROBOT -o DIR``: the effect series of an underwater arm (thesis ch. 7).

Kept apart from :mod:`robodyn.cli` (which registers it); it parses, calls
:func:`robodyn.studies.underwater.effect_series` and :func:`robodyn.report.underwater.write_study`, and
prints the files written. A robot without hydro blocks is a
:class:`~robodyn.robot.errors.StudyError` (exit 2, one line).
"""

from __future__ import annotations

import argparse

import robodyn as rd
from robodyn.cli.args import BACKEND_HELP, BACKENDS, resolve_backend
from robodyn.studies.underwater_effects import (
    DEFAULT_CD_VALUES,
    DEFAULT_CURRENT,
    DEFAULT_CURRENT_SPEEDS,
    EFFECTS,
)

__all__ = ["register"]


def _seconds(text: str) -> float:
    value = float(text)
    if not value > 0:
        raise argparse.ArgumentTypeError(f"expected a positive number of seconds, got {text}")
    return value


def _assignment(text: str) -> tuple[str, float]:
    name, sep, value = text.partition("=")
    if not sep or not name.strip():
        raise argparse.ArgumentTypeError(f"expected NAME=VALUE, got {text!r}")
    try:
        return name.strip(), float(value)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: {value!r} is not a number") from None


def _cmd_underwater(args: argparse.Namespace) -> int:
    import numpy as np

    from robodyn.report.underwater import write_study
    from robodyn.studies.underwater import check_series_size, effect_series
    from robodyn.studies.underwater_model_error import OMITTED, model_error_study
    from robodyn.studies.underwater_sensitivity import sensitivity

    robot = rd.load(args.robot)
    # the sample count checked before anything is simulated, named by the options
    check_series_size(robot.dof, len(EFFECTS), args.move_time, args.hold_time, args.free_time,
                      args.dt, where="underwater",
                      names=("--move-time", "--hold-time", "--free-time", "--dt"),
                      model_error=0 if args.series_only else len(OMITTED))
    args.backend = resolve_backend(args.backend)
    params = dict(args.set or [])
    series = effect_series(
        robot, start=args.start, end=args.end, move_time=args.move_time,
        hold_time=args.hold_time, free_time=args.free_time, dt=args.dt, bandwidth=args.bandwidth,
        current=args.current, lift=args.lift, parameters=params,
        backend=args.backend, progress=True)
    for note in series.notes:
        print(note)
    sens = errors = None
    if not args.series_only:
        t = series.runs[0].tracked.t
        speed = float(np.linalg.norm(series.current))
        sens = sensitivity(robot, series.reference, t, free_time=args.free_time, dt=args.dt,
                           cd_values=args.cd_values, current_speeds=args.current_speeds,
                           direction=series.current / speed if speed > 0 else (1.0, 0.0, 0.0),
                           lift=args.lift, parameters=params, backend=args.backend,
                           progress=True)
        errors = model_error_study(robot, series.reference, float(t[-1]), dt=args.dt,
                                   bandwidth=args.bandwidth, current=series.current,
                                   lift=args.lift, parameters=params, backend=args.backend,
                                   progress=True)
    for path in write_study(series, args.output, sens, errors):
        print(path)
    return 0


def register(sub: argparse._SubParsersAction, fmt: type) -> None:
    """Register ``robodyn underwater`` on the main parser's subcommands."""
    p = sub.add_parser(
        "underwater", help="effect series of an underwater arm (buoyancy, added mass, drag, ...)",
        formatter_class=fmt,
        description="Simulate the robot in air and in water with the hydrodynamic effects switched "
                    f"on one at a time ({', '.join(EFFECTS)}): a quintic move tracked by the same "
                    "PD controller, and a free motion from rest. Writes effects.csv and effects.md "
                    "(peak/RMS torque per joint, tracking error, settling, difference against dry, "
                    "free-motion amplitude), figures, underwater_section.html and underwater.html "
                    "to DIR; then sweeps C_d and the current speed (sensitivity.csv/.png) and "
                    "tracks the move by computed torque with a model omitting each effect in turn "
                    "(model_error.csv/.png). The robot needs hydro blocks (see "
                    "docs/underwater.md).",
        epilog="example:\n  robodyn underwater underwater_2r -o out/underwater")
    p.add_argument("robot", metavar="ROBOT", help="built-in name or a .yaml description")
    p.add_argument("-o", "--output", required=True, metavar="DIR", help="output folder (created)")
    p.add_argument("--start", type=float, nargs="+", metavar="Q",
                   help="start of the move, one value per joint, rad or m (default: 0)")
    p.add_argument("--end", type=float, nargs="+", metavar="Q",
                   help="end of the move (default: start + 0.8 rad / 0.1 m per joint)")
    p.add_argument("--move-time", type=_seconds, default=2.0, metavar="S",
                   help="duration of the move, s (default: %(default)s); the samples of move, "
                        "hold and free time at --dt are bounded before simulating: about 3.1e5 "
                        "for a 2-joint arm with --series-only, 1e4 for the whole study "
                        "($ROBODYN_MAX_GRID_SAMPLES sets another bound)")
    p.add_argument("--hold-time", type=_seconds, default=1.0, metavar="S",
                   help="hold after the move, s (default: %(default)s)")
    p.add_argument("--free-time", type=_seconds, default=3.0, metavar="S",
                   help="duration of the free motion, s (default: %(default)s)")
    p.add_argument("--dt", type=_seconds, default=1e-3, metavar="S",
                   help="RK4 step, s (default: %(default)s)")
    p.add_argument("--bandwidth", type=_seconds, default=2.0, metavar="HZ",
                   help="PD closed-loop natural frequency, Hz (default: %(default)s)")
    p.add_argument("--current", type=float, nargs=3, metavar=("VX", "VY", "VZ"),
                   help="current of the last variant, base frame, m/s (default: the description's "
                        f"when not zero, else {' '.join(f'{c:g}' for c in DEFAULT_CURRENT)})")
    p.add_argument("--lift", type=float, metavar="CL",
                   help="lift coefficient of every wet link from the lift variant on "
                        "(default: the description's)")
    p.add_argument("--set", type=_assignment, action="append", metavar="NAME=VALUE",
                   help="value of a named parameter of the description (repeatable)")
    p.add_argument("--cd-values", type=float, nargs="+", metavar="CD",
                   default=list(DEFAULT_CD_VALUES),
                   help="drag coefficients of the sensitivity sweep (default: %(default)s)")
    p.add_argument("--current-speeds", type=float, nargs="+", metavar="V",
                   default=list(DEFAULT_CURRENT_SPEEDS),
                   help="current speeds of the sensitivity sweep, m/s, along the current's "
                        "direction (default: %(default)s)")
    p.add_argument("--series-only", action="store_true",
                   help="only the effect series (no sensitivity sweep, no model-error study)")
    p.add_argument("--backend", choices=BACKENDS, default="auto", help=BACKEND_HELP)
    p.set_defaults(func=_cmd_underwater)
