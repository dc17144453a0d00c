"""``robodyn`` command line: parse, call the public API, print.

Subcommands: ``list``, ``show``, ``derive``, ``check``, ``codegen``, ``export``, ``simulate``,
``calibrate``, ``iso9283``, ``identify``, ``validate`` and ``demo`` (``robodyn --help``);
one module per command group registers its commands (``register(subparsers, formatter)``):
:mod:`~robodyn.cli.equations` (list, show, derive, check, codegen, export, demo),
:mod:`~robodyn.cli.workflows` (simulate, calibrate, iso9283), :mod:`~robodyn.cli.identify`
(identify, validate), :mod:`~robodyn.cli.record`, :mod:`~robodyn.cli.excite` (excite,
testprog), :mod:`~robodyn.cli.cache`, :mod:`~robodyn.cli.sweep`, :mod:`~robodyn.cli.underwater`.
Exit codes: 0 success; 1 the formulations disagree (check, demo), the calibration did not
converge (calibrate), or an internal error (a bug: one line, the traceback in a log file); 2 bad
input (a :class:`~robodyn.errors.RobodynError`: unknown robot, invalid description, unreadable
data; or a file that cannot be read or written); 130 interrupted.
"""

from __future__ import annotations

import argparse
import os
import sys
import textwrap
import threading
import warnings
from collections.abc import Sequence

import robodyn as rd
from robodyn.cli import cache, equations, excite, identify, record, sweep, underwater, workflows
from robodyn.cli.args import lock
from robodyn.robot.errors import RobodynError
from robodyn.text import err as _err

# ----------------------------------------------------------------------------------------------
# argument parsing
# ----------------------------------------------------------------------------------------------


def _parser() -> argparse.ArgumentParser:
    fmt = argparse.RawDescriptionHelpFormatter
    parser = argparse.ArgumentParser(
        prog="robodyn", formatter_class=fmt,
        description="Equations of motion of serial robot manipulators: derive them by "
                    "Newton-Euler, Lagrange or Kane and check the formulations against each "
                    "other; generate simulation code, simulate with controllers, export to "
                    "URDF/MJCF; read measured recordings (CSV, ROS 2 bags), design excitation, "
                    "identify and validate the model against measurements; calibrate the "
                    "kinematics from measured end-effector positions; model arms under water; "
                    "run parameter studies on Dask.",
        epilog="examples:\n"
               "  robodyn list\n"
               "  robodyn show puma560\n"
               "  robodyn derive trolley_pendulum --method kane --format latex -o trolley.tex\n"
               "  robodyn check planar_2r --samples 50\n"
               "  robodyn codegen puma560 --lang c -o gen/\n"
               "  robodyn simulate puma560 --controller computed-torque --target 0.5 -o sim/\n"
               "  robodyn calibrate puma560 --data poses.csv -o calib/\n"
               "  robodyn demo -o out\n\n"
               "Run 'robodyn COMMAND --help' for the options of a command.\n\n"
               "exit codes: 0 success; 1 a check failed (see the command's help) or an internal\n"
               "error (a bug in robodyn: one line, and the traceback in a log file to report;\n"
               "ROBODYN_DEBUG=1 shows it instead); 2 bad input (description, data, options, a\n"
               "file that cannot be read or written); 130 interrupted.")
    parser.add_argument("--version", action="version", version=f"robodyn {rd.__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    # each command group registers itself: register(subparsers, formatter)
    for group in (equations, workflows, identify, record, excite, cache, sweep, underwater):
        group.register(sub, fmt)
    for command in ("show", "derive", "check", "codegen", "export", "simulate", "calibrate",
                    "identify", "validate"):
        sub.choices[command].add_argument(
            "--tool", metavar="LINK",
            help="URDF only: the link whose frame is the end effector, e.g. tool0 or flange "
                 "(default: the end of the fixed joints after the last moving joint, or the "
                 "last moving link when they branch)")
        sub.choices[command].add_argument(
            "--lock", metavar="JOINT=VALUE", type=lock, action="append",
            help="URDF only, repeatable: hold a moving joint still at this position (rad, or m "
                 "for a prismatic joint) and treat it as fixed, e.g. a gripper's fingers "
                 "(--lock finger_joint1=0.04; a <mimic> joint follows the joint it mimics); the "
                 "robot's joints, and the recordings' columns, are the others")
    for each in (parser, *sub.choices.values()):
        each.description = textwrap.fill(each.description or "", width=88)
    return parser


def _show_warning(message: Warning | str, category: type[Warning], filename: str, lineno: int,
                  file: object = None, line: str | None = None) -> None:
    """Warnings as one line each on stderr (no source line)."""
    _err(f"robodyn: warning: {message}")


def main(argv: Sequence[str] | None = None) -> int:
    """Run the ``robodyn`` command line.

    Parameters
    ----------
    argv : sequence of str, optional
        Arguments without the program name; ``sys.argv[1:]`` when None.

    Returns
    -------
    int
        Exit code: 0 success, 1 a check failed or an internal error, 2 bad input, 130
        interrupted.
    """
    args = _parser().parse_args(argv)
    with warnings.catch_warnings():
        warnings.simplefilter("default")
        warnings.showwarning = _show_warning
        try:
            return args.func(args)
        except (RobodynError, OSError) as exc:
            _err(f"robodyn: error: {' '.join(str(exc).split())}")
            return 2
        except KeyboardInterrupt:
            _err("robodyn: interrupted")
            return 130
        except Exception as exc:  # not bad input: a bug
            from robodyn.codegen.build import CompilerNotFoundError

            if isinstance(exc, CompilerNotFoundError):
                _err(f"robodyn: error: {' '.join(str(exc).split())} (commands with --backend "
                     "numpy run without one)")
                return 2
            if os.environ.get("ROBODYN_DEBUG"):
                raise
            _err(f"robodyn: internal error (a bug in robodyn, not in your input): "
                 f"{type(exc).__name__}: {' '.join(str(exc).split())[:300]}; please report it "
                 f"with the traceback in {_crash_log(exc, argv)}")
            return 1


def _crash_log(exc: BaseException, argv: Sequence[str] | None) -> str:
    """Write the traceback of an internal error to a new log file; its path (or a note)."""
    import tempfile
    import traceback

    text = (f"robodyn {rd.__version__}, python {sys.version.split()[0]}, {sys.platform}\n"
            f"command: robodyn {' '.join(sys.argv[1:] if argv is None else argv)}\n\n"
            + "".join(traceback.format_exception(exc)))
    try:
        fd, path = tempfile.mkstemp(prefix="robodyn-internal-error-", suffix=".log")
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
    except OSError:
        return "(no log: the temporary folder is not writable; rerun with ROBODYN_DEBUG=1)"
    return path


def run() -> None:
    """The ``robodyn`` console command: :func:`main`, then a quick exit.

    Tearing SymPy, SciPy and matplotlib down at interpreter exit takes 0.4 s or more, as long as
    some commands' whole work. Once the command has returned (its files written and closed),
    the standard streams are flushed and the process ends without that teardown, unless a
    thread or a child process is still running: then the normal exit cleans them up.
    """
    code = main()
    children = "multiprocessing" in sys.modules and sys.modules["multiprocessing"].active_children()
    if threading.active_count() > 1 or children:
        sys.exit(code)
    try:
        sys.stdout.flush()
        sys.stderr.flush()
    except (OSError, ValueError):  # a closed pipe or stream: the normal exit reports it
        sys.exit(code)
    os._exit(code)


if __name__ == "__main__":
    run()
