"""The fixed-step schemes and the sampled state-feedback law, described once for C and NumPy.

The generated C integrators (:mod:`robodyn.codegen.c_simulation`), their NumPy twin
(:mod:`robodyn.numeric.integrate_numpy`) and the Python control loop of
:mod:`robodyn.simulation.steppers` take their arithmetic from the descriptions here, so that a
change of scheme or of law is made in one place and every backend follows it:

* :data:`RK4`, a :class:`ChainScheme`: an explicit Runge-Kutta scheme whose stage ``i`` starts
  from ``x + a_i h k_(i-1)`` (classical RK4: ``a = (1/2, 1/2, 1)``, weights ``(1, 2, 2, 1) / 6``,
  sampled at ``t, t + h/2, t + h/2, t + h``). :meth:`ChainScheme.step` advances NumPy states,
  :meth:`ChainScheme.c_lines` emits the same operations, in the same order, as C loops;
* the semi-implicit (symplectic) Euler step, :func:`semi_implicit_step` and
  :func:`semi_implicit_c_lines`;
* the sampled law (:data:`LAW_MODES`), with ``e = reference_row - x`` (2 n) and ``z`` the
  integral of the position error::

      v = feedforward_row + gain e + integral_gain * z
      mode 0 (feedback):        tau = v
      mode 1 (+ gravity):       tau = v + g(q)
      mode 2 (computed torque): tau = M(q) v + (C qd + g + friction)

  then clipped to ``+-tau_limit``: :func:`law` evaluates it in NumPy, :func:`law_c_lines` emits
  it as C. Each step of the law sits beside its C text, so the two cannot drift apart.

The NumPy forms evaluate the same operations in the same order as the C text (``x + 0.5 * dt *
k1``, ``dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)``), so the backends agree to rounding.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

__all__ = ["LAW_MODES", "RK4", "ChainScheme", "law", "law_c_lines", "semi_implicit_c_lines",
           "semi_implicit_step"]

#: The law's modes, by the integer the generated integrators take.
LAW_MODES = {0: "feedback", 1: "gravity", 2: "computed_torque"}


@dataclass(frozen=True)
class ChainScheme:
    """An explicit Runge-Kutta scheme with a sub-diagonal tableau (stage i from stage i - 1 only).

    Attributes
    ----------
    name : str
    steps : tuple of (float, str)
        For stages 2..s: ``a_i`` and its C text as a multiple of ``dt`` (stage i evaluates the
        slope at ``x + a_i dt k_(i-1)``).
    weights : tuple of float
        ``b_i`` times ``denominator`` (s,).
    denominator : float
    rows : tuple of int
        The sample of each stage in half steps: 0 at ``t``, 1 at ``t + dt/2``, 2 at ``t + dt``.
    """

    name: str
    steps: tuple[tuple[float, str], ...]
    weights: tuple[float, ...]
    denominator: float
    rows: tuple[int, ...]

    @property
    def stages(self) -> int:
        """Number of slope evaluations per step."""
        return len(self.weights)

    def step(self, states: Sequence[np.ndarray], dt: float,
             slopes: Callable[[int, tuple[np.ndarray, ...]], Sequence[np.ndarray]]
             ) -> tuple[np.ndarray, ...]:
        """One step of the states (each (m,)) given their ``slopes(stage, stage_states)``."""
        ks = [tuple(slopes(0, tuple(states)))]
        for i, (a, _) in enumerate(self.steps, start=1):
            # stage i: x_i = x + a_i dt k_(i-1)
            ks.append(tuple(slopes(i, tuple(x + a * dt * k for x, k in zip(states, ks[-1], strict=True)))))
        out = []
        for j, x in enumerate(states):
            # x + dt / d (w_1 k_1 + ... + w_s k_s), summed left to right as the C text
            acc = ks[0][j] if self.weights[0] == 1.0 else self.weights[0] * ks[0][j]
            for w, k in zip(self.weights[1:], ks[1:], strict=True):
                acc = acc + (k[j] if w == 1.0 else w * k[j])
            out.append(x + dt / self.denominator * acc)
        return tuple(out)

    def c_lines(self, ind: str, states: Sequence[tuple[str, str, str, str]],
                slopes: Callable[[int, tuple[str, ...]], list[str]], comment: str = "") -> list[str]:
        """C lines of one step: the operations of :meth:`step`, in its order.

        ``states``: per state ``(name, stage_name, length, slope_prefix)``; the slope of stage i
        goes to ``slope_prefix + str(i + 1)``. ``slopes(i, names)`` gives the C lines that
        evaluate stage i's slopes at the states ``names``; ``comment`` (a C comment line) goes
        before the final update.
        """
        lines = slopes(0, tuple(s[0] for s in states))
        for i, (_, text) in enumerate(self.steps, start=1):
            for name, tmp, size, k in states:
                # x_i = x + a_i dt k_(i-1)
                lines.append(f"{ind}for (int i = 0; i < {size}; ++i) "
                             f"{tmp}[i] = {name}[i] + {text} * {k}{i}[i];")
            lines += slopes(i, tuple(s[1] for s in states))
        if comment:
            lines.append(ind + comment)
        for name, _, size, k in states:
            terms = " + ".join(f"{k}{j + 1}[i]" if w == 1.0 else f"{w!r} * {k}{j + 1}[i]"
                               for j, w in enumerate(self.weights))
            lines += [f"{ind}for (int i = 0; i < {size}; ++i)",
                      f"{ind}    {name}[i] += dt / {self.denominator!r} * ({terms});"]
        return lines


#: Classical fourth-order Runge-Kutta.
RK4 = ChainScheme("rk4", steps=((0.5, "0.5 * dt"), (0.5, "0.5 * dt"), (1.0, "dt")),
                  weights=(1.0, 2.0, 2.0, 1.0), denominator=6.0, rows=(0, 1, 1, 2))


def semi_implicit_step(x: np.ndarray, dt: float, qdd: np.ndarray) -> np.ndarray:
    """Semi-implicit Euler: ``qd += dt qdd(q, qd)``, then ``q += dt qd`` with the new ``qd`` (2 n,)."""
    n = qdd.size
    qd = x[n:] + dt * qdd
    return np.concatenate([x[:n] + dt * qd, qd])


def semi_implicit_c_lines(ind: str, x: str, k: str, slope: list[str], off: str = "") -> list[str]:
    """C lines of :func:`semi_implicit_step` for the state ``x``: the ``slope`` lines (which put
    the state derivative in ``k``), then the update; ``off`` indexes one state of a block
    (``"j * NX + "``)."""
    return [f"{ind}/* semi-implicit Euler: qd += dt qdd(q, qd); q += dt qd (new qd) */", *slope,
            f"{ind}for (int i = 0; i < N; ++i) {x}[{off}N + i] += dt * {k}[{off}N + i];",
            f"{ind}for (int i = 0; i < N; ++i) {x}[{off}i] += dt * {x}[{off}N + i];"]


def law(inputs: Mapping[str, np.ndarray | None], row: int, x: np.ndarray, z: np.ndarray, mode: int,
        terms: Callable[[str, np.ndarray, np.ndarray], np.ndarray]) -> np.ndarray:
    """The sampled law's torque (n,) at state ``x`` (2 n,) and error integral ``z`` (n,).

    ``inputs``: ``feedforward`` (rows, n), ``reference`` (rows, 2 n), ``gain`` (n, 2 n),
    ``integral_gain`` (n,), ``tau_limit`` (n,), each None for none. ``terms(name, q, qd)``
    evaluates the model's ``"mass_matrix"`` (n, n), ``"bias"`` (n,: ``C qd + g + friction``) and
    ``"gravity"`` (n,).
    """
    n = z.size
    ref, ff = inputs.get("reference"), inputs.get("feedforward")
    # e = reference_row - x
    e = np.broadcast_to((ref[row] if ref is not None else 0.0) - x, (2 * n,))
    # v = feedforward_row + gain e + integral_gain * integral(e_q)
    v = ff[row].copy() if ff is not None else np.zeros(n)
    if inputs.get("gain") is not None:
        v += inputs["gain"] @ e
    if inputs.get("integral_gain") is not None:
        v += inputs["integral_gain"] * z
    q, qd = x[:n], x[n:]
    # computed torque: tau = M(q) v + (C qd + g + friction)
    tau = terms("mass_matrix", q, qd) @ v + terms("bias", q, qd) if mode == 2 else v
    if mode == 1:
        tau = tau + terms("gravity", q, qd)  # gravity compensation: tau += g(q)
    limit = inputs.get("tau_limit")
    return np.clip(tau, -limit, limit) if limit is not None else tau


def law_c_lines(n: int, prefix: str, has_gravity: bool, has_mass: bool, p: str,
                params_decl: str) -> list[str]:
    """C function ``PREFIXcontrol_law``: :func:`law` at one state from row ``row`` of the inputs.

    ``p`` is ``", params"`` and ``params_decl`` its declaration when the kernels take runtime
    parameters (else both empty).
    """
    lines = [
        "/* tau = the control law at state x with the inputs of sample `row` (see simulate). */",
        f"static void {prefix}control_law(long row, const double *x, const double *integ, "
        "const double *feedforward, const double *reference, const double *gain, "
        f"const double *integral_gain, int mode, const double *tau_limit, {params_decl}"
        "double *tau) {",
        f"    enum {{ N = {n}, NX = {2 * n} }};",
        "    double e[NX], v[N];",
        "    /* e = reference_row - x */",
        "    for (int i = 0; i < NX; ++i) e[i] = (reference ? reference[row * NX + i] : 0.0) - x[i];",
        "    /* v = feedforward_row + gain e + integral_gain * integral(e_q) */",
        "    for (int i = 0; i < N; ++i) {",
        "        double s = feedforward ? feedforward[row * N + i] : 0.0;",
        "        if (gain) for (int j = 0; j < NX; ++j) s += gain[i * NX + j] * e[j];",
        "        if (integral_gain) s += integral_gain[i] * integ[i];",
        "        v[i] = s;",
        "    }",
    ]
    if has_mass:
        lines += [
            "    if (mode == 2) {",
            "        /* computed torque: tau = M(q) v + (C qd + g + friction) */",
            "        double m[N * N], h[N], zero[N];",
            "        for (int i = 0; i < N; ++i) zero[i] = 0.0;",
            f"        {prefix}mass_matrix(x{p}, m);",
            f"        {prefix}inverse_dynamics(x, x + N, zero{p}, h);",
            "        for (int i = 0; i < N; ++i) {",
            "            double s = h[i];",
            "            for (int j = 0; j < N; ++j) s += m[i * N + j] * v[j];",
            "            tau[i] = s;",
            "        }",
            "    } else {",
            "        for (int i = 0; i < N; ++i) tau[i] = v[i];",
            "    }",
        ]
    else:
        lines += ["    for (int i = 0; i < N; ++i) tau[i] = v[i];"]
    if has_gravity:
        lines += [
            "    if (mode == 1) {",
            "        /* gravity compensation: tau += g(q) */",
            "        double gq[N];",
            f"        {prefix}gravity(x{p}, gq);",
            "        for (int i = 0; i < N; ++i) tau[i] += gq[i];",
            "    }",
        ]
    return lines + [
        "    if (tau_limit) for (int i = 0; i < N; ++i) {",
        "        if (tau[i] > tau_limit[i]) tau[i] = tau_limit[i];",
        "        if (tau[i] < -tau_limit[i]) tau[i] = -tau_limit[i];",
        "    }",
        "}",
        "",
    ]
