"""Agreement of the three formulations on random states, and the efficiency table."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import sympy as sp

from robodyn.robot.model import Robot
from robodyn.symbolic.eom import METHODS, EquationsOfMotion, derive
from robodyn.text import progress as _progress

#: Relative difference above which two formulations are reported as disagreeing.
TOLERANCE = 1e-9

_QUANTITIES = ("M", "g", "tau")


@dataclass(frozen=True)
class Agreement:
    """Largest relative difference of M, g and tau between two formulations.

    Attributes
    ----------
    first, second : str
        Method names.
    relative : dict[str, float]
        ``max over states of max|a - b| / max(max|a|, max|b|)`` per quantity ("M", "g", "tau").
    symbolic : bool or None
        Whether every simplified difference is zero (None: not checked).
    zero : tuple of str
        Quantities that are identically zero on every state in both formulations: nothing was
        compared. ``g`` may be (gravity normal to the motion); ``M`` and ``tau`` may not.
    singular : bool
        ``M`` is singular (smallest eigenvalue below 1e-12 of the largest) at some state in
        either formulation: the equations have no forward dynamics.
    """

    first: str
    second: str
    relative: dict[str, float]
    symbolic: bool | None = None
    zero: tuple[str, ...] = ()
    singular: bool = False

    @property
    def ok(self) -> bool:
        """Within :data:`TOLERANCE`, symbolically equal where checked, M and tau not zero, M regular."""
        vacuous = "M" in self.zero or "tau" in self.zero
        return (max(self.relative.values()) <= TOLERANCE and self.symbolic is not False
                and not vacuous and not self.singular)


def _evaluator(eom: EquationsOfMotion) -> Callable[..., dict[str, np.ndarray]]:
    """``f(q, qd, qdd) -> {"M": (n, n), "g": (n,), "tau": (n,)}`` at the default parameters.

    Each formulation is evaluated on its own straight-line form
    (:meth:`~robodyn.symbolic.eom.EquationsOfMotion.numeric_function`): seconds to build on a
    6- or 7-joint arm, where ``lambdify`` of the expanded expressions takes minutes.
    """
    mass, grav, tau = (eom.numeric_function(k) for k in _QUANTITIES)

    def call(q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> dict[str, np.ndarray]:
        return {"M": mass(q), "g": grav(q), "tau": tau(q, qd, qdd)}

    return call


def _states(n: int, count: int, seed: int) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    rng = np.random.default_rng(seed)
    return [(rng.uniform(-np.pi, np.pi, n), rng.uniform(-2, 2, n), rng.uniform(-3, 3, n))
            for _ in range(count)]


def _singular(matrices: Sequence[np.ndarray]) -> bool:
    """True when some (n, n) matrix has an eigenvalue at or below 1e-12 of its largest."""
    for m in matrices:
        lam = np.linalg.eigvalsh(0.5 * (m + m.T))
        if lam[0] <= 1e-12 * max(abs(lam[-1]), 1e-300):
            return True
    return False


def _symbolically_equal(a: EquationsOfMotion, b: EquationsOfMotion) -> bool:
    for name in _QUANTITIES:
        diff = sp.Matrix(getattr(a, name)) - sp.Matrix(getattr(b, name))
        if any(sp.simplify(sp.expand(e)) != 0 for e in diff):
            return False
    return True


def agreement(eoms: Sequence[EquationsOfMotion], samples: int = 20, seed: int = 0,
              symbolic: bool = False) -> list[Agreement]:
    """Compare every pair of formulations on random states (and symbolically if asked).

    Parameters
    ----------
    eoms : sequence of EquationsOfMotion
        Equations of one robot by different methods.
    samples : int
        Number of random states (q in [-pi, pi], qd in [-2, 2], qdd in [-3, 3]).
    seed : int
        Seed of the random states.
    symbolic : bool
        Also check that the simplified differences are zero (small arms only: slow).

    Returns
    -------
    list of Agreement
        One per pair, in the order of ``eoms``.
    """
    n = eoms[0].dof
    states = _states(n, samples, seed)
    values: dict[str, dict[str, list[np.ndarray]]] = {}
    for eom in eoms:
        with _progress(f"evaluating {eom.method} on {samples} states"):
            func = _evaluator(eom)
            results = [func(*s) for s in states]
            values[eom.method] = {k: [r[k] for r in results] for k in _QUANTITIES}
    out = []
    for i, a in enumerate(eoms):
        for b in eoms[i + 1:]:
            rel = {}
            for k in _QUANTITIES:
                worst = 0.0
                for va, vb in zip(values[a.method][k], values[b.method][k], strict=True):
                    scale = max(np.max(np.abs(va)), np.max(np.abs(vb)))
                    diff = np.max(np.abs(va - vb))
                    worst = max(worst, diff / scale if scale > 0 else diff)
                rel[k] = float(worst)
            # identically zero in both: agreement that compared nothing
            zero = tuple(k for k in _QUANTITIES
                         if all(not np.any(v) for v in values[a.method][k] + values[b.method][k]))
            singular = _singular(values[a.method]["M"]) or _singular(values[b.method]["M"])
            same = None
            if symbolic:
                with _progress(f"simplifying {a.method} - {b.method}"):
                    same = _symbolically_equal(a, b)
            out.append(Agreement(a.method, b.method, rel, same, zero, singular))
    return out


def verdict(results: Sequence[Agreement]) -> str:
    """One line for the end of ``robodyn check``: agree, disagree, or nothing to compare."""
    if any("M" in r.zero or "tau" in r.zero for r in results):
        return ("M and tau are identically zero (no mass or inertia moves): the formulations "
                "compared nothing")
    if any(r.singular for r in results):
        return "the mass matrix is singular at some states: no forward dynamics"
    if all(r.ok for r in results):
        return "the three formulations agree"
    return "the formulations DISAGREE"


def derive_all(robot: Robot) -> list[EquationsOfMotion]:
    eoms = []
    for method in METHODS:
        with _progress(f"deriving {method}"):
            eoms.append(derive(robot, method))
    for eom in eoms:
        with _progress(f"counting operations of {eom.method} (after CSE)"):
            eom.op_counts()
    return eoms


COUNT_HEADERS = ("method", "derive [s]", "tau +", "tau *", "tau fn", "M +", "M *", "M fn",
                  "g +", "g *", "g fn")


def count_rows(eoms: Sequence[EquationsOfMotion]) -> list[list[object]]:
    rows = []
    for eom in eoms:
        counts = eom.op_counts()
        row: list[object] = [eom.method, f"{eom.derivation_time:.3f}"]
        for key in ("tau", "M", "g"):
            ops = counts[key]
            row += [ops.additions, ops.multiplications, ops.functions]
        rows.append(row)
    return rows


def agreement_rows(results: Sequence[Agreement]) -> list[list[object]]:
    rows = []
    for r in results:
        sym = {None: "-", True: "yes", False: "NO"}[r.symbolic]
        cells = ["0 (both zero)" if k in r.zero else f"{r.relative[k]:.1e}" for k in _QUANTITIES]
        if "M" in r.zero or "tau" in r.zero:
            verdict = "NOTHING COMPARED (M, tau zero)"
        elif r.singular:
            verdict = "M SINGULAR"
        else:
            verdict = "ok" if r.ok else "DISAGREE"
        rows.append([f"{r.first} vs {r.second}", *cells, sym, verdict])
    return rows


AGREEMENT_HEADERS = ("pair", "M", "g", "tau", "symbolic", "result")
