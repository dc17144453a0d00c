"""Terminal output helpers: progress lines and bars on stderr, aligned text tables."""

from __future__ import annotations

import sys
import time
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from tqdm import tqdm


def err(*args: object) -> None:
    print(*args, file=sys.stderr, flush=True)


#: The progress bar of the innermost :func:`steps` block (empty when none is shown).
_BARS: list[tqdm] = []  # (tqdm is imported by steps(): 40 ms the CLI's start-up does not need)


@contextmanager
def steps(total: int, desc: str) -> Iterator[None]:
    """A tqdm progress bar on stderr that counts the :func:`progress` steps run inside the block.

    Shown on a terminal only; elsewhere (pipes, logs, tests) each step prints its plain
    ``label... 2.1 s`` line as without a bar.
    """
    from tqdm import tqdm

    bar = tqdm(total=total, desc=desc, unit="step", file=sys.stderr, disable=not sys.stderr.isatty(),
               bar_format="{desc}: {percentage:3.0f}%|{bar}| {n_fmt}/{total_fmt} [{elapsed}] {postfix}")
    if bar.disable:
        yield
        return
    _BARS.append(bar)
    try:
        yield
    finally:
        _BARS.remove(bar)
        bar.close()


@contextmanager
def progress(label: str) -> Iterator[None]:
    """``label... 2.1 s`` on stderr around a long step (a step of the bar inside :func:`steps`)."""
    start = time.perf_counter()
    if _BARS:
        bar = _BARS[-1]
        bar.set_postfix_str(label)
        try:
            yield
        finally:
            bar.update(1)
            bar.write(f"{label}: {time.perf_counter() - start:.1f} s", file=sys.stderr)
        return
    print(f"{label}...", end=" ", file=sys.stderr, flush=True)
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


def markdown_table(headers: Sequence[str], rows: Sequence[Sequence[object]]) -> str:
    """GitHub markdown table (no trailing newline); cells as ``str`` gives them."""
    lines = ["| " + " | ".join(str(h) for h in headers) + " |", "|" + "---|" * len(headers)]
    return "\n".join(lines + ["| " + " | ".join(str(c) for c in row) + " |" for row in rows])


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
