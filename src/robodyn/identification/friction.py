"""Friction beyond the linear model, fitted after the linear step (two-step least squares).

Step 1 is :func:`robodyn.identification` with the linear friction of the regressor (viscous, Coulomb
+/-, offset). Step 2 keeps its rigid-body and rotor-inertia parameters and fits, joint by joint, a
nonlinear friction law ``f_j(qd_j)`` to what they leave of the target,
``r_j = y_j - [Y(q, qd, qdd) p_nf]_j`` (``p_nf``: the identified parameters with friction set to
zero; the filtered regressor and target of the linear step), by nonlinear least squares
(``scipy.optimize.least_squares``, trust-region reflective, started from the linear step's
values). Models, ``v = qd_j``, ``s(v) = tanh(v / V_EPS)`` a sign
smoothed over ``V_EPS = 0.01`` rad/s (so that a joint at rest, whose filtered velocity wanders
around zero, is not given full Coulomb friction of random sign):

``"linear"``      ``Fv v + Fcp H(v) - Fcn H(-v) + Fo`` (step 1 itself; ``H`` the step);
``"stribeck"``    ``s(v) (Fc + (Fs - Fc) exp(-(v / vs)^2)) + Fv v + Fo`` (static Fs, Coulomb Fc,
                  Stribeck velocity vs, viscous Fv, offset Fo);
``"load"``        ``s(v) (Fc + mu |tau_j|) + Fv v + Fo``: Coulomb friction growing with the load
                  torque ``tau_j = [Y p_nf]_j`` the transmission carries;
``"polynomial"``  ``s(v) Fc + a1 v + a2 v |v| + a3 v^3 + Fo``.

``"none"`` (no friction at all, rigid body and rotor inertia only) is a separate linear fit,
``rd.identify(..., friction="none")``. :func:`friction_table` compares them on held-out data.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from scipy.optimize import least_squares

from robodyn.identification.preprocess import Samples, preprocess, regressor_rows
from robodyn.robot.errors import IdentificationError
from robodyn.symbolic.regressor import PER_JOINT, joint_columns

__all__ = ["FRICTION_MODELS", "MIN_REVERSAL", "NONLINEAR", "V_EPS", "FrictionFit", "fit_friction"]

V_EPS = 0.01
#: Fraction of a joint's samples beyond ``V_EPS`` in each direction from which its offset is
#: fitted with the law (:func:`_fit_law`).
MIN_REVERSAL = 0.01
NONLINEAR = ("stribeck", "load", "polynomial")
FRICTION_MODELS = ("none", "linear", *NONLINEAR)
_NAMES = {
    "stribeck": ("Fc", "Fs", "vs", "Fv", "Fo"),
    "load": ("Fc", "mu", "Fv", "Fo"),
    "polynomial": ("Fc", "a1", "a2", "a3", "Fo"),
}


def _law(model: str, x: np.ndarray, v: np.ndarray, load: np.ndarray) -> np.ndarray:
    s = np.tanh(v / V_EPS)
    if model == "stribeck":
        fc, fs, vs, fv, fo = x
        # f = s(v) (Fc + (Fs - Fc) exp(-(v/vs)^2)) + Fv v + Fo
        return s * (fc + (fs - fc) * np.exp(-((v / vs) ** 2))) + fv * v + fo
    if model == "load":
        fc, mu, fv, fo = x
        # f = s(v) (Fc + mu |tau|) + Fv v + Fo
        return s * (fc + mu * np.abs(load)) + fv * v + fo
    fc, a1, a2, a3, fo = x
    # f = s(v) Fc + a1 v + a2 v|v| + a3 v^3 + Fo
    return s * fc + a1 * v + a2 * v * np.abs(v) + a3 * v**3 + fo


def _law_jacobian(model: str, x: np.ndarray, v: np.ndarray, load: np.ndarray) -> np.ndarray:
    """``d f / d x`` (N, len(x)) of :func:`_law` at velocities ``v`` (N,) and loads (N,)."""
    s = np.tanh(v / V_EPS)
    one = np.ones_like(v)
    if model == "stribeck":
        fc, fs, vs, _, _ = x
        e = np.exp(-((v / vs) ** 2))
        # df/dFc = s (1 - e), df/dFs = s e, df/dvs = s (Fs - Fc) e 2 v^2 / vs^3, df/dFv = v
        return np.column_stack([s * (1.0 - e), s * e, s * (fs - fc) * e * 2.0 * v**2 / vs**3, v, one])
    if model == "load":
        return np.column_stack([s, s * np.abs(load), v, one])
    return np.column_stack([s, v, v * np.abs(v), v**3, one])


def _fit_law(model: str, x0: np.ndarray, bounds: tuple[np.ndarray, np.ndarray], v: np.ndarray,
             load: np.ndarray, r: np.ndarray) -> np.ndarray:
    """Parameters of ``model`` minimising ``|f(v, load) - r|`` (trust-region reflective within
    ``bounds``, from ``x0``, with the analytic Jacobian :func:`_law_jacobian`).

    A joint that does not reverse in the data (fewer than ``MIN_REVERSAL`` of its samples beyond
    ``V_EPS`` on one side) has a constant sign: its Coulomb level and offset are not separable
    (any split fits; a least-squares run drifts to large opposite values that a reversing
    motion then shows), so the offset stays the start's, the linear step's.
    """
    free = np.ones(x0.size, bool)
    free[-1] = min(np.mean(v > V_EPS), np.mean(v < -V_EPS)) >= MIN_REVERSAL  # Fo

    def full(z: np.ndarray) -> np.ndarray:
        x = x0.copy()
        x[free] = z
        return x

    return full(least_squares(lambda z: _law(model, full(z), v, load) - r, x0[free],
                              jac=lambda z: _law_jacobian(model, full(z), v, load)[:, free],
                              bounds=(bounds[0][free], bounds[1][free]), method="trf",
                              x_scale="jac").x)


@dataclass(frozen=True, eq=False)
class FrictionFit:
    """A nonlinear friction law per joint (module docstring), in target-torque units (N m).

    Attributes
    ----------
    model : {"stribeck", "load", "polynomial"}
    names : tuple of str
        Parameter names of the law.
    params : numpy.ndarray, shape (n, len(names))
    """

    model: str
    names: tuple[str, ...]
    params: np.ndarray

    def torque(self, qd: np.ndarray, load: np.ndarray) -> np.ndarray:
        """Friction torque (N, n) at velocities ``qd`` (N, n), rad/s, and load torques (N, n)."""
        return np.column_stack([_law(self.model, self.params[j], qd[:, j], load[:, j])
                                for j in range(self.params.shape[0])])


def without_friction(standard: np.ndarray) -> np.ndarray:
    """The standard vector (15 n,) with the friction entries (Fv, Fcp, Fcn, Fo) set to zero."""
    p = standard.copy()
    for j in range(p.size // PER_JOINT):
        p[joint_columns(j, "Fv")] = 0.0
    return p


def _start(model: str, linear: np.ndarray) -> tuple[np.ndarray, tuple[np.ndarray, np.ndarray]]:
    fv, fcp, fcn, fo = linear
    fc = max(0.5 * (fcp + fcn), 1e-6)
    inf = np.inf
    if model == "stribeck":
        return (np.array([fc, 1.2 * fc, 0.05, max(fv, 0.0), fo + 0.5 * (fcp - fcn)]),
                (np.array([0, 0, 1e-3, 0, -inf]), np.array([inf, inf, 10.0, inf, inf])))
    if model == "load":
        return (np.array([fc, 0.0, max(fv, 0.0), fo + 0.5 * (fcp - fcn)]),
                (np.array([0, 0, 0, -inf]), np.array([inf, inf, inf, inf])))
    return (np.array([fc, fv, 0.0, 0.0, fo + 0.5 * (fcp - fcn)]),
            (np.array([0, -inf, -inf, -inf, -inf]), np.full(5, inf)))


def fit_friction_samples(ident: Any, samples: Sequence[Samples], y_full: Sequence[np.ndarray],
                         model: str) -> FrictionFit:
    """Step 2 on already processed, decimated samples and their (filtered) full regressors
    (:func:`robodyn.identification.preprocess.regressor_rows`); see :func:`fit_friction`."""
    if model not in NONLINEAR:
        raise IdentificationError(f"friction: expected one of {FRICTION_MODELS}, got {model!r}")
    p_nf = without_friction(ident.standard)
    n = ident.robot.dof
    qd = np.vstack([s.qd for s in samples])
    load = np.vstack([y @ p_nf for y in y_full])
    r = np.vstack([s.y for s in samples]) * ident.gains[None, :] - load  # r = K H y - H Y p_nf
    params = []
    for j in range(n):
        b = joint_columns(j, "Fv").start
        x0, bounds = _start(model, ident.standard[b:b + 4])
        x0 = np.clip(x0, bounds[0] + 1e-12, bounds[1] - 1e-12)
        if np.ptp(qd[:, j]) == 0.0:  # a joint held still: only the offset is seen
            x = np.zeros_like(x0)
            x[-1] = float(np.mean(r[:, j]))
            params.append(x)
            continue
        params.append(_fit_law(model, x0, bounds, qd[:, j], load[:, j], r[:, j]))
    return FrictionFit(model=model, names=_NAMES[model], params=np.array(params))


def fit_friction(ident: Any, recordings: Any, model: str = "stribeck") -> Any:
    """Fit a nonlinear friction law after the linear identification (module docstring).

    Parameters
    ----------
    ident : Identification
        The linear step (``rd.identify``).
    recordings : Recording or sequence of Recording
        Identification data (normally the same as the linear step's), processed with
        ``ident.preprocess``.
    model : {"stribeck", "load", "polynomial"}

    Returns
    -------
    Identification
        ``ident`` with :attr:`~Identification.friction_fit` set; its :meth:`predict` then uses
        the nonlinear law in place of the linear friction.
    """
    recs = [recordings] if hasattr(recordings, "q") else list(recordings)
    d = ident.preprocess.decimate
    samples, y_full = [], []
    for r in recs:
        s = preprocess(r, ident.preprocess, ident.target)
        y_full.append(regressor_rows(ident._model, s, ident.preprocess))
        samples.append(Samples(s.t[::d], s.q[::d], s.qd[::d], s.qdd[::d], s.y[::d], s.source))
    return replace(ident, friction_fit=fit_friction_samples(ident, samples, y_full, model))
