"""Coriolis/centrifugal matrix from the Christoffel symbols of the inertia matrix.

``C_ij = sum_k c_ijk qd_k`` with ``c_ijk = (dM_ij/dq_k + dM_ik/dq_j - dM_jk/dq_i) / 2``; with this
choice ``dM/dt - 2 C`` is skew-symmetric.
"""

from __future__ import annotations

from collections.abc import Sequence

import sympy as sp

from robodyn.symbolic.program import Program, Recorder


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


def program_derivative(program: Program, var: sp.Symbol, rec: Recorder) -> sp.ImmutableMatrix:
    """Forward-mode derivative of a program's outputs with respect to ``var``.

    Each assignment ``s = e`` gets a derivative ``ds = sum_a de/da * da`` over the symbols ``a``
    of ``e`` that depend on ``var``; new intermediates go into ``rec``. Returns the derivative of
    the outputs (same shape), in terms of the program's and ``rec``'s symbols.
    """
    deriv: dict[sp.Symbol, sp.Expr] = {var: sp.Integer(1)}
    for sym, expr in program.assignments:
        # ds/dvar = sum_a (de/da) (da/dvar)
        terms = [expr.diff(a) * deriv[a] for a in expr.free_symbols if a in deriv]
        total = sp.Add(*terms)
        if total != 0:
            deriv[sym] = rec.scalar(total, f"d{sym.name}_d{var.name}")

    def d_out(e: sp.Expr) -> sp.Expr:
        return sp.Add(*[e.diff(a) * deriv[a] for a in e.free_symbols if a in deriv])

    return sp.ImmutableMatrix(program.outputs.applyfunc(d_out))


def christoffel_program(m_prog: Program, q: Sequence[sp.Symbol],
                        qd: Sequence[sp.Symbol]) -> Program:
    """Christoffel-form ``C(q, qd)`` from a recursive inertia-matrix program, as a program."""
    rec = Recorder({s.name for s, _ in m_prog.assignments})
    n = len(q)
    dm = [program_derivative(m_prog, qk, rec) for qk in q]
    c = sp.zeros(n, n)
    for i in range(n):
        for j in range(n):
            # C_ij = sum_k (dM_ij/dq_k + dM_ik/dq_j - dM_jk/dq_i) qd_k / 2
            c[i, j] = sp.Add(*[(dm[k][i, j] + dm[j][i, k] - dm[i][j, k]) / 2 * qd[k]
                               for k in range(n)])
    return Program(tuple(m_prog.assignments) + tuple(rec.assignments),
                   sp.ImmutableMatrix(c)).pruned()
