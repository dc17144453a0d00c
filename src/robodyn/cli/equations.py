"""``robodyn list``, ``show``, ``derive``, ``check``, ``codegen``, ``export`` and ``demo``: the
equations of motion of a description, the code and files made from them, and the PUMA 560 demo.

Thin: parse, call the public API, print. Bad input raises a
:class:`~robodyn.errors.RobodynError`, which :func:`robodyn.cli.main` turns into one line and
exit code 2.
"""

from __future__ import annotations

import argparse
import sys
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import robodyn as rd
from robodyn.cli.args import ROBOT_HELP as _ROBOT_HELP
from robodyn.cli.args import locked_joints, positive_int
from robodyn.text import err as _err
from robodyn.text import progress as _progress
from robodyn.text import steps as _steps
from robodyn.text import table as _table

if TYPE_CHECKING:
    import sympy as sp

# SymPy, the symbolic layer and the agreement report are imported inside the commands that use
# them, so that ``robodyn --help`` and the numeric commands (calibrate, identify, ...) start
# without them. The parser only needs these names; tests/calibration/test_startup.py checks them
# against robodyn.symbolic.eom.METHODS and robodyn.report.agreement.TOLERANCE.
METHODS: tuple[str, ...] = ("newton_euler", "lagrange", "kane")
TOLERANCE = 1e-9
_RENDERERS = ("text", "latex", "json")


# ----------------------------------------------------------------------------------------------
# small helpers
# ----------------------------------------------------------------------------------------------


def _fmt(expr: object) -> str:
    """Short text of a number or SymPy expression."""
    import sympy as sp

    if expr is None:
        return "-"
    return sp.sstr(sp.sympify(expr), full_prec=False)


def _vec(values: Sequence[object]) -> str:
    return "(" + ", ".join(_fmt(v) for v in values) + ")"


def _types(robot: rd.Robot) -> str:
    return "".join("P" if j.type == "prismatic" else "R" for j in robot.joints)


def _transform(mat: sp.MatrixBase) -> str:
    import sympy as sp

    if sp.Matrix(mat) == sp.eye(4):
        return "identity"
    return "; ".join(" ".join(_fmt(mat[r, c]) for c in range(4)) for r in range(3))


def _load(args: argparse.Namespace) -> rd.Robot:
    """The ROBOT argument, its tool frame at the ``--tool`` link of a URDF file when given."""
    return rd.load(args.robot, tool=args.tool, locked=locked_joints(args))


def _write(text: str, target: str | None) -> None:
    if target is None or target == "-":
        sys.stdout.write(text)
    else:
        Path(target).write_text(text, encoding="utf-8")
        _err(f"wrote {target}")


# ----------------------------------------------------------------------------------------------
# subcommands
# ----------------------------------------------------------------------------------------------


def _cmd_list(args: argparse.Namespace) -> int:
    rows = []
    for name in rd.builtin_names():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # plausibility notes belong to 'show', not here
            robot = rd.load(name)
        rows.append([name, robot.dof, _types(robot), ", ".join(robot.parameters) or "-"])
    print(_table(["name", "dof", "joints", "named parameters"], rows))
    return 0


def _cmd_show(args: argparse.Namespace) -> int:
    robot = _load(args)
    print(f"robot {robot.name}: {robot.dof} joints ({_types(robot)})")
    print(f"source: {robot.source}")
    print(f"description sha256: {robot.description_hash}\n")
    joint_rows = []
    for k, j in enumerate(robot.joints, 1):
        placement = " ".join(f"{key}={_fmt(v)}" for key, v in j.source_params.items()) or "-"
        limits = "-"
        if j.lower is not None or j.upper is not None:
            limits = f"[{_fmt(j.lower)}, {_fmt(j.upper)}]"
        fr = j.friction
        friction = "-" if fr.is_zero else (f"v={_fmt(fr.viscous)} c+={_fmt(fr.coulomb_positive)} "
                                          f"c-={_fmt(fr.coulomb_negative)} o={_fmt(fr.offset)}")
        joint_rows.append([k, j.name, j.type, j.convention, placement, limits,
                           _fmt(j.drive.gear_ratio), _fmt(j.drive.rotor_inertia), friction])
    print("joints")
    print(_table(["#", "name", "type", "convention", "placement", "limits", "gear ratio",
                  "rotor inertia", "friction (joint side)"], joint_rows))
    link_rows = []
    for k, link in enumerate(robot.links, 1):
        inertia = link.inertia
        link_rows.append([k, link.name, _fmt(link.mass), _vec(link.com),
                          _vec([inertia[0, 0], inertia[1, 1], inertia[2, 2]]),
                          _vec([inertia[0, 1], inertia[0, 2], inertia[1, 2]])])
    print("\nlinks (inertia about the centre of mass, link frame)")
    print(_table(["#", "name", "mass", "com", "ixx iyy izz", "ixy ixz iyz"], link_rows))
    print(f"\nbase: {_transform(robot.base)}")
    print(f"tool: {_transform(robot.tool)}")
    print(f"gravity: {_vec(robot.gravity)}")
    if robot.parameters:
        print("\nnamed parameters (defaults)")
        print(_table(["name", "default"], [[k, v] for k, v in robot.parameters.items()]))
    else:
        print("named parameters: none")
    return 0


