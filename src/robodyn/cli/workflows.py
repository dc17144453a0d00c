"""``robodyn simulate``, ``robodyn calibrate`` and ``robodyn iso9283``: parsers and commands.

Kept apart from :mod:`robodyn.cli` (which registers them) so that each file stays short; like the
rest of the command line, these only parse, call the public API and print.
"""

from __future__ import annotations

import argparse
import csv
import math
from collections.abc import Callable
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

import robodyn as rd
from robodyn.cli.args import BACKEND_HELP, BACKENDS, ROBOT_HELP, floats, locked_joints, resolve_backend
from robodyn.output_names import check_stem, output_path
from robodyn.robot.errors import InputError
from robodyn.text import err, progress, table

__all__ = ["register"]

# The parsers' choices and defaults, kept here so that building the parser (every command, and
# --help) imports neither the simulation nor the calibration package; test_startup.py in
# tests/calibration checks them against robodyn.simulation.simulation and robodyn.calibration.models.
FIXED_STEP: tuple[str, ...] = ("rk4", "semi_implicit")
ADAPTIVE: tuple[str, ...] = ("RK45", "RK23", "DOP853", "Radau", "BDF", "LSODA")
MAX_SAMPLES = 1_000_000
MODELS: tuple[str, ...] = ("dh", "hayati", "s-model", "poe")
DEFLECTIONS: tuple[str, ...] = ("linear", "exact")


def _vector(value: np.ndarray | None, n: int, option: str, default: float = 0.0) -> np.ndarray:
    if value is None:
        return np.full(n, default)
    if value.size == 1:
        return np.full(n, float(value[0]))
    if value.size != n:
        raise InputError(f"{option}: expected 1 or {n} comma-separated values (one per joint), "
                         f"got {value.size}")
    return value


# ----------------------------------------------------------------------------------------------
# simulate
# ----------------------------------------------------------------------------------------------


def _controller(args: argparse.Namespace, model: rd.Model, q0: np.ndarray):
    """The controller and the planned reference (None for a passive run)."""
    from robodyn.simulation.controllers import PD, PID, ComputedTorque, GravityCompensation
    from robodyn.simulation.trajectory import quintic

    n = model.dof
    if args.controller == "none":
        if args.target is not None:
            raise InputError("--target needs a controller (--controller pd|pid|gravity|computed-torque)")
        return None, None
    target = _vector(args.target, n, "--target") if args.target is not None else q0
    move = args.move_time if args.move_time is not None else 0.5 * args.duration
    if not 0 < move <= args.duration:
        raise InputError(f"--move-time: must be in (0, duration = {args.duration:g}] s, got {move:g}")
    plan = quintic(q0, target, move, dt=args.dt)
    # default gains: a stiff error loop for computed torque (1/s^2, 1/s), moderate PD otherwise
    ct = args.controller == "computed-torque"
    kp = _vector(args.kp, n, "--kp", 400.0 if ct else 100.0)
    kd = _vector(args.kd, n, "--kd", 40.0 if ct else 20.0)
    if args.controller == "computed-torque":
        return ComputedTorque(plan, kp=kp, kd=kd), plan
    if args.controller == "pd":
        return PD(kp, kd, plan), plan
    if args.controller == "pid":
        return PID(kp, _vector(args.ki, n, "--ki"), kd, plan), plan
    return GravityCompensation(kp, kd, plan), plan


#: Characters per value in the CSV (``repr`` of a double with its separator), for the estimate.
_CSV_VALUE_CHARS = 22


def _check_size(args: argparse.Namespace, n: int) -> None:
    """Refuse, before anything runs, an output above ``--max-samples`` (the CSV size named)."""
    if not (math.isfinite(args.duration) and math.isfinite(args.dt) and args.dt > 0
            and args.duration > 0):
        raise InputError(f"--duration and --dt must be positive finite numbers, got "
                         f"{args.duration:g} and {args.dt:g}")
    if args.decimate < 1:
        raise InputError(f"--decimate: must be a positive integer, got {args.decimate}")
    samples = math.floor(args.duration / args.dt / args.decimate) + 1
    if args.max_samples and samples > args.max_samples:
        size = samples * (4 * n + 2) * _CSV_VALUE_CHARS
        k = math.ceil(args.duration / args.dt / max(args.max_samples - 1, 1))
        raise InputError(
            f"--duration {args.duration:g} s at --dt {args.dt:g} s writes {samples:,} rows (a CSV "
            f"of about {size / 1e6:,.0f} MB), above --max-samples {args.max_samples:,}; keep "
            f"every k-th step with --decimate k (k >= {k:,}), shorten the run, or raise "
            "--max-samples (0: no limit)")


