"""Peer routes shared by the benchmarks (run as scripts: ``benchmarks/`` is on ``sys.path``)."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

import numpy as np
import sympy as sp

import robodyn as rd


def lambdified_rhs(robot: rd.Robot, values: Mapping[str, float] | None = None
                   ) -> Callable[[float, np.ndarray], np.ndarray]:
    """The usual Python route for SciPy's ``solve_ivp``: ``sympy.lambdify`` of robodyn's own M(q)
    and bias h(q, qd) = tau(q, qd, 0) (Lagrange), M qdd = -h solved in the right-hand side.

    ``values``: the description's named parameters (default: its defaults).
    """
    eom = rd.derive(robot, "lagrange")
    subs = eom.numeric(values) if values is not None else eom.numeric()
    zero = dict.fromkeys(eom.qdd, 0)
    m_fn = sp.lambdify([eom.q], eom.M.xreplace(subs), "numpy", cse=True)
    h_fn = sp.lambdify([eom.q, eom.qd], eom.tau.xreplace(zero).xreplace(subs), "numpy", cse=True)
    n = robot.dof

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        q, qd = y[:n], y[n:]
        # M qdd = -h
        qdd = np.linalg.solve(np.asarray(m_fn(q), float), -np.asarray(h_fn(q, qd), float).ravel())
        return np.concatenate([qd, qdd])

    return rhs


def pinocchio_loop(fn: Callable[..., Any], pmodel: Any, pdata: Any, loops: int,
                   *arrays: np.ndarray) -> Callable[[], None]:
    """A callable running ``fn(pmodel, pdata, a[k], ...)`` for k < ``loops`` from Python (Pinocchio
    has no batched form of most functions)."""
    def run() -> None:
        for k in range(loops):
            fn(pmodel, pdata, *(a[k] for a in arrays))
    return run
