"""Base parameters: the identifiable linear combinations of the standard parameters.

Gautier's numerical method (Gautier 1991): the full regressor ``W`` (15 n columns, see
:mod:`robodyn.symbolic.regressor`) is stacked over random states; QR with column pivoting of the
unit-norm columns gives its rank ``b`` and a permutation that puts ``b`` independent columns
first::

    W P = Q [R1 R2],   W_d = W_b beta,   beta = R1^-1 R2

so that ``W p = W_b (p_b + beta p_d)``: each base parameter is one independent standard parameter
plus the dependent ones it absorbs with coefficients ``beta``. The coefficients are constants of
the geometry (lengths, squared lengths, signs); they are snapped to simple rationals where they
are within 1e-9 of one and rounded to 10 significant digits otherwise, for display
(:attr:`BaseRelations.expressions`); the numerical ``beta`` itself is kept exactly.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg
import sympy as sp

from robodyn.numeric.model import Model
from robodyn.symbolic.regressor import parameter_names

__all__ = ["BaseRelations", "base_relations", "random_states"]

#: Rank tolerance: a pivot ``|R_kk| <= RANK_RTOL |R_00|`` (unit-norm columns) is dependent.
RANK_RTOL = 1e-8
#: Coefficients below this (relative to 1) are exact zeros.
BETA_ZERO = 1e-10
#: Relative preference for the earlier of two columns whose remaining norms tie (exactly
#: collinear columns, such as the first joint's ``ZZ`` and its rotor inertia ``Ia``): above the
#: error of LAPACK's downdated column norms (up to about 1e-8 relative, where it recomputes them),
#: far below any real difference of independence (:func:`pivoted_columns`).
TIE_PREFERENCE = 1e-6
#: Fraction of the random joint velocities set exactly to zero (see :func:`random_states`).
ZERO_VELOCITY_FRACTION = 0.2


@dataclass(frozen=True, eq=False)
class BaseRelations:
    """How the ``b`` base parameters combine the ``15 n`` standard ones.

    Attributes
    ----------
    standard_names : tuple of str, length 15 n
        Standard parameter names, regressor column order.
    independent : numpy.ndarray of int, shape (b,)
        Column index of the standard parameter each base parameter is named after (sorted).
    dependent : numpy.ndarray of int, shape (d,)
        Columns that are combinations of the independent ones (including all-zero columns).
    beta : numpy.ndarray, shape (b, d)
        ``W[:, dependent] = W[:, independent] @ beta``.
    zero : numpy.ndarray of int
        Columns that are identically zero (parameters that never act: e.g. XX1 about a fixed
        vertical axis); they are part of ``dependent`` with zero coefficients.
    """

    standard_names: tuple[str, ...]
    independent: np.ndarray
    dependent: np.ndarray
    beta: np.ndarray
    zero: np.ndarray

    @property
    def names(self) -> tuple[str, ...]:
        """Base parameter names: the independent standard parameter's name with suffix ``R``
        when it absorbs others (Khalil's regrouped-parameter notation), else its own name."""
        out = []
        for i, col in enumerate(self.independent):
            grouped = np.any(np.abs(self.beta[i]) > BETA_ZERO)
            out.append(self.standard_names[col] + ("R" if grouped else ""))
        return tuple(out)

    @property
    def matrix(self) -> np.ndarray:
        """``K`` (b, 15 n) with ``p_base = K @ p_standard``."""
        k = np.zeros((self.independent.size, len(self.standard_names)))
        k[np.arange(self.independent.size), self.independent] = 1.0
        k[:, self.dependent] = self.beta
        return k

    def to_base(self, standard: np.ndarray) -> np.ndarray:
        """Base parameter values (b,) of a standard parameter vector (15 n,)."""
        return self.matrix @ np.asarray(standard, dtype=float)

    @property
    def expressions(self) -> tuple[sp.Expr, ...]:
        """Each base parameter as a SymPy expression in the standard parameter symbols."""
        syms = [sp.Symbol(name, real=True) for name in self.standard_names]
        out = []
        for i, col in enumerate(self.independent):
            expr = syms[col]
            for k, dcol in enumerate(self.dependent):
                c = _nice(self.beta[i, k])
                if c != 0:
                    expr += c * syms[dcol]
            out.append(expr)
        return tuple(out)


def _nice(value: float) -> sp.Expr:
    """A display coefficient: 0, a simple rational within 1e-9, or 10 significant digits."""
    if abs(value) <= BETA_ZERO:
        return sp.Integer(0)
    frac = sp.nsimplify(value, rational=True, tolerance=1e-9 * max(1.0, abs(value)))
    if isinstance(frac, sp.Rational) and frac.q <= 1000:
        return frac
    return sp.Float(float(f"{value:.10g}"), 10)


def random_states(model: Model, samples: int, rng: np.random.Generator,
                  at_rest: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Random ``(q, qd, qdd)``, each (samples, n): positions uniform within the joint limits
    (``+-pi`` when none), velocities and accelerations standard normal.

    ``at_rest`` (n,) bool: joints whose velocity is exactly zero in ``ZERO_VELOCITY_FRACTION`` of
    the states (a joint at rest, or within the Coulomb dead band of
    :mod:`robodyn.identification.preprocess`): there the Coulomb columns vanish and the friction
    offset ``Fo`` acts alone, so it becomes a base parameter of its own instead of regrouping
    into ``Fcp``/``Fcn``. Default: none."""
    n = model.dof
    lo = np.array([-np.pi if j.lower is None else float(j.lower) for j in model.robot.joints])
    hi = np.array([np.pi if j.upper is None else float(j.upper) for j in model.robot.joints])
    q = rng.uniform(lo, hi, (samples, n))
    qd = rng.standard_normal((samples, n))
    if at_rest is not None:
        qd[(rng.random((samples, n)) < ZERO_VELOCITY_FRACTION) & np.asarray(at_rest, bool)[None, :]] = 0.0
    return q, qd, rng.standard_normal((samples, n))


def pivoted_columns(w: np.ndarray, rtol: float = RANK_RTOL
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, int]:
    """QR with column pivoting of a stacked regressor on its unit-norm columns: the base columns.

    The one rule of robodyn for which regressor columns are independent (identification and
    excitation design alike): columns whose norm is below ``BETA_ZERO`` of the largest (at least
    1) are structural zeros and left out; the others are scaled to unit norm, so that the units of
    the parameters do not decide the rank, and a pivot ``|R_kk| <= rtol |R_00|`` is dependent.
    Column ``k`` of ``p`` is scaled to norm ``1 + TIE_PREFERENCE (p - k) / p`` rather than exactly
    1, so that of two exactly collinear columns the earlier one is always the base column: left
    to round-off, the choice changes with the BLAS, the vector width and the generated code's
    statement order.

    Parameters
    ----------
    w : numpy.ndarray, shape (m, p)
        Stacked regressor rows.
    rtol : float
        Rank tolerance relative to the largest pivot.

    Returns
    -------
    scales : numpy.ndarray, shape (p,)
        The column scales ``D``: the column norms of ``w``, each divided by its tie preference.
    used : numpy.ndarray of int, shape (k,)
        The columns that are not structural zeros.
    r : numpy.ndarray, shape (min(m, k), k)
        ``R`` of ``W[:, used] D^-1 P = Q R`` (``D`` restricted to ``used``).
    piv : numpy.ndarray of int, shape (k,)
        The pivot order, into ``used``.
    rank : int
        The first ``rank`` pivots are the independent (base) columns.
    """
    norms = np.linalg.norm(w, axis=0)
    used = np.flatnonzero(norms > BETA_ZERO * max(1.0, float(norms.max()) if norms.size else 1.0))
    # near-unit-norm columns, the earlier slightly longer: exact ties go to the earlier column
    p = norms.size
    scales = norms / (1.0 + TIE_PREFERENCE * (p - np.arange(p)) / max(p, 1))
    # W D^-1 P = Q R: the pivots order the columns by independence
    _, r, piv = scipy.linalg.qr(w[:, used] / scales[used], mode="economic", pivoting=True)
    d = np.abs(np.diag(r))
    rank = int(np.sum(d > rtol * d[0])) if d.size else 0
    return scales, used, r, piv, rank


def base_relations(model: Model, *, samples: int | None = None, seed: int = 0,
                   at_rest: np.ndarray | None = None, unseen: np.ndarray | None = None
                   ) -> BaseRelations:
    """Base parameters of a compiled model by QR with column pivoting on random states.

    Parameters
    ----------
    model : Model
        ``rd.compile_model(robot)``; its :meth:`~Model.regressor` gives (N, n, 15 n).
    samples : int, optional
        Random states to stack (default ``max(60, 30 n)``: ``n`` rows each, many times the
        number of columns).
    seed : int
        Seed of the random states (the result does not depend on it beyond round-off).
    at_rest : numpy.ndarray of bool, shape (n,), optional
        Joints seen at rest in the data (:func:`random_states`): their friction offset ``Fo`` is
        a base parameter of its own. Default: none (``Fo`` regroups into the Coulomb levels,
        which is all that data without rest can tell).
    unseen : numpy.ndarray of int, optional
        Standard columns the measurement does not see (the rotor inertia ``Ia`` behind a
        link-side torque sensor): treated as identically zero, so they are no base parameter
        and nothing regroups into them.

    Returns
    -------
    BaseRelations
    """
    n = model.dof
    names = parameter_names(n)
    rng = np.random.default_rng(seed)
    count = samples if samples is not None else max(60, 30 * n)
    q, qd, qdd = random_states(model, count, rng, at_rest)
    w = model.regressor(q, qd, qdd).reshape(count * n, -1)
    if unseen is not None:
        w[:, np.asarray(unseen, dtype=int)] = 0.0
    scales, used, r, piv, rank = pivoted_columns(w)
    zero = np.setdiff1d(np.arange(w.shape[1]), used)
    ind_local = used[piv[:rank]]
    dep_local = used[piv[rank:]]
    # beta in original (unscaled) units: W_d = W_b beta
    beta_scaled = scipy.linalg.solve_triangular(r[:rank, :rank], r[:rank, rank:])
    beta_used = beta_scaled * scales[dep_local][None, :] / scales[ind_local][:, None]
    order = np.argsort(ind_local)
    independent = ind_local[order]
    beta_used = beta_used[order]
    dependent = np.concatenate([dep_local, zero]).astype(int)
    beta = np.concatenate([beta_used, np.zeros((rank, zero.size))], axis=1)
    dorder = np.argsort(dependent)
    beta = np.where(np.abs(beta) > BETA_ZERO, beta, 0.0)
    return BaseRelations(standard_names=names, independent=independent.astype(int),
                         dependent=dependent[dorder], beta=beta[:, dorder], zero=zero.astype(int))
