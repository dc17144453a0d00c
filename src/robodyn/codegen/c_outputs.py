"""C99: how a kernel's outputs reach the caller's rows from the block core's buffers.

The core (:meth:`robodyn.codegen.c.CPrinter.block_function`) leaves a block's outputs
structure-of-arrays (entry i of state k at ``[BLOCK i + k]``); :func:`output_lines` writes the
lines that move them out. Outputs with constant entries are the interesting case.

The regressor of a 7-joint arm is 735 doubles per state, 60 % of them constant (zeros, and the
ones of the friction and offset columns). In a batch that fits the cache, each state's row is
written in place: the constants from a template, then the computed entries over them. In a
larger batch that costs twice over: every destination line is first read from memory, and the
5.9 kB per state evict what the computation needs.

For batches too large for the cache (:data:`STREAM_MIN_BYTES`) the output
is staged instead: a block of states is assembled in a buffer that holds the constants from the
start (they are written once per call, not once per state); the computed entries are placed
into it, and the block, which is contiguous in the caller's matrix, is copied out in one piece
with non-temporal stores (SSE2/AVX ``_mm_stream_pd``/``_mm256_stream_pd``, under ``#if``;
``memcpy`` elsewhere): the destination lines are not read first, and the stores leave the cache
to the computation. The values are the same bits either way; only how they reach memory differs.
"""

from __future__ import annotations

from collections.abc import Callable, Collection
from dataclasses import dataclass, field

import sympy as sp

from robodyn.codegen.kernels import Kernel

#: Outputs of this many entries per state (the regressor; the derivatives, 72 and 108 entries for
#: six joints), some constant and some computed, are staged for large batches
#: (:func:`staged_output`). The lower bound was 128 before 2026-12-06: staged, the PUMA 560's
#: forward-dynamics derivatives into a reused 100,000-state array took 462 against 499 ns per
#: state (same process pair, alternating; the streaming stores skip reading the destination).
STAGE_MIN, STAGE_MAX = 64, 2048

#: A batch whose staged outputs reach this many bytes is written with streaming (non-temporal)
#: stores: it would not stay in cache anyway, and the stores then skip reading each line first.
STREAM_MIN_BYTES = 32 << 20

#: Kernels whose range functions also count the blocks with a non-finite output, returned by
#: ``PREFIXk_batch_nonfinite``: those a singular mass matrix makes non-finite, each with the
#: entries of its one output checked, a function of the output's first dimension (None: all).
#: The caller looks for the singular state only when the count is not 0. Reading the outputs
#: back from memory instead cost 23 ns of 380 per state (the PUMA 560's forward-dynamics
#: derivatives, 10^5 states); checking all 102 computed entries in the block, 7-10 ns.
FINITE_CHECKED: dict[str, Callable[[int], list[int]] | None] = {
    "forward_dynamics": None,
    "state_derivative": None,
    # the diagonal of M^-1 (entries (i, 2 n + i) of the (n, 3 n) output): a singular M makes
    # some 1 / L_jj non-finite, and with it (M^-1)_kk for every k <= j
    "forward_dynamics_derivatives": lambda n: [i * 3 * n + 2 * n + i for i in range(n)],
}

_COPY_OUT = """\
#if defined(__AVX__)
#include <immintrin.h>
#elif defined(__SSE2__)
#include <emmintrin.h>
#endif
#include <stdint.h>
#include <string.h>

/* dst[i] = src[i] for i < n by non-temporal stores from the first 32-byte (AVX) or 16-byte
 * (SSE2) boundary of dst: whole lines written without being read first; PREFIXstream_fence
 * orders them before the caller reads. Without SSE2 (other processors), memcpy. */
static void PREFIXcopy_out(double *restrict dst, const double *restrict src, long n) {
#if defined(__AVX__) || defined(__SSE2__)
    long i = 0;
#if defined(__AVX__)
    for (; i < n && ((uintptr_t)(dst + i) & 31) != 0; ++i) dst[i] = src[i];
    for (; i + 4 <= n; i += 4) _mm256_stream_pd(dst + i, _mm256_loadu_pd(src + i));
#else
    for (; i < n && ((uintptr_t)(dst + i) & 15) != 0; ++i) dst[i] = src[i];
    for (; i + 2 <= n; i += 2) _mm_stream_pd(dst + i, _mm_loadu_pd(src + i));
#endif
    for (; i < n; ++i) dst[i] = src[i];
#else
    memcpy(dst, src, sizeof(double) * (size_t)n);
#endif
}

/* Orders the non-temporal stores before any later load or store. */
static void PREFIXstream_fence(void) {
#if defined(__AVX__) || defined(__SSE2__)
    _mm_sfence();
#endif
}
"""


