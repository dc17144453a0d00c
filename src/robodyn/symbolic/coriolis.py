"""Coriolis/centrifugal matrix from the Christoffel symbols of the inertia matrix.

``C_ij = sum_k c_ijk qd_k`` with ``c_ijk = (dM_ij/dq_k + dM_ik/dq_j - dM_jk/dq_i) / 2``; with this
choice ``dM/dt - 2 C`` is skew-symmetric.
"""

from __future__ import annotations

from collections.abc import Sequence

import sympy as sp


def christoffel_coriolis(m: sp.MatrixBase, q: Sequence[sp.Symbol],
                         qd: Sequence[sp.Symbol]) -> sp.ImmutableMatrix:
    """Coriolis matrix ``C(q, qd)`` of inertia matrix ``m`` (n, n), shape (n, n)."""
    n = len(q)
    # dM[k][i, j] = dM_ij / dq_k, computed once for the upper triangle
    dm: list[dict[tuple[int, int], sp.Expr]] = []
    for k in range(n):
        dk = {}
        for i in range(n):
            for j in range(i, n):
                dk[(i, j)] = sp.diff(m[i, j], q[k])
        dm.append(dk)

    def d(k: int, i: int, j: int) -> sp.Expr:
        return dm[k][(i, j) if i <= j else (j, i)]

    c = sp.zeros(n, n)
    for i in range(n):
        for j in range(n):
            # C_ij = sum_k (dM_ij/dq_k + dM_ik/dq_j - dM_jk/dq_i) qd_k / 2
            c[i, j] = sum(
                ((d(k, i, j) + d(j, i, k) - d(i, j, k)) / 2 * qd[k] for k in range(n)),
                sp.Integer(0),
            )
    return sp.ImmutableMatrix(c)


def time_derivative(expr: sp.MatrixBase, q: Sequence[sp.Symbol], qd: Sequence[sp.Symbol],
                    qdd: Sequence[sp.Symbol] | None = None) -> sp.ImmutableMatrix:
    """``d/dt`` of an expression in ``q`` (and ``qd`` when ``qdd`` is given) along a motion."""
    out = sp.zeros(*expr.shape)
    for qk, qdk in zip(q, qd, strict=True):
        out += expr.diff(qk) * qdk
    if qdd is not None:
        for qdk, qddk in zip(qd, qdd, strict=True):
            out += expr.diff(qdk) * qddk
    return sp.ImmutableMatrix(out)