def _cmd_derive(args: argparse.Namespace) -> int:
    from robodyn.symbolic.render import render_json, render_latex, render_text

    renderers = {"text": render_text, "latex": render_latex, "json": render_json}
    robot = _load(args)
    with _progress(f"deriving {args.method}"):
        eom = rd.derive(robot, args.method)
    with _progress(f"rendering {args.format}"):
        text = renderers[args.format](eom)
    _write(text, args.output)
    return 0


def _cmd_check(args: argparse.Namespace) -> int:
    from robodyn.report.agreement import (
        AGREEMENT_HEADERS,
        COUNT_HEADERS,
        agreement,
        agreement_rows,
        count_rows,
        derive_all,
        verdict,
    )

    robot = _load(args)
    print(f"{robot.name}: {robot.dof} joints ({_types(robot)}), {robot.source}")
    symbolic = robot.dof <= 2
    # steps: derive and evaluate each formulation, and simplify each pair when symbolic
    with _steps(2 * len(METHODS) + (3 if symbolic else 0), f"check {robot.name}"):
        eoms = derive_all(robot)
        results = agreement(eoms, args.samples, args.seed, symbolic=symbolic)
    print("\nderivation time and operations after common-subexpression elimination")
    print(_table(COUNT_HEADERS, count_rows(eoms)))
    print(f"\nagreement: max relative difference over {args.samples} random states "
          f"(tolerance {TOLERANCE:g})")
    print(_table(AGREEMENT_HEADERS, agreement_rows(results)))
    ok = all(r.ok for r in results)
    print("\nresult: " + verdict(results))
    return 0 if ok else 1


def _cmd_codegen(args: argparse.Namespace) -> int:
    from robodyn.codegen.emit import generate

    robot = _load(args)
    with _progress(f"generating {args.lang} for {robot.name}"):
        paths = generate(robot, args.lang, Path(args.output))
    for path in paths:
        print(path)
    return 0


def _cmd_export(args: argparse.Namespace) -> int:
    from robodyn.export.mjcf import to_mjcf
    from robodyn.export.urdf import to_urdf

    robot = _load(args)
    writer = {"urdf": to_urdf, "mjcf": to_mjcf}[args.format]
    text = writer(robot)
    _write(text, args.output)
    return 0


def _cmd_demo(args: argparse.Namespace) -> int:
    from robodyn.report.demo import run_demo

    return run_demo(args.output, args.samples, args.seed)


def _add_model_parsers(sub: argparse._SubParsersAction, fmt: type) -> None:
    """``list``, ``show``, ``derive`` and ``check``."""
    p = sub.add_parser("list", help="list the built-in robots", formatter_class=fmt,
                       description="List the built-in robots: name, number of joints, joint "
                                   "types (R revolute, P prismatic) and named parameters.",
                       epilog="example:\n  robodyn list")
    p.set_defaults(func=_cmd_list)

    p = sub.add_parser("show", help="show a robot's joints, links and parameters",
                       formatter_class=fmt,
                       description="Print a robot description as tables: joints (placement as "
                                   "given, limits, drive, friction), links (mass, centre of "
                                   "mass, inertia), base, tool, gravity and named parameters.",
                       epilog="examples:\n  robodyn show puma560\n  robodyn show my_arm.yaml")
    p.add_argument("robot", metavar="ROBOT", help=_ROBOT_HELP)
    p.set_defaults(func=_cmd_show)

    p = sub.add_parser("derive", help="derive and print the equations of motion",
                       formatter_class=fmt,
                       description="Derive M(q), C(q, qd), g(q) and tau and print them. Arms "
                                   "with up to 3 joints print in simplified textbook form; "
                                   "larger arms in recursive Newton-Euler form with M and g "
                                   "after common-subexpression elimination.",
                       epilog="examples:\n"
                              "  robodyn derive planar_2r\n"
                              "  robodyn derive trolley_pendulum --method kane --format latex "
                              "-o trolley.tex\n"
                              "  robodyn derive puma560 --format json -o puma560.json")
    p.add_argument("robot", metavar="ROBOT", help=_ROBOT_HELP)
    p.add_argument("--method", choices=METHODS, default="newton_euler",
                   help="formulation (default: %(default)s)")
    p.add_argument("--format", choices=_RENDERERS, default="text",
                   help="output format (default: %(default)s)")
    p.add_argument("-o", "--output", metavar="FILE", help="write to FILE instead of stdout")
    p.set_defaults(func=_cmd_derive)

    p = sub.add_parser("check", help="derive three ways and check that they agree",
                       formatter_class=fmt,
                       description="Derive the equations of motion by Newton-Euler, Lagrange "
                                   "and Kane; print the derivation times and operation counts, "
                                   "and the largest relative difference of M, g and tau between "
                                   "each pair on random states (symbolically too for arms with "
                                   f"up to 2 joints). Exit code 1 if they differ by more than "
                                   f"{TOLERANCE:g}.",
                       epilog="examples:\n  robodyn check planar_2r\n"
                              "  robodyn check puma560 --samples 50 --seed 1")
    p.add_argument("robot", metavar="ROBOT", help=_ROBOT_HELP)
    p.add_argument("--samples", type=positive_int, default=20, metavar="N",
                   help="number of random states (default: %(default)s)")
    p.add_argument("--seed", type=int, default=0, help="random seed (default: %(default)s)")
    p.set_defaults(func=_cmd_check)