def copy_out_source(prefix: str) -> str:
    """C source of ``PREFIXcopy_out(dst, src, n)`` and ``PREFIXstream_fence()``."""
    return _COPY_OUT.replace("PREFIX", prefix)


def staged_output(prefix: str, name: str, size: int, count: int, block: int,
                  template: str, index: str) -> tuple[list[str], list[str], list[str]]:
    """Lines of a ``_range`` function that stage output ``name`` (``size`` entries per state).

    Parameters
    ----------
    prefix : str
        Function prefix (``PREFIXcopy_out``).
    name : str
        The output array (the caller's rows, ``size`` per state).
    size, count, block : int
        Entries per state, computed entries per state, states per block.
    template, index : str
        Names of the static tables: the ``size`` constants, and the ``count`` computed positions.

    Returns
    -------
    declare, start, per_block : list of str
        The buffer's declaration, its filling with the constants (once per call), and per block:
        when ``stream_``, the placement of the core's structure-of-arrays output ``name_b_``
        into the buffer, then the streaming copy to ``name + size * k0_``; otherwise (a batch
        that fits the cache) each state's row written in place from the template, then its
        computed entries over it.
    """
    stage = f"{name}_stage_"
    declare = [f"{stage}[{block * size}]"]
    start = ["    if (stream_)",
             f"        for (int k_ = 0; k_ < {block}; ++k_)",
             f"            for (int i_ = 0; i_ < {size}; ++i_) {stage}[{size} * k_ + i_] = {template}[i_];"]
    per_block = ["        if (stream_) {",
                 f"            {prefix}scatter(m_, {size}, {count}, {index}, {name}_b_, {stage});",
                 f"            {prefix}copy_out({name} + {size} * k0_, {stage}, {size}L * m_);",
                 "        } else {",
                 "            for (int k_ = 0; k_ < m_; ++k_)",
                 f"                for (int i_ = 0; i_ < {size}; ++i_) "
                 f"{name}[{size} * (k0_ + k_) + i_] = {template}[i_];",
                 f"            {prefix}scatter(m_, {size}, {count}, {index}, {name}_b_, "
                 f"{name} + {size} * k0_);",
                 "        }"]
    return declare, start, per_block


@dataclass
class OutputLines:
    """C lines of a ``_range`` function that move a kernel's outputs to the caller's rows."""

    tables: list[str] = field(default_factory=list)  # static constant tables, before the function
    arrays: list[str] = field(default_factory=list)  # local buffers
    start: list[str] = field(default_factory=list)  # once per call
    fill: list[str] = field(default_factory=list)  # per block, before the core
    scatter: list[str] = field(default_factory=list)  # per state of a block, after the core
    per_block: list[str] = field(default_factory=list)  # per block, after the core
    staged_bytes: int = 0  # bytes per state of the staged outputs


def nonfinite_lines(kernel: Kernel, core: Kernel, computed: dict[str, list[int]],
                    block: int) -> list[str]:
    """C lines of a ``_range`` block, after the core, that add 1 to ``nonfinite_`` when an entry
    of :data:`FINITE_CHECKED` is not finite in one of the block's ``m_`` states: each lane sums
    ``x - x`` over the entries (0 for finite ``x``, NaN for infinities and NaN) in registers,
    on values still in the cache. The lanes past ``m_`` of a last, partial block are summed too
    (the buffer's values from an earlier block, or unset) and not looked at."""
    (a, o), = zip(kernel.outputs, core.outputs, strict=True)  # one output
    spec = FINITE_CHECKED[kernel.name]
    entries = list(range(a.size)) if spec is None else spec(a.shape[0])
    # each entry's row in the core's buffer (its computed entries only, when some are constant)
    rows = entries if o.size == a.size else [computed[a.name].index(e) for e in entries]
    add = f"for (int k_ = 0; k_ < {block}; ++k_) z_[k_] += {{v}} - {{v}};"
    if rows == list(range(o.size)):
        body = [f"            for (int i_ = 0; i_ < {o.size}; ++i_)",
                "                " + add.format(v=f"{o.name}_b_[{block} * i_ + k_]")]
    else:
        body = ["            " + add.format(v=f"{o.name}_b_[{block * r} + k_]") for r in rows]
    return ["        {", f"            double z_[{block}] = {{0.0}};", *body,
            "            for (int k_ = 0; k_ < m_; ++k_)",
            "                if (!(z_[k_] == 0.0)) { ++nonfinite_; break; }", "        }"]


