"""``robodyn record info|plot|convert``: look at, plot and convert measured recordings.

Registered by :mod:`robodyn.cli`; like the rest of the command line these only parse, call the
public API and print. Bad input raises :class:`~robodyn.robot.errors.RecordingError` (a
``ValueError``), which the CLI reports on one line with exit code 2.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path

import numpy as np

import robodyn as rd
from robodyn.cli.args import ROBOT_HELP
from robodyn.robot.errors import InputError
from robodyn.text import err, table

__all__ = ["register"]

_FIELDS = ("q", "qd", "qdd", "tau", "current", "temperature")


def _read(args: argparse.Namespace) -> rd.Recording:
    robot = rd.load(args.robot) if getattr(args, "robot", None) else None
    return rd.read_recording(args.file, spec=args.spec, robot=robot)


def _cmd_info(args: argparse.Namespace) -> int:
    rec = _read(args)
    print(f"{rec.source}: {rec.n_samples} samples of {rec.dof} joints "
          f"({', '.join(rec.joint_names)})")
    print(f"duration {rec.duration:.6g} s, median period {rec.dt * 1e3:.6g} ms "
          f"({1.0 / rec.dt:.6g} Hz)")
    for key, value in rec.units.items():
        if key not in ("t", "q", "qd", "qdd", "tau", "current", "temperature", "tool_t", "tool_points"):
            print(f"{key}: {value}")
    gaps = rec.gaps
    if gaps:
        shown = ", ".join(f"{dt * 1e3:.4g} ms after t = {rec.t[k]:.6g} s" for k, dt in gaps[:5])
        print(f"gaps: {len(gaps)} ({shown}{', ...' if len(gaps) > 5 else ''})")
    else:
        print("gaps: none")
    rows = []
    for field in _FIELDS:
        value = getattr(rec, field)
        if value is None:
            continue
        note = " (estimated)" if field in rec.estimated else ""
        for k, name in enumerate(rec.joint_names):
            col = value[:, k]
            nan = int(np.isnan(col).sum())
            if nan == col.size:
                rows.append([f"{field}{note}", name, rec.units.get(field, ""), "-", "-", nan])
                continue
            rows.append([f"{field}{note}", name, rec.units.get(field, ""), f"{np.nanmin(col):.6g}",
                         f"{np.nanmax(col):.6g}", nan])
    print(table(["field", "joint", "unit", "min", "max", "NaN"], rows))
    if rec.tool_t is not None:
        print(f"tracker: {rec.tool_t.size} points over {rec.tool_t[-1] - rec.tool_t[0]:.6g} s")
    return 0


def _cmd_plot(args: argparse.Namespace) -> int:
    from matplotlib.figure import Figure

    rec = _read(args)
    out = Path(args.output)
    out.mkdir(parents=True, exist_ok=True)
    fields = [f for f in _FIELDS if getattr(rec, f) is not None]
    for k, name in enumerate(rec.joint_names):
        fig = Figure(figsize=(8, 1.8 * len(fields) + 0.6))
        axes = fig.subplots(len(fields), 1, sharex=True, squeeze=False)
        for ax, field in zip(axes[:, 0], fields, strict=True):
            ax.plot(rec.t, getattr(rec, field)[:, k], lw=0.8)
            est = " (estimated)" if field in rec.estimated else ""
            ax.set_ylabel(f"{field}\n[{rec.units.get(field, '')}]{est}", fontsize=8)
            ax.grid(True, lw=0.3)
        axes[-1, 0].set_xlabel("t [s]")
        fig.suptitle(f"{rec.source}: {name}")
        fig.tight_layout()
        path = out / f"{Path(rec.source).name.split('.')[0]}_{name}.png"
        fig.savefig(path, dpi=100)
        print(path)
    return 0


def _cmd_convert(args: argparse.Namespace) -> int:
    from robodyn.measure.csv_io import write_csv
    from robodyn.measure.mcap_io import write_mcap

    out = Path(args.output)
    source = Path(args.file)
    # the same file by any name: a symbolic or a hard link, another path to it
    if out.exists() and source.exists() and (out.resolve() == source.resolve()
                                             or os.path.samefile(out, source)):
        raise InputError(f"{out}: -o is the file being converted (or a link to it); write to "
                         "another file (the input is never overwritten)")
    rec = _read(args)
    if out.suffix.lower() not in (".mcap", ".csv", ".gz"):
        raise InputError(f"{out}: -o must end in .csv, .csv.gz or .mcap")
    out.parent.mkdir(parents=True, exist_ok=True)  # as every command's -o
    if out.suffix.lower() == ".mcap":
        dropped = [name for name in ("current", "temperature") if getattr(rec, name) is not None]
        if dropped:
            # a JointState carries position, velocity and effort only
            err(f"robodyn: warning: {out}: a ROS 2 JointState bag has no field for "
                f"{' and '.join(dropped)}: not written (convert to .csv to keep them)")
        write_mcap(rec, out)
    elif out.suffix.lower() in (".csv", ".gz"):
        write_csv(rec, out)
    else:
        raise InputError(f"{out}: -o must end in .csv, .csv.gz or .mcap")
    err(f"wrote {out}")
    return 0


def register(sub: argparse._SubParsersAction, fmt: type) -> None:
    """Register ``record`` with its ``info``, ``plot`` and ``convert`` subcommands."""
    robot_help = ROBOT_HELP
    p = sub.add_parser("record", help="inspect, plot and convert measured recordings",
                       formatter_class=fmt,
                       description="Measured joint data: CSV/TSV (optionally .gz) read through a "
                                   "recording spec (built-in 'kinova_gen3', or a YAML file; see "
                                   "docs/recording-spec.md), robodyn's own CSV layout, or a ROS 2 "
                                   "bag (.mcap) of sensor_msgs/JointState.",
                       epilog="examples:\n"
                              "  robodyn record info run.csv.gz --spec kinova_gen3\n"
                              "  robodyn record plot run.csv.gz --spec kinova_gen3 -o plots/\n"
                              "  robodyn record convert run.mcap -o run.csv")
    rsub = p.add_subparsers(dest="record_command", metavar="ACTION", required=True)
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument("file", metavar="FILE", help="recording (.csv, .tsv, .gz, .mcap)")
    common.add_argument("--spec", metavar="S", default=None,
                        help="recording spec: built-in name or YAML file (CSV/TSV only; default: "
                             "robodyn's own CSV layout)")
    common.add_argument("--robot", metavar="ROBOT", default=None,
                        help=robot_help + "; joints matched by name, put in chain order")
    q = rsub.add_parser("info", parents=[common], formatter_class=fmt,
                        help="duration, rate, ranges, gaps and NaN per column",
                        description="Print the duration, sample rate, gaps, and per joint and "
                                    "signal the range and the number of NaN values.")
    q.set_defaults(func=_cmd_info)
    q = rsub.add_parser("plot", parents=[common], formatter_class=fmt,
                        help="one PNG figure per joint",
                        description="Write one figure per joint (every signal against time) as "
                                    "PNG files into a folder.")
    q.add_argument("-o", "--output", required=True, metavar="DIR", help="output folder")
    q.set_defaults(func=_cmd_plot)
    q = rsub.add_parser("convert", parents=[common], formatter_class=fmt,
                        help="convert to robodyn's CSV layout or to a ROS 2 bag",
                        description="Convert a recording to robodyn's own CSV layout (.csv or "
                                    ".csv.gz) or to a ROS 2 bag (.mcap).")
    q.add_argument("-o", "--output", required=True, metavar="FILE",
                   help="output file (.csv, .csv.gz or .mcap)")
    q.set_defaults(func=_cmd_convert)
