"""The stacked identification matrix ``W`` (N n, p): the batched compiled regressor, chunked.

``W[k n + i, :] = Y(q_k, qd_k, qdd_k)[i, columns]``: one row per joint ``i`` per sample ``k``
(sample-major). With all columns the batched kernel writes ``W`` itself in one call: its
(N, n, 15 n) output is ``W`` in memory, reshaped without a copy; the generated kernel writes
the regressor's constant entries (its structural zeros, 446 of 735 for the Gen3) from a static
template and passes only the computed ones through its block buffer, and ``out=`` lets repeated
stacking reuse one matrix (no new allocation, no page faults on first touch). With a column
selection the regressor is evaluated in chunks of ``CHUNK`` samples, each chunk's kept columns
copied into one preallocated matrix, so that stacking 100,000 samples of a 7-joint arm does not
first build a second full-size temporary.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from robodyn.numeric.model import Model
from robodyn.robot.errors import InputError

__all__ = ["CHUNK", "identification_matrix", "regressor_rows_of"]

CHUNK = 4096


def identification_matrix(model: Model, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray,
                          columns: Sequence[int] | None = None, *, threads: int = 1,
                          out: np.ndarray | None = None) -> np.ndarray:
    """Stacked regressor.

    Parameters
    ----------
    model : Model
        ``rd.compile_model(robot)``.
    q, qd, qdd : numpy.ndarray, shape (N, n)
        rad, rad/s, rad/s^2 (m, m/s, m/s^2 for prismatic joints).
    columns : sequence of int, optional
        Regressor columns to keep (default all ``15 n``).
    threads : int
        Threads of the batched kernel (C backend with OpenMP; the result does not depend on it).
    out : numpy.ndarray, shape (N n, p), optional
        C-contiguous float64 matrix to write ``W`` into (returned): reuse it across calls.

    Returns
    -------
    numpy.ndarray, shape (N n, p)
    """
    q, qd, qdd = (np.atleast_2d(np.asarray(a, dtype=float)) for a in (q, qd, qdd))
    count, n = q.shape
    if columns is None:
        # (N, n, 15 n) C-order is (N n, 15 n): a view, not a copy
        if out is not None and out.shape != (count * n, 15 * n):
            raise InputError(f"identification_matrix(out=...): expected shape {(count * n, 15 * n)}, "
                             f"got {out.shape}")
        return model.regressor(q, qd, qdd, threads=threads, out=out).reshape(count * n, -1)
    cols = np.asarray(columns, dtype=int)
    if out is None:
        out = np.empty((count * n, cols.size))
    elif (not isinstance(out, np.ndarray) or out.shape != (count * n, cols.size)
          or out.dtype != np.float64 or not out.flags.writeable):
        raise InputError(f"identification_matrix(out=...): expected a writeable float64 array of "
                         f"shape {(count * n, cols.size)}, got "
                         f"{getattr(out, 'shape', type(out).__name__)}")
    for start in range(0, count, CHUNK):
        stop = min(start + CHUNK, count)
        y = model.regressor(q[start:stop], qd[start:stop], qdd[start:stop], threads=threads)
        out[start * n:stop * n] = y.reshape((stop - start) * n, -1)[:, cols]
    return out


def regressor_rows_of(model: Model, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray,
                      out: np.ndarray | None = None) -> np.ndarray:
    """The full stacked regressor as one block per sample, shape (N, n, 15 n).

    :func:`identification_matrix` with every column (the path ``benchmarks/bench_identify.py``
    times), viewed per sample: what :func:`robodyn.identification` filters and fits. ``out``
    (N, n, 15 n), C-contiguous float64: written and returned (reuse it across calls).
    """
    q = np.atleast_2d(np.asarray(q, dtype=float))
    count, n = q.shape
    flat = None
    if out is not None:
        if not (isinstance(out, np.ndarray) and out.shape == (count, n, 15 * n) and out.flags.c_contiguous):
            raise InputError(f"regressor_rows_of(out=...): expected a C-contiguous array of shape "
                             f"{(count, n, 15 * n)}, got {getattr(out, 'shape', type(out).__name__)}")
        flat = out.reshape(count * n, 15 * n)  # a view: C-contiguous
    return identification_matrix(model, q, qd, qdd, out=flat).reshape(count, n, -1)
