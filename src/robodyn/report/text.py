"""Terminal output helpers: progress lines on stderr and aligned text tables."""

from __future__ import annotations

import sys
import time
from collections.abc import Iterator, Sequence
from contextlib import contextmanager

import numpy as np


def err(*args: object) -> None:
    print(*args, file=sys.stderr, flush=True)


@contextmanager
def progress(label: str) -> Iterator[None]:
    """``label... 2.1 s`` on stderr around a long step."""
    print(f"{label}...", end=" ", file=sys.stderr, flush=True)
    start = time.perf_counter()
    try:
        yield
    finally:
        print(f"{time.perf_counter() - start:.1f} s", file=sys.stderr, flush=True)


def table(headers: Sequence[str], rows: Sequence[Sequence[object]]) -> str:
    """Plain aligned text table; numbers right-aligned, text left-aligned."""
    cells = [[str(c) for c in headers]] + [[str(c) for c in row] for row in rows]
    numeric = [bool(rows) and all(is_number(r[k]) for r in rows) for k in range(len(headers))]
    widths = [max(len(r[k]) for r in cells) for k in range(len(headers))]

    def line(row: list[str]) -> str:
        return "  ".join(c.rjust(w) if num else c.ljust(w)
                         for c, w, num in zip(row, widths, numeric, strict=True)).rstrip()

    rule = "  ".join("-" * w for w in widths)
    return "\n".join([line(cells[0]), rule] + [line(r) for r in cells[1:]])


def is_number(value: object) -> bool:
    """A number, or the text of one (right-aligned in tables)."""
    if isinstance(value, bool):
        return False
    if isinstance(value, int | float | np.floating):
        return True
    try:
        float(str(value))
    except ValueError:
        return False
    return True