def _add_output_parsers(sub: argparse._SubParsersAction, fmt: type) -> None:
    """``codegen`` and ``export``: source code and model files."""
    p = sub.add_parser("codegen", help="generate simulation code (C, Python, MATLAB, Fortran, ...)",
                       formatter_class=fmt,
                       description="Generate inverse dynamics, mass matrix, Coriolis, gravity, "
                                   "forward dynamics (Cholesky), forward kinematics, Jacobian, "
                                   "regressor and the ODE right-hand side as source files, with "
                                   "common subexpressions eliminated and the description's "
                                   "parameter values folded in.",
                       epilog="examples:\n  robodyn codegen puma560 --lang c -o gen/\n"
                              "  robodyn codegen my_arm.yaml --lang octave -o gen/matlab")
    p.add_argument("robot", metavar="ROBOT", help=_ROBOT_HELP)
    p.add_argument("--lang", required=True,
                   choices=("c", "python", "octave", "fortran", "julia", "latex", "mex"),
                   help="target language (c also writes a standalone simulator; mex writes the "
                        "MATLAB/Octave gateway and a Level-2 S-function)")
    p.add_argument("-o", "--output", required=True, metavar="DIR", help="output directory")
    p.set_defaults(func=_cmd_codegen)

    p = sub.add_parser("export", help="write a robot as URDF or MuJoCo MJCF",
                       formatter_class=fmt,
                       description="Export a description (parameters at their defaults) to URDF "
                                   "or MuJoCo MJCF. What a format cannot hold (e.g. asymmetric "
                                   "Coulomb friction, rotor inertia in URDF) is named in a "
                                   "warning.",
                       epilog="examples:\n  robodyn export puma560 --format urdf -o puma560.urdf\n"
                              "  robodyn export aa300 --format mjcf -o aa300.xml")
    p.add_argument("robot", metavar="ROBOT", help=_ROBOT_HELP)
    p.add_argument("--format", required=True, choices=("urdf", "mjcf"), help="output format")
    p.add_argument("-o", "--output", metavar="FILE", help="output file (default: stdout)")
    p.set_defaults(func=_cmd_export)


def _add_demo_parser(sub: argparse._SubParsersAction, fmt: type) -> None:
    """``demo``: the PUMA 560 pipeline and its report."""
    p = sub.add_parser("demo", help="PUMA 560 three ways: files, comparison and HTML report",
                       formatter_class=fmt,
                       description="Derive the PUMA 560 by the three formulations, check that "
                                   "they agree, and write to the output folder: the recursive "
                                   "Newton-Euler listing (puma560_newton_euler.txt), JSON per "
                                   "formulation, LaTeX documents (puma560_equations.tex, "
                                   "trolley_pendulum.tex), the efficiency comparison "
                                   "(comparison.md, comparison.csv) and report.html.",
                       epilog="example:\n  robodyn demo -o out   # then open out/report.html")
    p.add_argument("-o", "--output", metavar="DIR", default="out",
                   help="output folder, created if missing (default: %(default)s)")
    p.add_argument("--samples", type=positive_int, default=20, metavar="N",
                   help="number of random states for the agreement check (default: %(default)s)")
    p.add_argument("--seed", type=int, default=0, help="random seed (default: %(default)s)")
    p.set_defaults(func=_cmd_demo)


def register(sub: argparse._SubParsersAction, fmt: type) -> None:
    """Register ``list``, ``show``, ``derive``, ``check``, ``codegen``, ``export`` and ``demo``."""
    _add_model_parsers(sub, fmt)
    _add_output_parsers(sub, fmt)
    _add_demo_parser(sub, fmt)
