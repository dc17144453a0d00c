"""Convert a serial-chain URDF file into a robodyn YAML description.

Usage::

    python tools/urdf_to_yaml.py IN.urdf OUT.yaml [--name NAME] [--source TEXT] [--licence FILE]

The URDF is read by :func:`robodyn.robot.urdf.load_urdf` (fixed joints merged) and written by
:func:`robodyn.robot.yaml_writer.dump_yaml`. ``--licence`` puts the text of FILE, as a comment
block, at the top of the output (for descriptions derived from licensed data). The built-in
``kinova_gen3`` was made with::

    python tools/urdf_to_yaml.py ../shared/data/kinova-gen3/gen3.urdf \\
        src/robodyn/robot/library/kinova_gen3.yaml --name kinova_gen3 \\
        --source "gen3.urdf of github.com/wissem01chiha/dynamic-identification" \\
        --licence src/robodyn/robot/library/LICENSE-kinova_gen3.txt
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
from pathlib import Path

try:
    from robodyn.robot.urdf import load_urdf
    from robodyn.robot.yaml_writer import dump_yaml
except ImportError:  # run from a checkout without installing
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))
    from robodyn.robot.urdf import load_urdf
    from robodyn.robot.yaml_writer import dump_yaml


def comment_block(text: str) -> str:
    """``text`` as YAML comment lines (``#`` and a space before each non-empty line)."""
    return "".join(f"# {line}".rstrip() + "\n" for line in text.rstrip().splitlines())


def convert(
    urdf: Path, *, name: str | None = None, source: str | None = None, licence: Path | None = None
) -> str:
    """The YAML text of ``urdf`` (optionally renamed, with a source text and a licence header)."""
    robot = load_urdf(urdf)
    changes = {}
    if name:
        changes["name"] = name
    if source:
        changes["source"] = source
    if changes:
        robot = dataclasses.replace(robot, **changes)
    text = dump_yaml(robot)
    if licence is not None:
        text = comment_block(licence.read_text(encoding="utf-8")) + "#\n" + text
    return text


def main(argv: list[str] | None = None) -> int:
    """Command-line entry point; returns the exit status."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("urdf", type=Path, help="input URDF file")
    parser.add_argument("yaml", type=Path, help="output robodyn YAML file")
    parser.add_argument("--name", help="robot name to write (default: the URDF robot name)")
    parser.add_argument("--source", help="where the URDF came from, for the header comment")
    parser.add_argument("--licence", type=Path, help="text file put at the top as comments")
    args = parser.parse_args(argv)
    text = convert(args.urdf, name=args.name, source=args.source, licence=args.licence)
    args.yaml.write_text(text, encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