def _cmd_simulate(args: argparse.Namespace) -> int:
    from robodyn.codegen.build import CompilerNotFoundError
    from robodyn.measure.csv_io import write_csv
    from robodyn.measure.recording import Recording
    from robodyn.studies.simulation_plots import trajectory_figure

    robot = rd.load(args.robot, tool=args.tool, locked=locked_joints(args))
    n = robot.dof
    csv_path = output_path(args.output, robot.name, "_simulation.csv", what="robot name")
    q0 = _vector(args.q0, n, "--q0")
    qd0 = _vector(args.qd0, n, "--qd0")
    _check_size(args, n)
    out = Path(args.output)
    out.mkdir(parents=True, exist_ok=True)
    args.backend = resolve_backend(args.backend)
    with progress(f"compiling {robot.name} ({args.backend} backend)"):
        try:
            model = rd.compile_model(robot, backend=args.backend)
        except CompilerNotFoundError as exc:
            raise InputError(f"{exc}; rerun with --backend numpy (no compiler needed)") from None
    controller, plan = _controller(args, model, q0)
    limit = _vector(args.tau_limit, n, "--tau-limit") if args.tau_limit is not None else None
    with progress(f"simulating {args.duration:g} s at dt = {args.dt:g} s ({args.method})"):
        try:
            sim = rd.simulate(model, q0, qd0, args.duration, args.dt, method=args.method,
                              controller=controller, tau_limit=limit, control=args.control,
                              decimate=args.decimate, max_samples=args.max_samples or None,
                              substeps=args.substeps)
        except FloatingPointError as exc:
            # the controller's or the integrator's message, as one line and exit 2
            raise InputError(str(exc)) from None
    names = robot.joint_names
    # the run in the recording layout (reads back with robodyn record / rd.read_recording), the
    # energy beside it
    write_csv(Recording(t=sim.t, q=sim.q, qd=sim.qd, qdd=sim.qdd, tau=sim.tau, joint_names=names,
                        source=csv_path.name), csv_path)
    energy_path = output_path(out, robot.name, "_energy.csv", what="robot name")
    with energy_path.open("w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow(["t", "energy"])
        w.writerows([repr(float(t)), repr(float(e))] for t, e in zip(sim.t, sim.energy, strict=True))
    with progress("plotting"):
        fig = trajectory_figure(sim, names, output_path(out, robot.name, "_simulation.png"), plan)
    rows = [[j, f"{sim.q[-1, k]:.6g}", f"{np.abs(sim.qd[:, k]).max():.4g}",
             f"{np.abs(sim.tau[:, k]).max():.4g}"] for k, j in enumerate(names)]
    headers = ["joint", "final q", "max |qd|", "max |tau|"]
    if plan is not None:
        err_track = np.abs(sim.q - plan.at(sim.t)[0]).max(axis=0)
        headers.append("max |q - q_ref|")
        for row, e in zip(rows, err_track, strict=True):
            row.append(f"{e:.3g}")
    print(table(headers, rows))
    print(f"{len(sim.t) - 1} steps, {sim.evaluations} right-hand-side evaluations; energy "
          f"{sim.energy[0]:.6g} J -> {sim.energy[-1]:.6g} J"
          + (f" (relative drift {sim.energy_drift:.3g})" if controller is None else ""))
    print(f"wrote {csv_path}, {energy_path} and {fig}")
    return 0


# ----------------------------------------------------------------------------------------------
# calibrate
# ----------------------------------------------------------------------------------------------


def _payload(values: np.ndarray | None) -> tuple[float, np.ndarray] | None:
    """``--payload KG,X,Y,Z`` as (mass, centre of mass)."""
    if values is None:
        return None
    if values.size != 4:
        raise InputError(f"--payload: expected 4 numbers (mass in kg, then x, y, z of the centre of "
                         f"mass in the tool frame in m), got {values.size}")
    return float(values[0]), values[1:]


class CalibrationInputs(NamedTuple):
    """What ``robodyn calibrate`` reads before its solve (:func:`calibration_inputs`)."""

    robot: Any  # RobotNumbers
    stem: str
    jmap: Any  # JointMap or None
    data: Any  # CalibrationData
    units: dict[str, str]
    si: Callable[[Any], tuple[np.ndarray, np.ndarray]]  # a data set's q, points in rad and m
    circle: list[tuple[np.ndarray, np.ndarray]] | None
    sigma: Any  # float or array, the data's length unit
    sigma_rot: float  # the data's angle unit


def calibration_inputs(args: argparse.Namespace) -> CalibrationInputs:
    """What ``robodyn calibrate`` reads before its solve: the robot's numbers (from the cache
    where its description was loaded before: no SymPy), the output stem, the joint map, the
    data, the circle-point files, and sigma and sigma_rot in the data's units.
    ``benchmarks/bench_calibration.py`` times this function in a fresh process."""
    from robodyn.calibration.data_checks import ANGLE_UNITS, LENGTH_UNITS, convert_units
    from robodyn.calibration.io import read_calibration_csv, read_joint_map
    from robodyn.robot.numbers_cache import load_numbers

    robot = load_numbers(args.robot, tool=args.tool, locked=locked_joints(args))
    stem = check_stem(args.stem) if args.stem is not None else \
        check_stem(f"{robot.name}_calibrated", what="robot name")
    jmap = read_joint_map(args.joint_map, robot) if args.joint_map else None
    if jmap is not None and jmap.si and args.angle_unit != "rad":
        raise InputError(f"--angle-unit {args.angle_unit}: the joint map {jmap.source} is a recording "
                         "spec, whose position.unit already gives the joints' unit; leave "
                         "--angle-unit at rad")
    data = read_calibration_csv(args.data, robot, targets=args.targets, joint_map=jmap)
    units = {"length_unit": args.length_unit, "angle_unit": args.angle_unit}

    def si(d):  # q and points of a data set in rad and m
        q, pts, _, _ = convert_units(robot, d.q, d.points, 1.0, 1.0, **units)
        return q, pts

    circle = None
    if args.circle:
        if len(args.circle) != robot.dof:
            raise InputError(f"--circle: give one file per joint in chain order ({robot.dof} for "
                             f"{robot.name}), got {len(args.circle)}")
        circle = [si(read_calibration_csv(path, robot, joint_map=jmap)) for path in args.circle]
    # sigma in the data's length unit (the option is in mm)
    sigma = data.sigma if data.sigma is not None else args.sigma * 1e-3 / LENGTH_UNITS[args.length_unit]
    # sigma_rot in the angle unit (the option is in mrad)
    sigma_rot = args.sigma_rot * 1e-3 / ANGLE_UNITS[args.angle_unit]
    return CalibrationInputs(robot, stem, jmap, data, units, si, circle, sigma, sigma_rot)


def _cmd_calibrate(args: argparse.Namespace) -> int:
    from robodyn.calibration.io import write_calibration

    robot, stem, jmap, data, units, si, circle, sigma, sigma_rot = calibration_inputs(args)
    with progress(f"calibrating {robot.name} from {len(data.q)} poses ({args.model} model)"):
        cal = rd.calibrate(robot, data.q, data.points, args.model, sigma=sigma, loss=args.loss,
                           initial="circle-point" if circle else "nominal", circle_data=circle,
                           orientations=data.orientations, sigma_rot=sigma_rot,
                           nongeometric=tuple(args.nongeometric or ()),
                           payload=_payload(args.payload), identify_payload=args.identify_payload,
                           deflection=args.deflection, **units)
    held = _held_out(args, robot, cal, jmap, si) if args.validate else None
    paths = write_calibration(cal, args.output, stem=stem)
    check = alone = None
    if args.nongeometric:
        poses = (Path(args.validate).name, held["q"], held["points"]) if held else \
            (Path(args.data).name, *si(data))
        check, alone = _terms_check(args, robot, cal, data, sigma, units, poses, paths, stem)
    if held is not None:
        _add_to_report(paths["json"], {"validation": held["entry"]})
    if not args.no_report:
        from robodyn.report.calibration_report import calibration_html  # matplotlib: after the solve

        paths["html"] = calibration_html(cal, output_path(args.output, stem, "_report.html"),
                                         source=str(args.data),
                                         validation=held["residuals"] if held else None)
    print(cal.summary())
    if check is not None and alone is not None:
        _print_terms(check, alone, paths["yaml"].name, stem)
    for line in held["lines"] if held else ():
        print(line)
    print()
    for kind, path in paths.items():
        if path is not None:
            print(f"wrote {kind:<9} {path}")
    if not cal.converged:
        err("robodyn: warning: the least-squares solver did not converge")
        return 1
    return 0


def _held_out(args: argparse.Namespace, robot: rd.Robot, cal: Any, jmap: Any,
              si: Callable[[Any], tuple[np.ndarray, np.ndarray]]) -> dict[str, Any]:
    """``--validate``: the held-out poses (q, points in rad and m), their statistics after and
    before (the nominal kinematics placed, first target), the JSON entry, the report's residuals
    and the lines to print."""
    from robodyn.calibration.frames import robot_positions
    from robodyn.calibration.held_out import validate, validate_orientation
    from robodyn.calibration.io import read_calibration_csv
    from robodyn.calibration.result import ErrorStats

    data = read_calibration_csv(args.validate, robot, targets=args.targets, joint_map=jmap)
    q, pts = si(data)
    stats = validate(cal, q, pts)
    rot_stats = None
    if data.orientations is not None and cal.model.orientation:
        rot_stats = validate_orientation(cal, q, data.orientations)
    first = pts if pts.ndim == 2 else pts[:, 0]
    before = ErrorStats.from_residuals(first - robot_positions(cal.before_robot, q))
    entry = {"file": str(args.validate), "before_m": before.__dict__, "before_targets": "first",
             "after_m": stats.__dict__}
    lines = [f"\nheld-out ({args.validate}), after calibration: {stats.text()}",
             f"held-out ({args.validate}), before (nominal, placed): {before.text()}"
             + (" (first target)" if cal.targets_axis else "")]
    if rot_stats is not None:
        entry["orientation_after_rad"] = rot_stats.__dict__
        lines.append(f"held-out ({args.validate}), orientation after calibration: "
                     f"{rot_stats.angle_text()}")
    residuals = (Path(args.validate).name, (pts - cal.predict(q)).reshape(-1, 3))
    return {"q": q, "points": pts, "entry": entry, "residuals": residuals, "lines": lines}


def _terms_check(args: argparse.Namespace, robot: rd.Robot, cal: Any, data: Any, sigma: Any,
                 units: dict[str, str], poses: tuple[str, Any, Any], paths: dict[str, Any],
                 stem: str) -> tuple[Any, tuple[str, float, float, float]]:
    """The non-geometric terms cross-validated over the poses, and the written description's own
    figure on ``poses`` (name, q rad, points m), stated in its files and the JSON report."""
    from robodyn.calibration.term_check import description_alone, terms_cross_validation

    with progress(f"cross-validating the non-geometric terms over {len(data.q)} poses"):
        check = terms_cross_validation(
            rd.calibrate, robot, data.q, data.points, tuple(args.nongeometric), model=args.model,
            sigma=sigma, loss=args.loss, payload=_payload(args.payload),
            deflection=args.deflection, **units)
    alone = (poses[0], *description_alone(cal, poses[1], poses[2]))
    _state_alone(paths, alone, stem)
    _add_to_report(paths["json"], {
        "terms_cross_validation_m": {" + ".join(("geometry",) + t): r
                                     for t, r in zip(check.term_sets, check.rms, strict=True)},
        "description_alone_m": {"poses": alone[0], "alone_rms": alone[1],
                                "urdf_geometry_only_rms": alone[2], "with_terms_rms": alone[3]}})
    return check, alone


def _add_to_report(path: Path, entries: dict[str, Any]) -> None:
    """Add top-level ``entries`` to the calibration's JSON report at ``path``."""
    import json

    report = json.loads(path.read_text(encoding="utf-8"))
    report.update(entries)
    path.write_text(json.dumps(report, indent=1) + "\n", encoding="utf-8")


def _print_terms(check: Any, alone: tuple[str, float, float, float], yaml_name: str, stem: str) -> None:
    """The terms' cross-validation, a warning per family that overfits, and what the written
    files predict alone (:mod:`robodyn.calibration.term_check`)."""
    print(f"\n{check.text()}")
    for family in check.overfitting:
        err(f"robodyn: warning: adding '{family}' made the held-out error worse "
            "(cross-validation over poses): it fits these poses, not the arm; consider "
            "leaving it out")
    err(f"robodyn: note: {yaml_name} carries the non-geometric terms as joint-reading corrections: "
        f"loaded alone it predicts {alone[1] * 1e3:.4f} mm RMS on {alone[0]} (cal.predict: "
        f"{alone[3] * 1e3:.4f} mm); {stem}.urdf cannot hold them and predicts "
        f"{alone[2] * 1e3:.4f} mm")


def _state_alone(paths: dict[str, Any], alone: tuple[str, float, float, float], stem: str) -> None:
    """Say in the written description's header (YAML and URDF) what it predicts alone."""
    lines = {
        "yaml": (f"carries the non-geometric terms as joint-reading corrections (block "
                 f"'corrections'): alone it predicts {alone[1] * 1e3:.4f} mm RMS on {alone[0]} "
                 f"(cal.predict: {alone[3] * 1e3:.4f} mm)"),
        "urdf": (f"geometry estimated together with non-geometric terms that URDF cannot hold "
                 f"(they are in {stem}.yaml): alone this file predicts {alone[2] * 1e3:.4f} mm RMS "
                 f"on {alone[0]} (with them: {alone[1] * 1e3:.4f} mm)"),
    }
    yaml_path = paths.get("yaml")
    if yaml_path is not None:
        yaml_path.write_text(f"# {lines['yaml']}\n" + yaml_path.read_text(encoding="utf-8"),
                             encoding="utf-8")
    urdf = paths.get("urdf")
    if urdf is not None:
        text = urdf.read_text(encoding="utf-8")
        head, sep, rest = text.partition("?>")
        comment = "\n<!-- " + lines["urdf"].replace("--", "- -") + " -->"
        urdf.write_text(head + sep + comment + rest if sep else f"<!-- {lines['urdf']} -->\n" + text,
                        encoding="utf-8")


# ----------------------------------------------------------------------------------------------
# iso9283
# ----------------------------------------------------------------------------------------------


def _cmd_iso9283(args: argparse.Namespace) -> int:
    from robodyn.calibration.iso9283 import overshoot_from_csv, pose_characteristics_from_csv

    if args.data is None and args.approach is None:
        raise InputError("give a CSV of repeated poses (DATA) and/or --approach FILE.csv")
    if args.data is not None:
        pc = pose_characteristics_from_csv(args.data)
        print(f"ISO 9283 pose accuracy and repeatability, {args.data} ({pc.cycles} cycles)")
        print(pc.text())
    if args.approach is not None:
        attained = _vector(args.attained, 3, "--attained") if args.attained is not None else None
        ov = overshoot_from_csv(args.approach, band=args.band * 1e-3, attained=attained)
        stab = (f"{ov.stabilisation_time:.4g} s" if not math.isnan(ov.stabilisation_time)
                else "not stabilised within the record")
        over = (f"{ov.overshoot * 1e3:.4f} mm" if not math.isnan(ov.overshoot)
                else "never within the band")
        print(f"\nISO 9283 overshoot and stabilisation, {args.approach} (band {args.band:g} mm):")
        print(f"  attained position   {', '.join(f'{v:.6f}' for v in ov.attained)} m")
        print(f"  position overshoot  {over}")
        print(f"  stabilisation time  {stab}")
    return 0


# ----------------------------------------------------------------------------------------------
# parsers
# ----------------------------------------------------------------------------------------------


def register(sub: argparse._SubParsersAction, fmt: type) -> None:
    """Register ``simulate``, ``calibrate`` and ``iso9283`` on the ``robodyn`` sub-parsers."""
    robot_help = ROBOT_HELP
    _simulate_parser(sub, fmt, robot_help)
    _calibrate_parser(sub, fmt, robot_help)
    _iso9283_parser(sub, fmt)


def _simulate_parser(sub: argparse._SubParsersAction, fmt: type, robot_help: str) -> None:
    p = sub.add_parser(
        "simulate", help="simulate a robot (passive or under a controller), CSV and plots",
        formatter_class=fmt,
        description="Compile the robot's dynamics and simulate it from (q0, qd0): passive, or "
                    "moving to --target along a quintic path under PD, PID, PD with gravity "
                    "compensation, or computed torque. Writes ROBOT_simulation.csv (t, q, qd, qdd, "
                    "tau, energy) and ROBOT_simulation.png (positions with the reference, "
                    "velocities, torques, energy) into the output folder.",
        epilog="examples:\n"
               "  robodyn simulate trolley_double_pendulum --q0 0,0.3,-0.2 --duration 5 -o sim/\n"
               "  robodyn simulate puma560 --controller computed-torque "
               "--target 0.8,-0.6,0.9,0.5,-0.7,1 --duration 3 -o sim/\n"
               "  robodyn simulate planar_2r --method DOP853 --q0 1,0 -o sim/")
    p.add_argument("robot", metavar="ROBOT", help=robot_help)
    p.add_argument("--q0", type=floats, metavar="Q", help="initial positions, rad/m (default 0)")
    p.add_argument("--qd0", type=floats, metavar="QD", help="initial velocities (default 0)")
    p.add_argument("--duration", type=float, default=2.0, metavar="S",
                   help="simulated time, s (default: %(default)s)")
    p.add_argument("--dt", type=float, default=1e-3, metavar="S",
                   help="step and output interval, s (default: %(default)s)")
    p.add_argument("--method", choices=FIXED_STEP + ADAPTIVE, default="rk4",
                   help="integrator; rk4 and semi_implicit run inside the generated C "
                        "(default: %(default)s)")
    p.add_argument("--controller", default="none",
                   choices=("none", "pd", "pid", "gravity", "computed-torque"),
                   help="control law (default: %(default)s, i.e. no actuator torque)")
    p.add_argument("--target", type=floats, metavar="Q",
                   help="final joint positions of a quintic move from q0 (default: hold q0)")
    p.add_argument("--move-time", type=float, metavar="S",
                   help="duration of the move, s (default: half of --duration)")
    p.add_argument("--kp", type=floats, metavar="K",
                   help="stiffness per joint (default 100; 400 1/s^2 for computed torque)")
    p.add_argument("--kd", type=floats, metavar="K",
                   help="damping per joint (default 20; 40 1/s for computed torque)")
    p.add_argument("--ki", type=floats, metavar="K", help="integral gain (pid; default 0)")
    p.add_argument("--control", choices=("sampled", "continuous"), default="sampled",
                   help="fixed-step methods: evaluate the law once per step and hold it (a "
                        "digital controller at 1/dt), or at every RK4 stage (continuous-time) "
                        "(default: %(default)s)")
    p.add_argument("--tau-limit", type=floats, metavar="T", help="actuator limits, N m or N")
    p.add_argument("--backend", choices=BACKENDS, default="auto", help=BACKEND_HELP)
    p.add_argument("--substeps", type=int, default=1, metavar="K",
                   help="sampled control: hold the law over K integration steps of dt/K (for a "
                        "plant stiffer than the control rate) (default: %(default)s)")
    p.add_argument("--decimate", type=int, default=1, metavar="K",
                   help="keep every K-th step in the CSV and plots (the integration still uses "
                        "--dt) (default: %(default)s)")
    p.add_argument("--max-samples", type=int, default=MAX_SAMPLES, metavar="N",
                   help="refuse a run that would write more than N rows (checked before it "
                        "starts; 0: no limit) (default: %(default)s)")
    p.add_argument("-o", "--output", metavar="DIR", default="sim",
                   help="output folder (default: %(default)s)")
    p.set_defaults(func=_cmd_simulate)


def _calibrate_parser(sub: argparse._SubParsersAction, fmt: type, robot_help: str) -> None:
    p = sub.add_parser(
        "calibrate", help="kinematic calibration from measured end-effector positions",
        formatter_class=fmt,
        description="Kinematic calibration (Stone's method): fit an error model to measured "
                    "target positions, with the instrument-to-base transform and the target "
                    "offset on the last link estimated too. DATA is a CSV with one column per "
                    "joint (named as in 'robodyn show ROBOT'), x, y, z in metres, and optionally "
                    "qw, qx, qy, qz (measured orientation) and sigma (m). Writes the calibrated "
                    "description (YAML and URDF, both readable by robodyn) and a report (text, "
                    "JSON, residuals CSV, HTML with plots). Exit code 1 if the solver did not "
                    "converge.",
        epilog="examples:\n"
               "  robodyn calibrate puma560 --data poses.csv -o calib/\n"
               "  robodyn calibrate puma560 --data poses.csv --model hayati --validate held.csv "
               "-o calib/\n"
               "  robodyn calibrate puma560 --data poses.csv --circle j1.csv --circle j2.csv ... "
               "-o calib/")
    p.add_argument("robot", metavar="ROBOT", help=robot_help)
    p.add_argument("--data", required=True, metavar="FILE.csv", help="measured poses")
    p.add_argument("--model", choices=tuple(MODELS), default="s-model",
                   help="error model (default: %(default)s)")
    p.add_argument("--sigma", type=float, default=0.05, metavar="MM",
                   help="measurement standard uncertainty per coordinate, mm, when the CSV has "
                        "no sigma column (default: %(default)s)")
    p.add_argument("--loss", choices=("linear", "huber", "soft_l1", "cauchy", "arctan"),
                   default="linear", help="robust loss (default: %(default)s)")
    p.add_argument("--circle", action="append", metavar="FILE.csv",
                   help="circle-point data, one file per joint in chain order (only that joint "
                        "moves): start from Stone's circle-point estimate instead of the nominal")
    p.add_argument("--validate", metavar="FILE.csv", help="held-out poses to report errors on")
    p.add_argument("--length-unit", choices=("m", "mm"), default="m",
                   help="unit of x, y, z (and a sigma column) in the CSV files (default: %(default)s)")
    p.add_argument("--angle-unit", choices=("rad", "deg"), default="rad",
                   help="unit of the revolute joints' columns (default: %(default)s)")
    p.add_argument("--joint-map", metavar="FILE.yaml",
                   help="controller columns to model joints: the arm's recording spec (its "
                        "joints, position and couplings; docs/recording-spec.md), or per joint "
                        "{column, sign, offset, coupling: {other column: factor}} "
                        "(docs/calibration.md)")
    p.add_argument("--targets", type=int, metavar="K",
                   help="targets per pose (x, y, z, x2, y2, z2, ...); checked against the columns")
    p.add_argument("--sigma-rot", type=float, default=0.1, metavar="MRAD",
                   help="standard uncertainty of a measured orientation (qw, qx, qy, qz columns) "
                        "about each axis, milliradians (default: %(default)s)")
    p.add_argument("--payload", type=floats, metavar="KG,X,Y,Z",
                   help="known payload for the compliance torques: mass in kg and centre of mass in "
                        "the tool frame in m (the start value with --identify-payload)")
    p.add_argument("--identify-payload", action="store_true",
                   help="estimate the payload's mass and centre of mass with the compliances "
                        "(needs --nongeometric compliance)")
    p.add_argument("--deflection", choices=DEFLECTIONS, default="linear",
                   help="compliance model: holding torque at the readings (linear, default) or the "
                        "static equilibrium at the deflected pose (exact: compiles the model's "
                        "gravity derivatives on first use; for compliant arms such as cobots)")
    p.add_argument("--nongeometric", action="append", choices=("compliance", "harmonics"),
                   help="add joint compliance (gravity model) and/or transmission errors (ratio, "
                        "first harmonics); repeat for both")
    p.add_argument("--no-report", action="store_true",
                   help="skip the HTML report and its figure (about 0.7 s of plotting); the YAML, "
                        "URDF, JSON, text report and residual CSV are written as always")
    p.add_argument("--stem", help="file name stem (default: ROBOT_calibrated)")
    p.add_argument("-o", "--output", required=True, metavar="DIR", help="output folder")
    p.set_defaults(func=_cmd_calibrate)


def _iso9283_parser(sub: argparse._SubParsersAction, fmt: type) -> None:
    p = sub.add_parser(
        "iso9283", help="ISO 9283 pose accuracy, repeatability, overshoot from measurements",
        formatter_class=fmt,
        description="ISO 9283 performance characteristics. DATA: a CSV of repeated cycles with "
                    "columns pose (label), x_cmd, y_cmd, z_cmd (commanded) and x, y, z "
                    "(attained), m; prints the pose accuracy AP and repeatability RP per pose. "
                    "--approach: a CSV with t, x, y, z of a measured approach to a pose; prints "
                    "the position overshoot and the stabilisation time for --band.",
        epilog="examples:\n  robodyn iso9283 cycles.csv\n"
               "  robodyn iso9283 --approach approach.csv --band 0.1")
    p.add_argument("data", metavar="DATA", nargs="?", help="CSV of repeated cycles")
    p.add_argument("--approach", metavar="FILE.csv", help="measured approach trajectory")
    p.add_argument("--band", type=float, default=0.1, metavar="MM",
                   help="stabilisation band, mm (default: %(default)s)")
    p.add_argument("--attained", type=floats, metavar="X,Y,Z",
                   help="the attained pose, m (default: the mean of the last 10 %% of samples)")
    p.set_defaults(func=_cmd_iso9283)
