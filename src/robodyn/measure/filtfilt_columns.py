"""Zero-phase filtering of many columns of a row-major matrix at once (compiled).

``scipy.signal.sosfiltfilt`` runs the recursion of a cascade of second-order sections one signal
at a time: each output waits on the one before it (a chain of dependent multiply-adds), so a
wide matrix, such as the hundreds of columns of a stacked regressor, costs about 6 ns per
sample, section and pass on a 2020s core, plus the copies that bring each column together in
memory. :func:`filtfilt_columns` runs the same recursion (transposed direct form II, the form
``sosfilt`` uses) on a block of columns side by side: at each sample the columns' states are
updated by one vector loop, so the recursion's latency is shared by the whole block, and the
matrix is read and written row by row where it lies. It computes what ``sosfiltfilt`` computes
(odd extension by ``padlen`` samples at both ends, the steady state of the first and last value
as initial conditions, a forward and a backward pass): the same arithmetic but for the
rounding of fused multiply-adds, so the results agree to about 1e-14 of the signal's scale
(``tests/measure/test_filtfilt_columns.py`` checks them against SciPy). Each column's result
does not depend on which other columns it is filtered with.

The kernel is a small fixed C source compiled once per processor into robodyn's cache
(:func:`robodyn.codegen.build.compile_library`). Without a C compiler (and no library built
before), or when it fails to build (a warning says so), :func:`filtfilt_columns` uses
``sosfiltfilt`` itself, a block of columns at a time.
"""

from __future__ import annotations

import functools
import warnings
from typing import Any

import numpy as np
from scipy import signal

from robodyn.codegen.build import CompilerNotFoundError, compile_library

__all__ = ["COLUMN_BLOCK", "filtfilt_columns"]

#: Columns filtered side by side in one call of the kernel (their padded copy is
#: ``8 COLUMN_BLOCK (N + 2 padlen)`` bytes).
COLUMN_BLOCK = 32

_DECLARATIONS = """
void rd_filtfilt_columns(int sections, const double *sos, const double *zi, int64_t count,
                         int64_t pad, const double *x, int64_t ldx, int64_t width,
                         const int64_t *cols, int64_t keep, double *out, int64_t ldo,
                         double *buf, double *z);
"""

_SOURCE = r"""
#include <stdint.h>

/* One pass of the cascade over `rows` rows of `width` columns, in place: row r at
   data + r * step (step < 0: backward). Transposed direct form II per section (scipy's sosfilt):
   y = b0 x + z0; z0 = b1 x - a1 y + z1; z1 = b2 x - a2 y. z: (sections, 2, width). */
static void rd_pass(int sections, const double *sos, int64_t rows, int64_t step, int64_t width,
                    double *data, double *restrict z) {
    for (int64_t r = 0; r < rows; ++r) {
        double *restrict row = data + r * step;
        for (int s = 0; s < sections; ++s) {
            const double b0 = sos[6 * s], b1 = sos[6 * s + 1], b2 = sos[6 * s + 2];
            const double a1 = sos[6 * s + 4], a2 = sos[6 * s + 5];
            double *restrict z0 = z + 2 * s * width;
            double *restrict z1 = z0 + width;
            for (int64_t j = 0; j < width; ++j) {
                const double in = row[j];
                const double y = b0 * in + z0[j];
                z0[j] = b1 * in - a1 * y + z1[j];
                z1[j] = b2 * in - a2 * y;
                row[j] = y;
            }
        }
    }
}

/* The cascade's state: zi (sections, 2) times each column's value in row `row`. */
static void rd_steady(int sections, const double *zi, int64_t width, const double *row,
                      double *restrict z) {
    for (int k = 0; k < 2 * sections; ++k)
        for (int64_t j = 0; j < width; ++j) z[k * width + j] = zi[k] * row[j];
}

/* sosfiltfilt of columns cols[0..width) of x (count rows, ldx apart) with odd extension by
   pad rows; every keep-th output row i / keep written to out[(i / keep) ldo + cols[j]].
   buf: (count + 2 pad, width) scratch; z: (sections, 2, width) scratch. */
void rd_filtfilt_columns(int sections, const double *sos, const double *zi, int64_t count,
                         int64_t pad, const double *x, int64_t ldx, int64_t width,
                         const int64_t *cols, int64_t keep, double *out, int64_t ldo,
                         double *buf, double *z) {
    const int64_t total = count + 2 * pad;
    for (int64_t r = 0; r < pad; ++r)  /* left: 2 x[0] - x[pad - r] */
        for (int64_t j = 0; j < width; ++j)
            buf[r * width + j] = 2.0 * x[cols[j]] - x[(pad - r) * ldx + cols[j]];
    for (int64_t i = 0; i < count; ++i)
        for (int64_t j = 0; j < width; ++j) buf[(pad + i) * width + j] = x[i * ldx + cols[j]];
    for (int64_t r = 0; r < pad; ++r)  /* right: 2 x[N - 1] - x[N - 2 - r] */
        for (int64_t j = 0; j < width; ++j)
            buf[(pad + count + r) * width + j] =
                2.0 * x[(count - 1) * ldx + cols[j]] - x[(count - 2 - r) * ldx + cols[j]];
    rd_steady(sections, zi, width, buf, z);
    rd_pass(sections, sos, total, width, width, buf, z);
    rd_steady(sections, zi, width, buf + (total - 1) * width, z);
    /* backward down to the first kept row (the left extension's outputs are dropped) */
    rd_pass(sections, sos, total - pad, -width, width, buf + (total - 1) * width, z);
    for (int64_t i = 0; i < count; i += keep)
        for (int64_t j = 0; j < width; ++j)
            out[(i / keep) * ldo + cols[j]] = buf[(pad + i) * width + j];
}
"""


