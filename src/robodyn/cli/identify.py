"""``robodyn identify`` and ``robodyn validate``: parsers and commands.

Kept apart from :mod:`robodyn.cli` (which registers them); like the rest of the command line,
these only parse, call the public API (``rd.read_recording``, ``rd.identify``, ``rd.validate``)
and write or print the results.
"""

from __future__ import annotations

import argparse
import csv
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

import robodyn as rd
from robodyn.cli.args import ROBOT_HELP, floats, locked_joints
from robodyn.output_names import check_stem
from robodyn.robot.errors import InputError
from robodyn.text import err, progress

__all__ = ["register"]

# The choice lists of the parser, kept here so that building it does not import the
# identification package; tests/calibration/test_startup.py checks them against
# robodyn.identification.friction.FRICTION_MODELS and robodyn.identification.options.
FRICTION_MODELS: tuple[str, ...] = ("none", "linear", "stribeck", "load", "polynomial")
METHODS: tuple[str, ...] = ("ols", "wls", "consistent")
VELOCITIES: tuple[str, ...] = ("auto", "position", "measured")
SENSORS: tuple[str, ...] = ("motor", "link")
SPIKES: tuple[str, ...] = ("auto", "keep", "drop")


def tqdm(*args: object, **kwargs: object) -> object:
    """:class:`tqdm.tqdm`, imported on first use (it is not needed to build the parser)."""
    from tqdm import tqdm as _tqdm

    return _tqdm(*args, **kwargs)


def _gains(value: np.ndarray | None, n: int) -> np.ndarray | None:
    if value is None:
        return None
    if value.size == 1:
        return np.full(n, float(value[0]))
    if value.size != n:
        raise InputError(f"--gains: expected 1 or {n} comma-separated values (one per joint), got "
                         f"{value.size}")
    return value


def _payload(args: argparse.Namespace) -> rd.Payload | None:
    """The known payload of ``--payload`` (None without ``--payload-data``)."""
    if (args.payload is None) != (not args.payload_data):
        raise InputError("--payload and --payload-data go together: the recordings made with the "
                         "payload attached, and its mass, centre of mass (and inertia)")
    if args.payload is None:
        return None
    v = args.payload
    if v.size not in (4, 7, 10):
        raise InputError(f"--payload: expected KG,X,Y,Z[,IXX,IYY,IZZ[,IXY,IXZ,IYZ]] (4, 7 or 10 "
                         f"values), got {v.size}")
    inertia = np.zeros((3, 3))
    if v.size >= 7:
        inertia[np.diag_indices(3)] = v[4:7]
    if v.size == 10:
        for (i, j), value in zip(((0, 1), (0, 2), (1, 2)), v[7:10], strict=True):
            inertia[i, j] = inertia[j, i] = value
    return rd.Payload(mass=float(v[0]), com=v[1:4], inertia=inertia, frame=args.payload_frame)


def _read(paths: Sequence[str], spec: str | None, robot: rd.Robot, what: str) -> list:
    recs = []
    for path in tqdm(paths, desc=f"reading {what}", unit="file", leave=False, disable=len(paths) < 2):
        recs.append(rd.read_recording(path, spec=spec, robot=robot))
    return recs


def _metric_rows(val: rd.Validation) -> list[list[object]]:
    rows = []
    for k, name in enumerate(val.joint_names):
        drift = val.simulation.median_final[k] if val.simulation is not None else float("nan")
        rows.append([val.source, name, val.target, val.unit, repr(float(val.prediction.rms[k])),
                     repr(float(val.prediction.max[k])), repr(float(val.prediction.relative[k])),
                     repr(float(val.prediction.nrmse[k])),
                     repr(float(val.prediction_filtered.relative[k])),
                     repr(float(val.noise.relative[k])), repr(float(drift)), int(val.moving[k])])
    return rows


_METRIC_HEADERS = ["source", "joint", "target", "unit", "rms", "max", "relative", "nrmse",
                   "relative_filtered", "noise_floor", "median_drift_rad", "moving"]


