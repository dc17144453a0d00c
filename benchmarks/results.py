"""One results file per machine: ``benchmarks/results/<machine>.json`` (issue 22).

Each benchmark merges its entry under its own name (``{"benchmarks": {"kernels": {...}}}``), so
that others can be added later without touching the rest. The file also records the machine:
CPU model, logical CPUs, the load average at the time, and the date. Figures are stored as
``{"min": ..., "median": ...}`` over the repeats, in the unit their key names.

Used by the benchmarks (run as scripts: ``benchmarks/`` is on ``sys.path``) and by
``render_readme.py``; nothing here times anything.
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import re
import statistics
from collections.abc import Sequence
from pathlib import Path
from typing import Any

#: Folder of the results files.
RESULTS_DIR = Path(__file__).resolve().parent / "results"


def cpu_model() -> str:
    """The processor's model name (``/proc/cpuinfo``, else :func:`platform.processor`).

    Returns
    -------
    str
        E.g. ``"AMD EPYC 7B13"``; ``"unknown"`` when nothing says.
    """
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine() or "unknown"


def machine_name() -> str:
    """File-name-safe name of this machine: its CPU model and logical CPU count.

    A CPU model rather than the host name: containers get random host names, and the figures
    belong to the processor.

    Returns
    -------
    str
        Lower-case letters, digits and dashes, e.g. ``"intel-xeon-processor-avx512-2cpu"``: the
        widest vector set (:func:`simd_level`) is part of the name, as a model name such as
        "AMD EPYC" covers processors with and without AVX-512, whose kernels differ.
    """
    model = re.sub(r"\((r|tm)\)", "", cpu_model().lower())
    model = re.sub(r"\b(cpu|with|radeon graphics)\b", " ", model)
    slug = re.sub(r"[^a-z0-9]+", "-", model).strip("-") or "unknown"
    level = simd_level()
    return f"{slug}-{level + '-' if level else ''}{os.cpu_count() or 0}cpu"


def default_path() -> Path:
    """``benchmarks/results/<machine_name()>.json``."""
    return RESULTS_DIR / f"{machine_name()}.json"


def load_average() -> list[float]:
    """The 1, 5 and 15 minute load averages (zeros where the system has none)."""
    try:
        return [round(x, 2) for x in os.getloadavg()]
    except OSError:
        return [0.0, 0.0, 0.0]


def summary(seconds: Sequence[float], scale: float = 1.0, digits: int = 1) -> dict[str, float]:
    """Minimum and median of repeated timings, scaled (e.g. to ns per state).

    Parameters
    ----------
    seconds : sequence of float
        One wall time per repeat.
    scale : float
        Factor applied to both (``1e9 / count`` gives ns per state).
    digits : int
        Decimals kept.

    Returns
    -------
    dict
        ``{"min": ..., "median": ..., "repeats": n}``.
    """
    return {"min": round(min(seconds) * scale, digits),
            "median": round(statistics.median(seconds) * scale, digits),
            "repeats": len(seconds)}


def ratio(seconds: Sequence[float], reference: Sequence[float], digits: int = 2,
          ) -> dict[str, float]:
    """How many times ``reference`` the repeated timings ``seconds`` take.

    Parameters
    ----------
    seconds, reference : sequence of float
        Wall times of the repeats of a row and of the row it is compared with (the same rounds).

    Returns
    -------
    dict
        ``{"min": min(seconds) / min(reference), "median": median / median}``, rounded.
    """
    return {"min": round(min(seconds) / min(reference), digits),
            "median": round(statistics.median(seconds) / statistics.median(reference), digits)}


def simd() -> list[str]:
    """The vector instruction sets among AVX, AVX2, FMA and AVX-512F that the CPU reports."""
    try:
        flags = next((line.split(":", 1)[1].split() for line in
                      Path("/proc/cpuinfo").read_text().splitlines() if line.startswith("flags")), [])
    except OSError:
        flags = []
    return [f for f in ("avx", "avx2", "fma", "avx512f") if f in flags]


def simd_level() -> str:
    """``"avx512"``, ``"avx2"`` or ``""``: the widest of the two that the CPU reports."""
    flags = simd()
    return "avx512" if "avx512f" in flags else "avx2" if "avx2" in flags else ""


def machine_record() -> dict[str, Any]:
    """What the file says about the machine (the entry of each benchmark has its own load)."""
    return {"name": machine_name(), "cpu_model": cpu_model(), "simd": simd(),
            "logical_cpus": os.cpu_count(),
            "system": f"{platform.system()} {platform.release()}",
            "python": platform.python_version()}


def merge(path: Path, name: str, entry: dict[str, Any]) -> Path:
    """Write ``entry`` as benchmark ``name`` into the results file at ``path``.

    Other benchmarks' entries in the file are kept; the machine record and this entry are
    replaced. The entry gets the date and the load average at the time of writing. A file
    written on another machine (CPU model, vector set or CPU count) is refused: its other
    entries would be attributed to this one.

    Parameters
    ----------
    path : Path
        The results file (created with its folder when missing).
    name : str
        Benchmark name, e.g. ``"kernels"``.
    entry : dict
        JSON-serialisable figures.

    Returns
    -------
    Path
        ``path``.
    """
    data: dict[str, Any] = {}
    if path.exists():
        data = json.loads(path.read_text())
    here, there = machine_record(), data.get("machine", {})
    differs = [k for k in ("cpu_model", "simd", "logical_cpus") if k in there and there[k] != here[k]]
    if differs:
        # the other entries were measured on another processor: one file per machine
        was = ", ".join(f"{k} {there[k]!r}" for k in differs)
        now = ", ".join(f"{k} {here[k]!r}" for k in differs)
        raise SystemExit(f"{path}: written on another machine ({was}; this one: {now}); write "
                         f"this machine's file ({default_path().name}) or name one with --results")
    data["machine"] = here
    entry = {"date": datetime.date.today().isoformat(), **entry,
             "load_average_at_end": load_average()}
    data.setdefault("benchmarks", {})[name] = entry
    data["benchmarks"] = dict(sorted(data["benchmarks"].items()))
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(data, indent=1) + "\n")
    tmp.replace(path)
    return path


if __name__ == "__main__":  # the path of this machine's results file, for the Makefile
    print(default_path().relative_to(RESULTS_DIR.parent.parent))


def add_options(parser: argparse.ArgumentParser) -> None:
    """The ``--results PATH`` and ``--no-results`` options every benchmark that writes here has."""
    parser.add_argument("--results", type=Path, default=None,
                        help="results file (default: benchmarks/results/<machine>.json on full "
                             "runs, none with --quick)")
    parser.add_argument("--no-results", action="store_true", help="write no results file")


def target(args: argparse.Namespace) -> Path | None:
    """The results file a run writes (None: none), from :func:`add_options` and ``--quick``."""
    if args.no_results:
        return None
    return args.results or (None if args.quick else default_path())
