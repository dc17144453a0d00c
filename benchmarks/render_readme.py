"""Render the README's benchmark figures from a results file (issue 22, item 2).

The README holds marked sections::

    <!-- results:kernels benchmarks/results/<machine>.json -->
    ... generated text ...
    <!-- /results:kernels -->

Each names a benchmark and the results file (``results.py``) it is rendered from. This script
rewrites the text between the markers from that file; ``--results PATH`` points the markers
at another file first (e.g. the one ``make bench`` just wrote on this machine); ``--check``
changes nothing and exits 1 if the README differs from its rendering (what
``tests/test_readme_results.py`` asserts).

Run: ``.venv/bin/python benchmarks/render_readme.py [--results PATH] [--check]``.
Standard library only; nothing here times anything.
"""

from __future__ import annotations

import argparse
import json
import re
import sys
import textwrap
from collections.abc import Callable
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
README = ROOT / "README.md"
MARKER = re.compile(r"<!-- results:(?P<name>[\w-]+) (?P<path>\S+) -->\n(?P<body>.*?)"
                    r"<!-- /results:(?P=name) -->", re.S)
LIBRARIES = {"robodyn": "robodyn, no friction", "robodyn (friction)": "robodyn, PUMA friction",
             "pinocchio native": "Pinocchio native", "pinocchio wheel": "Pinocchio wheel"}


def _wrap(text: str, bullet: bool = False) -> list[str]:
    """Lines of at most 100 characters, as the README's prose (bullets with a hanging indent)."""
    return textwrap.wrap(text, 100, initial_indent="* " if bullet else "",
                         subsequent_indent="  " if bullet else "", break_long_words=False,
                         break_on_hyphens=False)


def _fmt(x: float) -> str:
    return f"{x:.0f}" if x >= 100 else f"{x:.1f}"


def _ratio_cell(ratios: list[dict[str, Any]], kernel: str, library: str) -> tuple[str, str]:
    """Speed-up and target cells of one table row."""
    for r in ratios:
        if r["kernel"] != kernel:
            continue
        if library == r["peer"] and r["robodyn"] == "robodyn":
            target = (f">= {r['target']:g}x: {'met' if r['met'] else 'not met'}"
                      if "target" in r else "")
            return f"{r['min']:.1f}x / {r['median']:.1f}x", target
        if library == r["robodyn"] != "robodyn":
            return f"{r['min']:.1f}x / {r['median']:.1f}x over native", ""
    return "", ""


def render_kernels(data: dict[str, Any]) -> str:
    """Markdown of the ``kernels`` entry: a sentence on the run, a table, what each row differs in.

    Parameters
    ----------
    data : dict
        The whole results file (machine record and benchmarks).

    Returns
    -------
    str
        Lines ending in a newline.
    """
    m, e = data["machine"], data["benchmarks"]["kernels"]
    simd = "AVX-512F" if "avx512f" in m.get("simd", []) else "/".join(m.get("simd", [])).upper()
    lines = _wrap(
        f"PUMA 560 kernels against Pinocchio (`{e['command']}`, {e['states']:,} random states, one "
        f"thread, ns per state, min / median of {e['repeats']} rounds in which the libraries take "
        f"turns; {m['cpu_model']}, "
        f"{m['logical_cpus']} logical CPUs, {simd or 'no AVX'}; load average "
        f"{' '.join(map(str, e['load_average_at_start']))} at the start and "
        f"{' '.join(map(str, e['load_average_at_end']))} at the end; {e['date']}). "
        "Speed-up = the row's time / robodyn's without friction; the issue's targets apply to "
        "the native build and are judged on the minima.")
    lines += [
        "",
        "| kernel | library | min | median | robodyn's speed-up (min / median) | target "
        "| max rel. error vs robodyn |",
        "|---|---|---:|---:|---:|---|---:|",
    ]
    for row in e["rows"]:
        speed, target = _ratio_cell(e["ratios"], row["kernel"], row["library"])
        err = row["max_rel_error"]
        err_text = "reference" if row["library"] == "robodyn" else (
            "(has friction)" if err is None else f"{err:.1e}")
        ns = row["ns_per_state"]
        lines.append(f"| {row['kernel']} | {LIBRARIES.get(row['library'], row['library'])} | "
                     f"{_fmt(ns['min'])} | {_fmt(ns['median'])} | {speed} | {target} | {err_text} |")
    if e.get("skipped"):
        lines += ["", e["skipped"]]
    bullets = [f"{LIBRARIES.get(k, k)}: {v}." for k, v in e["peers"].items()]
    notes: dict[str, list[str]] = {r["library"]: [] for r in e["rows"]}
    for r in e["rows"]:
        if r["note"]:
            notes[r["library"]].append(f"{r['kernel']}: {r['note']}")
    bullets += [f"{LIBRARIES.get(lib, lib)} calls: {'; '.join(t)}." for lib, t in notes.items() if t]
    if e.get("native"):
        n = e["native"]
        bullets.append(f"Pinocchio native built by {n['compiler']} with `{' '.join(n['flags'])}` "
                       f"against the {n['headers']}, {n['linked']}.")
    bullets.append("The wheel's derivative loop without the Python loop's own cost: "
                   f"{_fmt(e['wheel']['derivatives_minus_loop_ns']['min'])} ns per state (min).")
    lines += ["", "What each row is and differs in:", ""]
    for b in bullets:
        lines += _wrap(b, bullet=True)
    return "\n".join(lines) + "\n"


RENDERERS: dict[str, Callable[[dict[str, Any]], str]] = {"kernels": render_kernels}


def render(text: str, root: Path = ROOT, results: str | None = None) -> str:
    """The README text with every marked section rendered from the file it names.

    Parameters
    ----------
    text : str
        README contents.
    root : Path
        Folder the results paths are relative to.
    results : str, optional
        Results path (relative to ``root``) to put into every marker first.

    Returns
    -------
    str
        The new README contents.

    Raises
    ------
    ValueError
        No marked section, or one for a benchmark without a renderer.
    """
    def section(match: re.Match[str]) -> str:
        name, path = match["name"], results or match["path"]
        if name not in RENDERERS:
            raise ValueError(f"no renderer for results:{name}")
        data = json.loads((root / path).read_text())
        return f"<!-- results:{name} {path} -->\n{RENDERERS[name](data)}<!-- /results:{name} -->"

    new, count = MARKER.subn(section, text)
    if not count:
        raise ValueError("no <!-- results:NAME PATH --> section in the README")
    return new


def main(argv: list[str] | None = None) -> int:
    """Command line: render (or ``--check``) README.md; returns the exit status."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--results", help="results file (relative to the repository) to render from")
    parser.add_argument("--check", action="store_true", help="exit 1 if README.md is not rendered")
    parser.add_argument("--readme", type=Path, default=README)
    args = parser.parse_args(argv)
    results = args.results
    if results is not None and Path(results).is_absolute():
        results = str(Path(results).resolve().relative_to(ROOT))
    text = args.readme.read_text()
    new = render(text, ROOT, results)
    if args.check:
        if new != text:
            print(f"{args.readme} differs from its rendering: run benchmarks/render_readme.py")
            return 1
        print(f"{args.readme} matches its results file(s)")
        return 0
    if new != text:
        args.readme.write_text(new)
    print(f"{args.readme}: benchmark section(s) rendered")
    return 0


if __name__ == "__main__":
    sys.exit(main())