def _write_metrics(vals: Sequence[rd.Validation], path: Path) -> Path:
    with path.open("w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow(_METRIC_HEADERS)
        for v in vals:
            w.writerows(_metric_rows(v))
    return path


# ----------------------------------------------------------------------------------------------
# identify
# ----------------------------------------------------------------------------------------------


def _cmd_identify(args: argparse.Namespace) -> int:
    from robodyn.export.urdf import to_urdf
    from robodyn.report.identification_report import identification_html
    from robodyn.robot.yaml_writer import dump_yaml

    robot = rd.load(args.robot, tool=args.tool, locked=locked_joints(args))
    stem = check_stem(f"{robot.name}_identified", what="robot name")  # data, never a path
    gains = _gains(args.gains, robot.dof)
    if gains is not None:
        robot = _with_gains(robot, gains)
    out = Path(args.output)
    out.mkdir(parents=True, exist_ok=True)
    payload = _payload(args)
    recs = _read(args.data, args.spec, robot, "identification data")
    loaded = _read(args.payload_data or [], args.spec, robot, "payload data")
    held = _read(args.validate or [], args.spec, robot, "validation data")
    extra = {"gains": "description"} if gains is not None else {}
    if loaded:
        extra["payloads"] = [None] * len(recs) + [payload] * len(loaded)
    model = _compiled(robot)
    with progress(f"identifying {robot.name} ({args.method}, {len(recs) + len(loaded)} "
                  "recording(s))"):
        ident = rd.identify(robot, recs + loaded, target=args.target, method=args.method,
                            model=model,
                            friction=args.friction, velocity=args.velocity,
                            dead_band=args.dead_band, coulomb_width=args.coulomb_width,
                            spikes=args.spikes, cutoff=args.cutoff,
                            regularization=args.regularization, decimate=args.decimate,
                            sensor=args.sensor, ripple=args.ripple, resonance=args.resonance,
                            prediction_cutoff=args.prediction_cutoff, local=args.local, **extra)
    paths = {"yaml": out / f"{stem}.yaml", "urdf": out / f"{stem}.urdf",
             "parameters": out / "parameters.csv"}
    paths["yaml"].write_text(dump_yaml(ident.robot), encoding="utf-8")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        paths["urdf"].write_text(to_urdf(ident.robot), encoding="utf-8")
    for w in caught:
        err(f"robodyn: note: URDF: {w.message}")
    ident.base_parameters.to_frame().to_csv(paths["parameters"], index=False)
    vals = []
    jobs = [("identification data", r) for r in recs] + [("held-out (--validate)", r) for r in held]
    for kind, rec in tqdm(jobs, desc="validating", unit="recording", leave=False):
        vals.append((f"{kind}: {rec.source}", rd.validate(ident.robot, rec, ident=ident,
                                                          window=args.window,
                                                          backend=model.backend)))
    if ident.target == "current" and loaded:
        gain_text = ", ".join(f"{k:.4g} +- {s:.2g}" for k, s in zip(ident.gains, ident.gains_std,
                                                                      strict=True))
        print(f"drive gains from the payload run(s), N m/A: {gain_text}")
    paths["metrics"] = _write_metrics([v for _, v in vals], out / "validation.csv")
    note = _prediction_note(ident, paths["yaml"], [r for _, r in jobs])
    for k, path in enumerate(_write_predictions(vals, out, note)):
        paths[f"predictions{k + 1}"] = path
    if not args.no_report:
        with progress("writing the report and its figures"):
            paths["report"] = identification_html(ident, vals, out, [r.source for r in recs])
    table = _held_out_table([(kind, v) for (kind, _), (_, v) in zip(jobs, vals, strict=True)])
    print(f"identified {len(ident.base_parameters)} base parameters of {robot.name} "
          f"({args.method}, target {ident.target}); condition number {ident.condition:.3g}, "
          f"Tikhonov weight {ident.regularization:.3g}")
    print(f"choices: {ident.choices.summary()}")
    if ident.unobserved:
        print(f"no {ident.target} data for joint(s) {', '.join(ident.unobserved)} (all-NaN columns): "
              "not fitted; their own terms are the description's")
    print(ident.base_parameters)
    for head, v in vals:
        print(f"\n{head}")
        print(v.summary())
    print(f"\n{table}\n{note}\n")
    for kind, path in paths.items():
        print(f"wrote {kind:<10} {path}")
    return _check_loadable(paths["yaml"])


def _prediction_note(ident: Any, yaml_path: Path, recs: Sequence[Any]) -> str:
    """How the written predictions of ``recs`` were made, and the ``robodyn validate`` command
    that reproduces them from the written description where the description alone does."""
    pre = ident.prediction_settings
    # recordings that move faster than the identification data: their own band
    wider = [f"{c:.3g} Hz for {r.source}" for r in recs
             if (c := ident.recording_cutoff(r)) != pre.cutoff]
    note = ("predicted by the identified model at states processed as the identification's: "
            + ("measured velocity" if pre.velocity == "measured" else "velocity from positions")
            + ("" if pre.cutoff is None else f", zero-phase low-pass at {pre.cutoff:.3g} Hz")
            + (f" ({', '.join(wider)}: faster motion than the identification data's)"
               if wider else "")
            + (f", Coulomb dead band {pre.dead_band:g} rad/s" if pre.dead_band else "")
            + _smoothing_note(ident.coulomb_width))
    fits = (ident.friction_fit, ident.thermal_fit, ident.ripple_fit, ident.resonance_fit,
            ident.prediction, ident.local_fit)
    if pre.velocity == "position" and pre.cutoff is not None and not pre.dead_band and not wider \
            and not np.any(ident.coulomb_width) and all(f is None for f in fits):
        note += (f"; robodyn validate {yaml_path} --target {ident.target} --cutoff "
                 f"{pre.cutoff:.17g} reproduces these figures from the written description")
    return note


def _smoothing_note(width: float | np.ndarray) -> str:
    """The predictions' Coulomb smoothing as the note says it ("" without one)."""
    if not np.any(width):
        return ""
    from robodyn.identification.coulomb_width import HOLD_SPEED

    text = ", ".join(f"{w:.2g}" for w in np.atleast_1d(width))
    return f", Coulomb step smoothed over {text} rad/s (at least {HOLD_SPEED:g} where held)"


def _compiled(robot: rd.Robot) -> rd.Model:
    """The compiled model of ``robot``; without a C compiler the NumPy one, with a note (same
    results, slower) instead of a traceback."""
    from robodyn.codegen.build import CompilerNotFoundError

    try:
        with progress(f"compiling {robot.name}"):
            return rd.compile_model(robot)
    except CompilerNotFoundError as exc:
        err(f"robodyn: note: {' '.join(str(exc).split())}; using the NumPy backend (same results, "
            "slower)")
        with progress(f"generating the NumPy model of {robot.name}"):
            return rd.compile_model(robot, backend="numpy")


def _held_out_table(vals: Sequence[tuple[str, rd.Validation]]) -> str:
    """Relative error of each validation, raw and against the reference-filtered target, beside
    its noise floor (a jointwise run: its moving joint only), and the held-out recordings
    pooled over every joint (the figure a user compares models by)."""
    from robodyn.validation.heldout import format_held_out, held_out_error, held_out_from_validation

    rows = [held_out_from_validation(v, label) for label, v in vals]
    held = [v for label, v in vals if label.startswith("held-out")]
    if held:
        # every joint with a measurement in every held-out recording
        cols = [j for j in range(len(held[0].joint_names))
                if all(not np.all(np.isnan(v.measured[:, j])) for v in held)]
        pooled = held_out_error([v.t for v in held], [v.measured for v in held],
                                [v.predicted for v in held], held[0].joint_names, cols,
                                source=f"{len(held)} recording(s), all measured joints",
                                cutoff=held[0].noise.cutoff)
        rows.append(("held-out, pooled", pooled))
    return format_held_out(rows)


def _safe_stem(source: str) -> str:
    """A file-name stem from a recording's source: its last path part, other characters as _."""
    name = Path(str(source)).name or "recording"
    for suffix in (".gz", ".csv", ".tsv", ".mcap", ".txt", ".log"):
        name = name[: -len(suffix)] if name.lower().endswith(suffix) else name
    return "".join(c if c.isalnum() or c in "-_." else "_" for c in name).strip(".") or "recording"


def _write_predictions(vals: Sequence[tuple[str, rd.Validation]], out: Path, note: str) -> list[Path]:
    """One CSV per validation: t, then measured and predicted target per joint (the model's
    prediction exactly as the printed figures used it); ``note`` says how the states were
    processed."""
    paths, used = [], set()
    for label, v in vals:
        stem = _safe_stem(v.source)
        while stem in used:
            stem += "_"
        used.add(stem)
        path = out / f"predictions_{stem}.csv"
        head = ["t"] + [f"{kind}_{j}" for j in v.joint_names for kind in ("measured", "predicted")]
        cols = [v.t] + [a[:, k] for k in range(len(v.joint_names)) for a in (v.measured, v.predicted)]
        with path.open("w", newline="", encoding="utf-8") as fh:
            fh.write(f"# {label}; target {v.target} ({v.unit}); {note}\n")
            writer = csv.writer(fh)
            writer.writerow(head)
            writer.writerows(zip(*(c.tolist() for c in cols), strict=True))
        paths.append(path)
    return paths


def _with_gains(robot: rd.Robot, gains: np.ndarray) -> rd.Robot:
    """A copy of ``robot`` whose drives give ``gains`` N m/A in magnitude: ``torque_constant =
    K / |gear_ratio|`` (gear ratio, hence the reflected rotor inertia and the current's sense,
    unchanged: the drive gain ``gear_ratio x torque_constant`` is ``sign(gear_ratio) K``)."""
    import dataclasses

    import sympy as sp

    joints = []
    for j, k in zip(robot.joints, gains, strict=True):
        ratio = abs(float(sp.sympify(j.drive.gear_ratio).subs(robot.defaults())))
        if ratio == 0:
            raise InputError(f"--gains: joint {j.name} has gear ratio 0 in {robot.source}")
        drive = dataclasses.replace(j.drive, torque_constant=sp.Float(float(k) / ratio))
        joints.append(dataclasses.replace(j, drive=drive))
    return dataclasses.replace(robot, joints=tuple(joints))


def _check_loadable(path: Path) -> int:
    """0 when the identified description loads again with physical values (strict: every link's
    inertia positive semi-definite and within the triangle inequality, a regular mass matrix),
    else 1 with the loader's reason, as ``--help`` promises."""
    from robodyn.robot.errors import DescriptionError

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            rd.load(str(path), strict=True)
    except DescriptionError as exc:
        err(f"robodyn: warning: the identified description does not load: {' '.join(str(exc).split())}"
            " (an unconstrained estimate can be non-physical; try --method consistent)")
        return 1
    return 0


# ----------------------------------------------------------------------------------------------
# validate
# ----------------------------------------------------------------------------------------------


def _cmd_validate(args: argparse.Namespace) -> int:
    from robodyn.report.identification_report import validation_html

    robot = rd.load(args.robot, tool=args.tool, locked=locked_joints(args))
    out = Path(args.output)
    out.mkdir(parents=True, exist_ok=True)
    recs = _read(args.data, args.spec, robot, "data")
    model = _compiled(robot)
    gains = _gains(args.gains, robot.dof)
    vals = []
    for rec in tqdm(recs, desc="validating", unit="recording", leave=False, disable=len(recs) < 2):
        extra = {} if args.noise_cutoff is None else {"noise_cutoff": args.noise_cutoff}
        if args.cutoff is not None:
            extra["cutoff"] = args.cutoff
        vals.append(rd.validate(robot, rec, args.target, model=model, gains=gains,
                                window=args.window, backend=model.backend, **extra))
    paths = {"metrics": _write_metrics(vals, out / "validation.csv")}
    with progress("writing the report and its figures"):
        for i, v in enumerate(vals):
            name = "validation.html" if len(vals) == 1 else f"validation_{i + 1}.html"
            paths[f"report {i + 1}"] = validation_html(v, out, name)
    for v in vals:
        print(v.summary())
        print()
    print(_held_out_table([("validation", v) for v in vals]))
    print()
    for kind, path in paths.items():
        print(f"wrote {kind:<10} {path}")
    return 0


# ----------------------------------------------------------------------------------------------
# parsers
# ----------------------------------------------------------------------------------------------


def register(sub: argparse._SubParsersAction, fmt: type) -> None:
    """Register ``identify`` and ``validate`` on the ``robodyn`` sub-parsers."""
    robot_help = ROBOT_HELP
    _identify_parser(sub, fmt, robot_help)
    _validate_parser(sub, fmt, robot_help)


def _common(p: argparse.ArgumentParser) -> None:
    p.add_argument("--spec", metavar="S",
                   help="recording spec for CSV files: a built-in name (kinova_gen3, robodyn), or a "
                        "spec YAML file (default: robodyn's own CSV layout; MCAP needs none)")
    p.add_argument("--target", choices=("tau", "current"),
                   help="joint torque or motor current (default: torque when every file has it)")
    p.add_argument("--window", type=float, default=0.2, metavar="S",
                   help="simulation window, s: simulate from the measured state under the "
                        "measured torque and report the drift (default: %(default)s)")
    p.add_argument("-o", "--output", required=True, metavar="DIR", help="output folder")


def _identify_parser(sub: argparse._SubParsersAction, fmt: type, robot_help: str) -> None:
    p = sub.add_parser(
        "identify", help="identify inertial, drive and friction parameters from recordings",
        formatter_class=fmt,
        description="Identify a robot's base inertial parameters, drive (rotor inertia, gain) and "
                    "friction parameters from measured runs (rd.identify), then validate the "
                    "result on the same runs and on held-out ones (rd.validate). Writes the "
                    "identified description (ROBOT_identified.yaml and .urdf, readable by "
                    "robodyn), parameters.csv (estimates, standard deviations, the standard "
                    "parameters each base parameter combines), validation.csv (per-joint "
                    "errors) and report.html with the figures. Exit code 1 if the identified "
                    "description does not load again (non-physical values, named).",
        epilog="examples:\n"
               "  robodyn identify kinova_gen3 --spec kinova_gen3 --target current \\\n"
               "      --data run1.csv.gz run2.csv.gz --validate run3.csv.gz -o ident/\n"
               "  robodyn identify kinova_gen3 --spec kinova_gen3 --target current \\\n"
               "      --gains 9.13,9.13,9.13,9.13,5.852,5.852,5.852 --data run1.csv.gz -o ident/\n"
               "  robodyn identify my_arm.yaml --data bag.mcap --method wls -o ident/")
    p.add_argument("robot", metavar="ROBOT", help=robot_help)
    p.add_argument("--data", required=True, nargs="+", metavar="FILE",
                   help="identification recordings (CSV, CSV.gz or MCAP)")
    p.add_argument("--validate", nargs="+", metavar="FILE", help="held-out recordings to validate on")
    p.add_argument("--method", choices=METHODS, default="consistent",
                   help="estimator: ordinary or weighted least squares, or physically consistent "
                        "(pseudo-inertia LMIs) (default: %(default)s)")
    p.add_argument("--gains", type=floats, metavar="K",
                   help="drive gains, joint torque per motor ampere (N m/A), one or one per joint, "
                        "for --target current: fixed instead of absorbed per joint (magnitudes: a "
                        "drive with a negative gear ratio keeps its reversed current)")
    p.add_argument("--payload-data", nargs="+", metavar="FILE",
                   help="recordings made with a known payload on the last link (with --payload): "
                        "for --target current they separate the drive gains from the inertia")
    p.add_argument("--payload", type=floats, metavar="KG,X,Y,Z[,IXX,IYY,IZZ[,IXY,IXZ,IYZ]]",
                   help="the payload of --payload-data: mass (kg), centre of mass (m) and "
                        "optionally its inertia about the centre of mass (kg m^2)")
    p.add_argument("--payload-frame", choices=("tool", "link"), default="tool",
                   help="frame of --payload's centre of mass and inertia: the tool frame or the "
                        "last link's frame (default: %(default)s)")
    p.add_argument("--friction", default="auto", choices=(*FRICTION_MODELS, "auto"),
                   help="friction model: linear (viscous, Coulomb +/-, offset, in the linear fit), "
                        "none, a nonlinear law fitted after the linear step, or auto: linear or "
                        "Stribeck chosen by held-out time blocks (default: %(default)s)")
    _preprocessing(p)
    _common(p)
    p.set_defaults(func=_cmd_identify)


def _auto_or(kind: type, *, none: bool = False) -> Any:
    """An argparse type: "auto", optionally "none", or a number of ``kind``."""
    def parse(text: str) -> Any:
        if text == "auto":
            return "auto"
        if none and text == "none":
            return None
        try:
            value = kind(text)
        except ValueError:
            words = "'auto', 'none' or " if none else "'auto' or "
            raise argparse.ArgumentTypeError(f"expected {words}a number, got {text!r}") from None
        if not np.isfinite(value):
            raise argparse.ArgumentTypeError(f"expected a finite number, got {text!r}")
        return value
    return parse


def _auto_on_off(text: str) -> bool | str:
    """``--ripple``, ``--resonance``: "auto", "on" (True) or "off" (False)."""
    values = {"auto": "auto", "on": True, "off": False}
    if text not in values:
        raise argparse.ArgumentTypeError(f"expected auto, on or off, got {text!r}")
    return values[text]


def _width(text: str) -> float | str:
    """``--coulomb-width``: "auto" or a finite velocity >= 0."""
    if text == "auto":
        return text
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected auto or a velocity in rad/s, got {text!r}") from None
    if not (np.isfinite(value) and value >= 0):
        raise argparse.ArgumentTypeError(f"expected auto or a finite velocity >= 0, got {text!r}")
    return value


def _prediction_cutoff(text: str) -> float | str:
    """``--prediction-cutoff``: "motion", "fit", "auto" or a frequency in Hz."""
    if text in ("motion", "fit", "auto"):
        return text
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected motion, fit, auto or a frequency in Hz, "
                                         f"got {text!r}") from None
    if not (np.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"expected a positive frequency in Hz, got {text!r}")
    return value