def staged_outputs(kernel: Kernel, direct: Collection[str] = ()) -> list[str]:
    """Names of the outputs of ``kernel`` that its batch functions stage.

    Those of :data:`STAGE_MIN` to :data:`STAGE_MAX` entries per state, some of them constant and
    some computed, and not in ``direct`` (stored by the core itself).
    """
    staged = []
    for o in kernel.outputs:
        constant = sum(1 for e in o.entries if sp.sympify(e).is_Number)
        if STAGE_MIN <= o.size <= STAGE_MAX and 0 < constant < o.size and o.name not in direct:
            staged.append(o.name)
    return staged


def output_lines(prefix: str, expr: Callable[[sp.Expr], str], kernel: Kernel, core: Kernel,
                 computed: dict[str, list[int]], direct: dict[str, tuple[int, list[int]]],
                 block: int) -> OutputLines:
    """How each output of ``kernel`` reaches the caller's rows from the core's buffers.

    Four ways: stored by the core itself (``direct``); transposed back whole (every entry
    computed); staged (:func:`staged_output`); or, for smaller outputs with constant entries,
    each state's row written from a static template of the constants, then its computed entries
    over them. ``computed`` lists each output's computed entries; ``expr`` prints a constant.
    """
    lines = OutputLines()
    staged = staged_outputs(kernel, direct)
    for a, o in zip(kernel.outputs, core.outputs, strict=True):
        if a.name in direct and o.size == a.size:
            continue
        if o.size == a.size:
            lines.scatter.append(f"            for (int i_ = 0; i_ < {a.size}; ++i_) "
                                 f"{a.name}[{a.size} * j_ + i_] = {a.name}_b_[{block} * i_ + k_];")
            continue
        keep = list(range(a.size)) if a.name in direct else computed[a.name]
        stem = f"{prefix}{kernel.name}_{a.name}"
        template, index = f"{stem}_template_", f"{stem}_index_"
        values = [expr(sp.Float(e)) if sp.sympify(e).is_Number else "0.0" for e in a.entries]
        lines.tables.append(f"static const double {template}[{a.size}] = {{{', '.join(values)}}};")
        if a.name in direct:
            # the constants first; the core then stores the computed entries over them
            lines.fill += ["        for (int k_ = 0; k_ < m_; ++k_)",
                           f"            for (int i_ = 0; i_ < {a.size}; ++i_) "
                           f"{a.name}[{a.size} * (k0_ + k_) + i_] = {template}[i_];"]
            continue
        lines.tables.append(f"static const int {index}[{len(keep)}] = {{{', '.join(map(str, keep))}}};")
        if a.name in staged:
            declare, start, per_block = staged_output(prefix, a.name, a.size, len(keep), block,
                                                      template, index)
            lines.arrays += declare
            lines.start += start
            lines.per_block += per_block
            lines.staged_bytes += 8 * a.size
            continue
        # the constants from a template, then the computed entries over them
        lines.scatter += [f"            double *restrict row_ = {a.name} + {a.size} * j_;",
                          f"            for (int i_ = 0; i_ < {a.size}; ++i_) row_[i_] = {template}[i_];",
                          f"            for (int i_ = 0; i_ < {len(keep)}; ++i_) row_[{index}[i_]] = "
                          f"{a.name}_b_[{block} * i_ + k_];"]
    if lines.tables:
        lines.tables = [f"/* {kernel.name}: constant entries of its outputs, and the computed ones' "
                        "positions. */", *lines.tables, ""]
    return lines
