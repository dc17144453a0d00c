"""The block width of the generated C kernels, chosen for the processor they are built on.

The batch kernels evaluate :data:`robodyn.codegen.c.BLOCK` states at a time, structure-of-arrays,
so that one loop over the block becomes vector instructions. The width that fills the vector
registers depends on the processor: with AVX-512 (8 doubles per register) 16 states, two
registers per quantity; with AVX2 (4 doubles) 16 states too, four registers per quantity;
narrower (2 doubles, or none known) 8 states. Measured on an AVX-512
Xeon (2 cores, shared with other jobs; PUMA 560, 10^5 states, ns per state, min of 7), the code
built for AVX-512 (``-march=native``) and for AVX2 (``-march=haswell``) at each width:

=========  =================  ==================
width      AVX-512 ID / FD    AVX2 ID / FD
=========  =================  ==================
4          29.9 / 91.7        34.1-35.3 / 57-58
8          28.9-30.9 / 49-88  34.4-35.1 / 56-59
16         31.5-33.6 / 49-94  37.7-38.4 / 56-58
32         45.7 / 91.3        40.7 / 56.9
=========  =================  ==================

(the spread within a cell is the machine's load: runs of the same build differed by up to 2x in
forward dynamics). Wider than 16 is slower everywhere; between 8 and 16 the difference is
within that noise on AVX-512 and about 8 % in favour of 8 for AVX2's inverse dynamics.
``benchmarks/bench_block_width.py`` repeats the sweep on the machine it runs on (the README's
``results:block_width`` section); on an AMD EPYC with AVX-512 (2 shared cores), two runs put
width 16 within 0-15 % of the fastest width (8 or 16) for both kernels, and every width from 4
up 2-3x faster than scalar code: not a difference that would justify another rule. AVX2 had 8
until 2026-12-06, when the inputs' transposition by shuffles (:mod:`robodyn.codegen.c_transpose`)
and the scheduled statement order (:mod:`robodyn.codegen.schedule`) made 16 the fastest on the
AMD EPYC with AVX2 (``bench_block_width.py``, PUMA 560, ns per state, min of 12, native code:
ID 38.5 / 38.1 / 34.4 / 36.9 and FD 69.8 / 69.3 / 66.7 / 69.8 at widths 4 / 8 / 16 / 32; the
Gen3 through ``Model``: ID 77 -> 70, FD 183 -> 174, mass matrix 146 -> 121, FD derivatives
1132 -> 1162). Before those changes 16 was already within 1 % of 8 there. The
environment variable ``ROBODYN_BLOCK`` (1, 2, 4, 8, 16 or 32) overrides the choice: 1 gives
scalar code (one state per loop), which the CI runs the kernel tests with too. The width is
part of the generated source, so each width has its own entry in the compiled-model cache.
"""

from __future__ import annotations

import os
from pathlib import Path

from robodyn.robot.errors import InputError

__all__ = ["BLOCK", "WIDTHS", "block_width", "cpu_flags", "default_block_width", "vector_flags"]

#: Block widths the generator accepts.
WIDTHS = (1, 2, 4, 8, 16, 32)


def cpu_flags() -> frozenset[str]:
    """The processor's feature flags (``/proc/cpuinfo``; empty where there is none)."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith(("flags", "Features")):
                return frozenset(line.split(":", 1)[1].split())
    except OSError:
        pass
    return frozenset()


def block_width() -> int:
    """States per block: ``ROBODYN_BLOCK`` when set, else 16 with AVX-512 or AVX2 and 8 otherwise.

    Raises
    ------
    InputError
        ``ROBODYN_BLOCK`` is not one of :data:`WIDTHS`.
    """
    text = os.environ.get("ROBODYN_BLOCK", "").strip()
    if text:
        if text not in {str(w) for w in WIDTHS}:
            raise InputError(f"ROBODYN_BLOCK={text!r}: the block width of the generated kernels "
                             f"must be one of {', '.join(map(str, WIDTHS))} (1: scalar code)")
        return int(text)
    return default_block_width()


def default_block_width(flags: frozenset[str] | None = None) -> int:
    """The width for a processor with feature ``flags`` (default: this one's): 16 with AVX-512
    or AVX2 (two 8-double or four 4-double registers per quantity), else 8."""
    flags = cpu_flags() if flags is None else flags
    return 16 if "avx512f" in flags or "avx2" in flags else 8


def vector_flags(flags: frozenset[str] | None = None) -> tuple[str, ...]:
    """Compiler flags for the vector width of a processor with feature ``flags`` (default: this
    one's): ``-mprefer-vector-width=256`` with AVX2 and without AVX-512, else none.

    ``-march=native`` also picks the tuning of the processor the compiler recognises. An AMD
    EPYC that reports family 23 model 1 (Zen 1; peak FP64 measured at 21.5 GFLOP/s on one
    core, 8 flops per cycle) is tuned by GCC 12 as ``znver1``: 128-bit vectors preferred, as
    Zen 1 splits 256-bit operations in two. On that machine (2 cores, PUMA 560, 10^5 states,
    the two builds timed in turns) the 256-bit build still took 12-18 % less time for forward
    dynamics and its derivatives and about 5 % less for inverse dynamics (fewer instructions
    for the same work); processors that run 256-bit operations at full width gain more.
    """
    flags = cpu_flags() if flags is None else flags
    return ("-mprefer-vector-width=256",) if "avx2" in flags and "avx512f" not in flags else ()


#: States per block of the generated batch functions in this process (:func:`block_width` at
#: import): one vector loop evaluates a block's sines and cosines.
BLOCK = block_width()
