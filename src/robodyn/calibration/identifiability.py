"""Which parameters a pose set can identify, observability indices, and pose selection.

Identifiable subset: the columns of the (weighted) identification Jacobian are normalised and
taken in the model's priority order; a column is kept when its part orthogonal to the columns
already kept is larger than ``tol`` (Gram-Schmidt; the same decision as an unpivoted QR
factorisation, ``|R_kk| > tol``, of the reordered matrix, Khalil & Dombre 2002, ch. 11). A dropped
parameter is held at its initial value; the least-squares coefficients ``c`` of its column on
the kept ones name the combination that cannot be separated: changing it by ``delta`` has the
same effect as changing each kept parameter ``j`` by ``c_j delta``.

Observability indices of the Jacobian ``J`` (m rows for N poses, L identifiable columns, singular
values ``s_1 >= ... >= s_L``):

* O1 (Borm & Menq 1991): ``(s_1 s_2 ... s_L)^(1/L) / sqrt(N)``;
* O2 (Driels & Pathre 1990): ``s_L / s_1``, the inverse condition number;
* O3 (Nahvi, Hollerbach & Hayward 1994): ``s_L``, the minimum singular value;
* O4 (Nahvi & Hollerbach 1996): ``s_L^2 / s_1``, the noise amplification index;
* O5 (Sun & Hollerbach 2008): ``1 / (1/s_1 + ... + 1/s_L)``, related to A-optimality.

They are computed on the unweighted Jacobian in m per m and m per rad (a unit length error and a
unit angle error count alike, which suits arms about a metre long).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from robodyn.robot.errors import InputError

__all__ = [
    "Observability",
    "Unidentifiable",
    "compress_rows",
    "dependency",
    "independent_columns",
    "observability",
    "select_poses",
]


@dataclass(frozen=True)
class Unidentifiable:
    """A parameter the data cannot separate from others.

    Attributes
    ----------
    name : str
    value : float
        The value it is held at (m or rad).
    kind : {"structural", "pose set"}
        ``"structural"``: no pose set can identify it in this model; ``"pose set"``: a richer pose
        set would.
    combination : tuple of (str, float)
        Kept parameters ``j`` and coefficients ``c_j``: its effect equals ``sum c_j * effect(j)``.
    reason : str
        A sentence for people.
    """

    name: str
    value: float
    kind: str
    combination: tuple[tuple[str, float], ...]
    reason: str


@dataclass(frozen=True, eq=False)
class Observability:
    """Observability indices O1-O5 of an identification Jacobian (see the module docstring)."""

    o1: float
    o2: float
    o3: float
    o4: float
    o5: float
    condition: float
    singular_values: np.ndarray
    n_poses: int

    def as_dict(self) -> dict[str, float]:
        """``{"O1": .., ..., "O5": .., "condition": ..}``."""
        return {"O1": self.o1, "O2": self.o2, "O3": self.o3, "O4": self.o4, "O5": self.o5,
                "condition": self.condition}


def observability(jac: np.ndarray, n_poses: int) -> Observability:
    """Observability indices of ``jac`` (shape (m, L), m per unit parameter) for ``n_poses`` poses.

    A tall ``jac`` is first reduced to its triangular factor (:func:`compress_rows`), which has
    the same singular values.
    """
    jac = compress_rows(jac)
    s = np.linalg.svd(jac, compute_uv=False) if jac.size else np.zeros(0)
    if s.size == 0:
        return Observability(0.0, 0.0, 0.0, 0.0, 0.0, np.inf, s, n_poses)
    with np.errstate(divide="ignore"):
        o1 = float(np.exp(np.mean(np.log(s))) / np.sqrt(n_poses)) if s[-1] > 0 else 0.0
        o5 = float(1.0 / np.sum(1.0 / s)) if s[-1] > 0 else 0.0
    return Observability(
        o1=o1,
        o2=float(s[-1] / s[0]) if s[0] > 0 else 0.0,
        o3=float(s[-1]),
        o4=float(s[-1] ** 2 / s[0]) if s[0] > 0 else 0.0,
        o5=o5,
        condition=float(s[0] / s[-1]) if s[-1] > 0 else np.inf,
        singular_values=s,
        n_poses=n_poses,
    )


def compress_rows(jac: np.ndarray) -> np.ndarray:
    """``R`` (L, L), upper triangular, with ``R^T R = J^T J`` for a tall ``jac`` (m, L), m > 2 L.

    Householder QR written with :func:`numpy.einsum` and in-place updates: the same column norms,
    angles, ranks, least-squares coefficients and singular values as ``jac``, without handing the
    tall matrix to a multithreaded LAPACK (which can take seconds on a busy machine for what one
    thread does in milliseconds). Other shapes are returned as given.
    """
    m, p = jac.shape
    if m <= 2 * p:
        return jac
    a = np.array(jac, dtype=float)
    for k in range(p):
        x = a[k:, k]
        nx = math.sqrt(float(np.einsum("i,i", x, x)))
        if nx == 0.0:
            continue
        v = x.copy()
        v[0] += math.copysign(nx, x[0])  # reflect x onto -sign(x0) |x| e1
        # A <- (I - 2 v v^T / v^T v) A on the trailing block
        w = np.einsum("i,ij->j", v, a[k:, k:]) * (2.0 / float(np.einsum("i,i", v, v)))
        a[k:, k:] -= np.multiply.outer(v, w)
    return np.triu(a[:p])


def independent_columns(jac: np.ndarray, order: Sequence[int], tol: float = 1e-7) -> list[int]:
    """Columns of ``jac`` kept in ``order``: each adds a direction larger than ``tol``.

    Parameters
    ----------
    jac : numpy.ndarray, shape (m, P)
    order : sequence of int
        Column priority (earlier columns are kept first).
    tol : float
        Threshold on the norm of the new orthogonal component of the normalised column.

    Returns
    -------
    list of int
        Kept column indices, in ``order``.
    """
    norms = np.linalg.norm(jac, axis=0)
    scale = norms.max() if norms.size else 0.0
    basis = np.zeros((jac.shape[0], min(jac.shape)))
    rank = 0
    kept = []
    for k in order:
        if not norms[k] > 1e-12 * scale or rank == basis.shape[1]:
            continue
        r = jac[:, k] / norms[k]
        for _ in range(2):  # Gram-Schmidt, twice for orthogonality
            r = r - basis[:, :rank] @ (basis[:, :rank].T @ r)
        size = np.linalg.norm(r)
        if size > tol:
            basis[:, rank] = r / size
            rank += 1
            kept.append(k)
    return kept


def dependency(jac: np.ndarray, kept: Sequence[int], k: int) -> np.ndarray:
    """Coefficients ``c`` with ``jac[:, k] ~ jac[:, kept] @ c`` (least squares)."""
    if not len(kept):
        return np.zeros(0)
    c, *_ = np.linalg.lstsq(jac[:, kept], jac[:, k], rcond=None)
    return c


def describe(jac: np.ndarray, names: Sequence[str], kept: Sequence[int], dropped: Sequence[int],
             ) -> list[tuple[tuple[tuple[str, float], ...], str]]:
    """For each dropped column: the combination (name, coefficient) it equals, and a sentence."""
    norms = np.linalg.norm(jac, axis=0)
    scale = max(norms.max() if norms.size else 0.0, 1e-300)
    coef = np.zeros((len(kept), len(dropped)))
    if len(kept) and len(dropped):
        coef, *_ = np.linalg.lstsq(jac[:, kept], jac[:, dropped], rcond=None)
    out = []
    for col, k in enumerate(dropped):
        size = norms[k]
        terms = []
        if size > 1e-12 * scale:
            for row, j in enumerate(kept):
                if abs(coef[row, col]) * norms[j] > 1e-6 * size:
                    terms.append((names[j], float(coef[row, col]), abs(coef[row, col]) * norms[j]))
        terms.sort(key=lambda t: -t[2])
        combo = tuple((n, c) for n, c, _ in terms)
        if not combo:
            out.append(((), "has no effect on the measurements"))
            continue
        sentence = "acts exactly like " + " ".join(f"{c:+.4g}*{n}" for n, c in combo)
        if len(combo) == 1:
            other, c1 = combo[0]
            sentence += f" (only {other} {'+' if c1 >= 0 else '-'} {abs(c1):.4g}*{names[k]} is determined)"
        out.append((combo, sentence))
    return out


def select_poses(
    jac: np.ndarray,
    count: int,
    *,
    index: str = "O1",
    exchange_passes: int = 2,
) -> np.ndarray:
    """Pick ``count`` of M candidate poses that make the identification best conditioned.

    Greedy D-optimal forward selection (each step adds the pose that most increases
    ``log det(J^T J)``, by rank-3 updates), then exchange passes that swap a chosen pose for a
    candidate while the requested observability index improves.

    Parameters
    ----------
    jac : numpy.ndarray, shape (M, r, L)
        Identification Jacobian of each candidate pose (r rows per pose, L identifiable
        parameters), m per unit parameter.
    count : int
        Number of poses to choose (at most M).
    index : {"O1", "O2", "O3", "O4", "O5"}
        The index the exchange passes maximise.
    exchange_passes : int

    Returns
    -------
    numpy.ndarray of int, shape (count,)
        Indices of the chosen candidates, sorted.
    """
    big_m, rows, big_l = jac.shape
    if not 0 < count <= big_m:
        raise InputError(f"count must be between 1 and the number of candidates ({big_m}), got {count}")
    key = index.upper()
    if key not in ("O1", "O2", "O3", "O4", "O5"):
        raise InputError(f"unknown observability index {index!r}; use O1 to O5")
    info = np.einsum("mri,mrj->ij", jac, jac)
    eps = 1e-9 * np.trace(info) / big_l / big_m
    a_inv = np.eye(big_l) / eps
    chosen: list[int] = []
    free = np.ones(big_m, dtype=bool)
    eye = np.eye(rows)
    for _ in range(count):
        # gain of each candidate: log det(I + J_c A^-1 J_c^T)
        ja = jac @ a_inv
        s = eye + np.einsum("mri,msi->mrs", ja, jac)
        gain = np.linalg.slogdet(s)[1]
        gain[~free] = -np.inf
        c = int(np.argmax(gain))
        chosen.append(c)
        free[c] = False
        # Woodbury: (A + J^T J)^-1 = A^-1 - A^-1 J^T (I + J A^-1 J^T)^-1 J A^-1
        a_inv = a_inv - ja[c].T @ np.linalg.solve(s[c], ja[c])
        a_inv = (a_inv + a_inv.T) / 2

    def score(sel: list[int]) -> float:
        obs = observability(jac[sel].reshape(-1, big_l), len(sel))
        return getattr(obs, key.lower())

    best = score(chosen)
    for _ in range(exchange_passes):
        improved = False
        for pos in range(len(chosen)):
            for cand in np.flatnonzero(free):
                trial = chosen.copy()
                trial[pos] = int(cand)
                value = score(trial)
                if value > best * (1 + 1e-9):
                    free[chosen[pos]], free[cand] = True, False
                    chosen, best, improved = trial, value, True
        if not improved:
            break
    return np.array(sorted(chosen))