def _preprocessing(p: argparse.ArgumentParser) -> None:
    """The identification's preprocessing options (rd.identify's keywords of the same names)."""
    p.add_argument("--velocity", choices=VELOCITIES, default="auto",
                   help="joint velocity source: differences of the filtered positions, the "
                        "filtered measured velocity, or auto: with a recorded velocity, the "
                        "source whose finished model fits the data better (printed under "
                        "'choices') (default: %(default)s)")
    p.add_argument("--dead-band", type=_auto_or(float), default=0.0, metavar="RAD_S",
                   help="Coulomb dead band in rad/s, in the fit and the prediction alike (below "
                        "it a joint carries only its friction offset), or auto: 0 or 1e-3 chosen "
                        "by held-out time blocks (default: %(default)s)")
    p.add_argument("--coulomb-width", type=_width, default="auto", metavar="{auto,RAD_S}",
                   help="velocity in rad/s over which the predictions smooth the Coulomb step "
                        "(tanh(qd / width)): the expected friction where the estimated velocity's "
                        "sign is uncertain (joints held still, slow reversals); the fit keeps the "
                        "step; 0: none; auto: per joint, from the noise of the identification "
                        "data's processed velocity (default: %(default)s)")
    p.add_argument("--spikes", choices=SPIKES, default="auto",
                   help="glitches (a position or target sample far off the line through its "
                        "neighbours, or a burst of up to 5 such rows) in the identification "
                        "recordings: keep them, "
                        "drop those rows before the fit (beyond 12 robust standard deviations), "
                        "or auto: drop gross glitches only (beyond 100), with a warning "
                        "(default: %(default)s)")
    p.add_argument("--ripple", type=_auto_on_off, default="auto", metavar="{auto,on,off}",
                   help="a torque once per revolution of each revolute joint (a sin q + b cos q), "
                        "fitted on what the model leaves: on, off, or auto: kept when it predicts "
                        "held-out time blocks better (default: %(default)s)")
    p.add_argument("--resonance", type=_auto_on_off, default="auto", metavar="{auto,on,off}",
                   help="one lightly damped drive mode per joint (joint and gear elasticity, the "
                        "current loop) added to the prediction, its frequency, damping and share "
                        "fitted on what the model leaves: on, off, or auto: kept on a joint when "
                        "it predicts held-out time blocks better (default: %(default)s)")
    p.add_argument("--local", type=_auto_on_off, default="auto", metavar="{auto,on,off}",
                   help="a kernel correction of what the model leaves near the identification "
                        "data's states, zero far from them (a repeated trajectory is predicted "
                        "with it, new motion by the model alone): on, off, or auto: kept when it "
                        "predicts held-out time blocks better (default: %(default)s)")
    p.add_argument("--prediction-cutoff", type=_prediction_cutoff, default="motion",
                   metavar="{motion,fit,auto,HZ}",
                   help="low-pass cut-off of the states the model is evaluated at in predictions: "
                        "motion: the fit's, widened for a recording that moves faster than the "
                        "identification data (the --cutoff auto rule on that recording); fit: the "
                        "fit's; a frequency in Hz; or auto: a wider one when it predicts the "
                        "raw target of the identification data better (lower error against the "
                        "raw target, higher against a low-passed one) (default: %(default)s)")
    p.add_argument("--cutoff", type=_auto_or(float, none=True), default="auto", metavar="HZ",
                   help="zero-phase low-pass cut-off in Hz, none (the recording's own "
                        "velocities and accelerations), or auto: the motion's bandwidth within "
                        "2-5 Hz (default: %(default)s)")
    p.add_argument("--regularization", type=_auto_or(float, none=True), default="auto",
                   metavar="W", help="Tikhonov weight toward the description, none, or auto: "
                                     "chosen by held-out time blocks (default: %(default)s)")
    p.add_argument("--decimate", type=_auto_or(int), default="auto", metavar="K",
                   help="keep every K-th filtered sample for the fit, or auto: about five per "
                        "cut-off period (default: %(default)s)")
    p.add_argument("--sensor", choices=SENSORS, default="motor",
                   help="where the effort is measured: motor (current, or a torque that includes "
                        "the drive) or link (a joint torque sensor after the gear: the rotor "
                        "inertia is not identified; --target tau) (default: %(default)s)")
    p.add_argument("--no-report", action="store_true",
                   help="skip report.html and its figures (every other output is written)")


