"""C source of the transpositions between a block's rows and its structure-of-arrays buffers.

The batch kernels (:mod:`robodyn.codegen.c`) take states stored one after another (row k of an
input at ``[size k + i]``) and evaluate a block of :data:`~robodyn.codegen.cpu.BLOCK` of them
from buffers that hold entry i of every state together (``[BLOCK i + k]``). Copied one double at
a time, the buffers are written by scalar stores that the core then reads by vector loads: a
load that spans several smaller earlier stores cannot take its value from them while they are
in flight, and waits until they reach the cache. With AVX, ``PREFIXgather`` moves a full block
by 4 x 4 transpositions instead: four rows' unaligned 4-double loads, two unpacks and two
lane permutations per pair of output vectors, and 4-double stores (columns 4 at a time, the last
group overlapping the one before when ``size`` is not a multiple of 4, so any ``size >= 4``).
Loads, shuffles and stores only: every value is copied bit for bit. The function is not
inlined: measured on the AMD EPYC with AVX2 (2026-12-06, 8 states per block, Kinova Gen3 inverse
dynamics, 5 10^4 states, six builds whose code layouts differ by alignment and OpenMP flags),
inlined it ran 73.6-83.4 ns per state, called 71.8-81.0 (median 82.9 and 72.6; PUMA 560: 36.1
and 37.2).

``PREFIXscatter`` is the way back for outputs with constant entries (the derivatives, the
regressor): the computed entries, listed by their positions in the row, go from the buffers into
rows that already hold the constants. Where four computed entries sit side by side in the row,
a full block moves them by the same 4 x 4 transpositions; the others one double at a time.
Measured on the AMD EPYC with AVX2 (2026-12-06, PUMA 560 forward-dynamics derivatives, 102 of
108 entries computed, 10^5 states into a reused array through ``Model``, min of 10 calls, two
processes one after the other): 440 -> 427 ns per state, the same bits.
"""

from __future__ import annotations

__all__ = ["VECTOR", "gather_source", "scatter_source"]

#: Whether the AVX path is generated (False: one double at a time everywhere; kept for
#: ``benchmarks/bench_schedule.py``, which compares the two).
VECTOR = True

_GATHER = """\
#if defined(__AVX__)
#include <immintrin.h>
#endif

/* xb[BLOCK i + k] = x[size k + i] for k < m, i < size: a block's rows into structure-of-arrays
 * buffers. A full block of at least 4 columns with AVX: 4 x 4 transpositions (the last group
 * of columns overlaps the one before); otherwise one double at a time. Not inlined: a copy
 * in every kernel's loop made the Gen3's inverse dynamics slower in some code layouts. */
#if defined(__GNUC__)
__attribute__((noinline))
#endif
static void PREFIXgather(int m, int size, const double *restrict x, double *restrict xb) {
#if defined(__AVX__)
    if (m == BLOCK && BLOCK % 4 == 0 && size >= 4) {
        for (int k = 0; k < BLOCK; k += 4) {
            const double *restrict r = x + (long)size * k;
            for (int i = 0; i < size; i += 4) {
                const int c = i + 4 <= size ? i : size - 4;
                const __m256d a = _mm256_loadu_pd(r + c), b = _mm256_loadu_pd(r + size + c);
                const __m256d e = _mm256_loadu_pd(r + 2 * size + c);
                const __m256d f = _mm256_loadu_pd(r + 3 * size + c);
                /* (a0 b0 a2 b2), (a1 b1 a3 b3), (e0 f0 e2 f2), (e1 f1 e3 f3) */
                const __m256d lo = _mm256_unpacklo_pd(a, b), hi = _mm256_unpackhi_pd(a, b);
                const __m256d lo2 = _mm256_unpacklo_pd(e, f), hi2 = _mm256_unpackhi_pd(e, f);
                _mm256_storeu_pd(xb + BLOCK * c + k, _mm256_permute2f128_pd(lo, lo2, 0x20));
                _mm256_storeu_pd(xb + BLOCK * (c + 1) + k, _mm256_permute2f128_pd(hi, hi2, 0x20));
                _mm256_storeu_pd(xb + BLOCK * (c + 2) + k, _mm256_permute2f128_pd(lo, lo2, 0x31));
                _mm256_storeu_pd(xb + BLOCK * (c + 3) + k, _mm256_permute2f128_pd(hi, hi2, 0x31));
            }
        }
        return;
    }
#endif
    for (int k = 0; k < m; ++k)
        for (int i = 0; i < size; ++i) xb[BLOCK * i + k] = x[(long)size * k + i];
}
"""


_SCATTER = """\
#if defined(__AVX__)
#include <immintrin.h>
#endif

/* row[size k + index[i]] = b[BLOCK i + k] for k < m, i < count (index increasing): a block's
 * computed entries into its rows. A full block with AVX: runs of four consecutive positions by
 * 4 x 4 transpositions; otherwise one double at a time. */
static void PREFIXscatter(int m, int size, int count, const int *restrict index,
                          const double *restrict b, double *restrict row) {
    int i = 0;
#if defined(__AVX__)
    if (m == BLOCK && BLOCK % 4 == 0) {
        while (i + 4 <= count) {
            const int p = index[i];
            if (index[i + 1] != p + 1 || index[i + 2] != p + 2 || index[i + 3] != p + 3) {
                for (int k = 0; k < BLOCK; ++k) row[(long)size * k + p] = b[BLOCK * i + k];
                ++i;
                continue;
            }
            for (int k = 0; k < BLOCK; k += 4) {
                const double *restrict c = b + BLOCK * i + k;
                const __m256d a = _mm256_loadu_pd(c), d = _mm256_loadu_pd(c + BLOCK);
                const __m256d e = _mm256_loadu_pd(c + 2 * BLOCK);
                const __m256d f = _mm256_loadu_pd(c + 3 * BLOCK);
                const __m256d lo = _mm256_unpacklo_pd(a, d), hi = _mm256_unpackhi_pd(a, d);
                const __m256d lo2 = _mm256_unpacklo_pd(e, f), hi2 = _mm256_unpackhi_pd(e, f);
                double *restrict r = row + (long)size * k + p;
                _mm256_storeu_pd(r, _mm256_permute2f128_pd(lo, lo2, 0x20));
                _mm256_storeu_pd(r + size, _mm256_permute2f128_pd(hi, hi2, 0x20));
                _mm256_storeu_pd(r + 2 * size, _mm256_permute2f128_pd(lo, lo2, 0x31));
                _mm256_storeu_pd(r + 3 * size, _mm256_permute2f128_pd(hi, hi2, 0x31));
            }
            i += 4;
        }
    }
#endif
    for (; i < count; ++i)
        for (int k = 0; k < m; ++k) row[(long)size * k + index[i]] = b[BLOCK * i + k];
}
"""


def scatter_source(prefix: str, block: int) -> str:
    """C source of ``static void PREFIXscatter(m, size, count, index, b, row)`` for blocks of
    ``block`` states."""
    text = _SCATTER if VECTOR else _SCATTER.replace("#if defined(__AVX__)\n    if", "#if 0\n    if")
    return text.replace("PREFIX", prefix).replace("BLOCK", str(block))


def gather_source(prefix: str, block: int) -> str:
    """C source of ``static void PREFIXgather(m, size, x, xb)`` for blocks of ``block`` states."""
    text = _GATHER if VECTOR else _GATHER.replace("#if defined(__AVX__)\n    if", "#if 0\n    if")
    return text.replace("PREFIX", prefix).replace("BLOCK", str(block))