@functools.cache
def _library() -> Any | None:
    """The compiled kernel, or None without a C compiler (or when compiling fails: warned)."""
    try:
        return compile_library(_SOURCE, _DECLARATIONS)
    except CompilerNotFoundError:
        return None
    except (RuntimeError, OSError) as exc:
        warnings.warn(f"filtering with scipy.signal.sosfiltfilt: the compiled filter did not "
                      f"build ({str(exc)[:200]})", RuntimeWarning, stacklevel=3)
        return None


def filtfilt_columns(sos: np.ndarray, padlen: int, x: np.ndarray, columns: np.ndarray,
                     out: np.ndarray, keep: int = 1) -> np.ndarray:
    """``scipy.signal.sosfiltfilt`` of some columns of ``x`` along axis 0, into ``out``.

    Parameters
    ----------
    sos : (S, 6) ndarray
        Second-order sections (``a0 = 1``), e.g. from ``scipy.signal.butter(..., output="sos")``.
    padlen : int
        Samples of odd extension at each end, ``0 <= padlen < N``.
    x : (N, c) ndarray
        Signals in its columns, float64 with unit stride along a row; not modified.
    columns : (k,) ndarray of int
        The columns of ``x`` to filter.
    out : (ceil(N / keep), c) ndarray
        Float64, C-contiguous: its ``columns`` receive every ``keep``-th filtered sample, the
        others are left as they are.
    keep : int
        Keep every ``keep``-th filtered sample.

    Returns
    -------
    (ceil(N / keep), c) ndarray
        ``out``.
    """
    count = x.shape[0]
    columns = np.ascontiguousarray(columns, dtype=np.int64)
    lib = _library()
    if lib is None or count < 2:
        for a in range(0, columns.size, COLUMN_BLOCK):
            cols = columns[a:a + COLUMN_BLOCK]
            block = np.ascontiguousarray(x[:, cols].T)
            out[:, cols] = signal.sosfiltfilt(sos, block, axis=-1, padlen=padlen).T[::keep]
        return out
    if not _rows(x):
        x = np.ascontiguousarray(x, dtype=np.float64)
    if not _rows(out):
        raise ValueError(f"filtfilt_columns: out must be float64 with unit column stride, got "
                         f"{out.dtype} with strides {out.strides}")
    sos = np.ascontiguousarray(sos, dtype=np.float64)
    zi = np.ascontiguousarray(signal.sosfilt_zi(sos))
    width = min(COLUMN_BLOCK, max(columns.size, 1))
    buf = np.empty((count + 2 * padlen) * width)
    z = np.empty(zi.size * width)
    ffi, c = lib.ffi, lib.lib
    # the first element of each view (x and out may be views of larger arrays)
    px = ffi.cast("const double *", x.ctypes.data)
    po = ffi.cast("double *", out.ctypes.data)
    for a in range(0, columns.size, width):
        cols = columns[a:a + width]
        c.rd_filtfilt_columns(sos.shape[0], ffi.from_buffer("double[]", sos),
                              ffi.from_buffer("double[]", zi), count, padlen, px,
                              x.strides[0] // 8, cols.size,
                              ffi.cast("const int64_t *", cols.ctypes.data), keep, po,
                              out.strides[0] // 8, ffi.from_buffer("double[]", buf),
                              ffi.from_buffer("double[]", z))
    return out


def _rows(x: np.ndarray) -> bool:
    """True when ``x`` is a float64 matrix with unit column stride and rows evenly spaced
    forward in memory (what the kernel addresses)."""
    return (x.dtype == np.float64 and x.ndim == 2 and x.strides[1] == 8 and x.strides[0] > 0
            and x.strides[0] % 8 == 0)