def _validate_parser(sub: argparse._SubParsersAction, fmt: type, robot_help: str) -> None:
    p = sub.add_parser(
        "validate", help="validate a robot's model against recordings",
        formatter_class=fmt,
        description="Compare a robot's model with measured data (rd.validate): predicted against "
                    "measured torque or motor current per joint (RMS, maximum, relative error, "
                    "NRMSE, against the raw and the low-pass filtered target, with the noise "
                    "floor), and short simulations from the measured state under the measured "
                    "torque (drift per window). Writes validation.csv and validation.html with "
                    "figures (measured vs predicted, friction curves, error histograms, residual "
                    "spectra).",
        epilog="examples:\n"
               "  robodyn validate ident/kinova_gen3_identified.yaml --spec kinova_gen3 \\\n"
               "      --data joint_2_trapez.csv.gz -o val/\n"
               "  robodyn validate kinova_gen3 --spec kinova_gen3 --target current \\\n"
               "      --gains 9.13,9.13,9.13,9.13,5.852,5.852,5.852 --data run.csv.gz -o val/")
    p.add_argument("robot", metavar="ROBOT", help=robot_help)
    p.add_argument("--data", required=True, nargs="+", metavar="FILE",
                   help="recordings (CSV, CSV.gz or MCAP)")
    p.add_argument("--gains", type=floats, metavar="K",
                   help="joint torque per motor ampere, N m/A, one or one per joint (default: the "
                        "description's gear ratio x torque constant)")
    p.add_argument("--noise-cutoff", type=float, metavar="HZ",
                   help="low-pass cut-off separating the target from its noise, Hz (default: the "
                        "reference filter of robodyn.validation.heldout, zero-phase Butterworth "
                        "order 4 at 2.5 Hz, which reproduces the Kinova data README's noise floor)")
    p.add_argument("--cutoff", type=float, metavar="HZ",
                   help="process the states as an identification did: positions low-passed at HZ "
                        "and differentiated (robodyn identify prints its value; with it, an "
                        "identified description reproduces identify's figures) (default: the "
                        "recording's own velocities and accelerations)")
    _common(p)
    p.set_defaults(func=_cmd_validate)
