"""Shared pieces of the README's benchmark sections: wrapping, number formats, tables, the
sentence that opens each section (what ran, the command, the machine, its load, the date).

Used by ``render_readme.py`` and the ``render_*.py`` modules it registers. Standard library only;
nothing here times anything.
"""

from __future__ import annotations

import textwrap
from typing import Any


def wrap(text: str, bullet: bool = False) -> list[str]:
    """Lines of at most 100 characters, as the README's prose (bullets with a hanging indent)."""
    return textwrap.wrap(text, 100, initial_indent="* " if bullet else "",
                         subsequent_indent="  " if bullet else "", break_long_words=False,
                         break_on_hyphens=False)



def fmt(x: float) -> str:
    return f"{x:.0f}" if x >= 100 else f"{x:.1f}"



def machine(m: dict[str, Any]) -> str:
    """``"<CPU>, <n> logical CPUs, <SIMD>"`` of the machine record."""
    simd = "AVX-512F" if "avx512f" in m.get("simd", []) else "/".join(m.get("simd", [])).upper()
    return f"{m['cpu_model']}, {m['logical_cpus']} logical CPUs, {simd or 'no AVX'}"



def run(data: dict[str, Any], e: dict[str, Any], what: str) -> str:
    """The sentence opening a section: what ran, the command, the machine, load and date."""
    quick = " (quick mode)" if "--quick" in e["command"] else ""
    return (f"{what} (`{e['command']}`{quick}; {machine(data['machine'])}; load average "
            f"{' '.join(map(str, e['load_average_at_start']))} at the start and "
            f"{' '.join(map(str, e['load_average_at_end']))} at the end; {e['date']}).")



def sig(x: float) -> str:
    """About three significant digits, without exponent (1234, 123, 12.3, 1.23, 0.123)."""
    return f"{x:.0f}" if x >= 100 else f"{x:.1f}" if x >= 10 else f"{x:.2f}" if x >= 1 else f"{x:.3f}"



def mm(s: dict[str, float]) -> tuple[str, str]:
    """Min and median cells."""
    return sig(s["min"]), sig(s["median"])



def x(r: dict[str, float], digits: int = 1) -> str:
    """``"min / median"`` of a ratio."""
    return f"{r['min']:.{digits}f}x / {r['median']:.{digits}f}x"



def and_list(items: list[str]) -> str:
    """``a``, ``a and b``, ``a, b and c``."""
    return items[0] if len(items) == 1 else f"{', '.join(items[:-1])} and {items[-1]}"


def table(header: list[str], rows: list[list[str]], text_last: bool = True) -> list[str]:
    """A Markdown table: first column left-aligned, the others right-aligned (but the last,
    with ``text_last``)."""
    align = ["---"] + ["---:"] * (len(header) - 1 - text_last) + ["---"] * text_last
    return ([f"| {' | '.join(header)} |", f"|{'|'.join(align)}|"]
            + [f"| {' | '.join(r)} |" for r in rows])
