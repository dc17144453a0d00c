"""The generated C simulators: the fixed-step integrators (RK4, semi-implicit Euler) with the
state-feedback laws, one trajectory or an ensemble of trajectories a block at a time.

Emitted beside the kernels by :class:`robodyn.codegen.c.CPrinter` (``rd_simulate``,
``rd_simulate_ensemble``); called by :func:`robodyn.simulation.rollouts.rollout`.
"""

from __future__ import annotations

from robodyn.codegen.cpu import BLOCK
from robodyn.codegen.fixed_step import RK4, law_c_lines, semi_implicit_c_lines

__all__ = ["ensemble_signature", "ensemble_source", "simulate_signature", "simulation_source"]


def _params_decl(runtime: int) -> str:
    """The parameter argument of the integrators when the kernels take runtime parameters."""
    return "const double *params, " if runtime else ""


def simulate_signature(prefix: str, runtime: int = 0) -> str:
    """Prototype of the in-C trajectory integrator.

    With ``runtime`` > 0 parameters left as kernel inputs it takes ``params`` (runtime,).
    """
    return (f"int {prefix}simulate(long steps, double dt, int method, const double *x0, "
            "const double *feedforward, const double *reference, const double *gain, "
            "const double *integral_gain, int mode, const double *tau_limit, "
            f"{_params_decl(runtime)}int continuous, double *x_out, double *tau_out)")


def ensemble_signature(prefix: str, runtime: int = 0) -> str:
    """Prototype of the in-C integrator of many trajectories.

    With ``runtime`` > 0 parameters it takes ``params`` (count, runtime): one set per trajectory.
    """
    return (f"int {prefix}simulate_ensemble(long count, long steps, double dt, int method, "
            "const double *x0, const double *feedforward, const double *reference, "
            "const double *gain, const double *integral_gain, int mode, const double *tau_limit, "
            f"{_params_decl(runtime)}int threads, double *x_out, double *tau_out, long *status)")


def ensemble_source(n: int, prefix: str, runtime: int = 0) -> str:
    """C source of ``PREFIXsimulate_ensemble``: ``count`` trajectories of ``PREFIXsimulate``.

    Trajectory i starts at ``x0[i]`` (2 n) and follows the sampled law of
    :func:`simulation_source` (``continuous`` 0) with the same ``feedforward``, ``reference``,
    gains and limits; its states go to ``x_out[i]`` ((steps + 1) x 2 n) and its torques to
    ``tau_out[i]`` (steps x n, or NULL). Trajectories are integrated :data:`BLOCK` at a time:
    each RK4 stage is one ``state_derivative`` over the block (the vectorised kernel, SIMD
    across trajectories) and the updates are loops over the block's states. Every trajectory
    gets the same bits as ``PREFIXsimulate`` alone. ``status[i]`` is 0, or k + 1 when trajectory i
    stopped being finite at step k (its later rows are not written). Blocks go to ``threads``
    OpenMP threads. Returns the number of trajectories that failed. With ``runtime`` > 0
    parameters left as kernel inputs, trajectory i uses ``params[i]`` (runtime values) in its
    dynamics and in the law's model terms.
    """
    sd = f"{prefix}state_derivative_range"
    law = f"{prefix}control_law"
    args = "feedforward, reference, gain, integral_gain, mode, tau_limit"
    # the block's parameter rows (the kernels index them like the states), one row per law
    blk = f", params + first * {runtime}" if runtime else ""
    own = f", params + (first + j) * {runtime}" if runtime else ""
    lines = [
        f"/* trajectories first .. first + m - 1 (m <= {BLOCK}) of simulate_ensemble. */",
        f"static void {prefix}ensemble_block(long first, int m, long steps, double dt, int method, "
        "const double *x0, const double *feedforward, const double *reference, const double *gain, "
        f"const double *integral_gain, int mode, const double *tau_limit, {_params_decl(runtime)}"
        "double *x_out, double *tau_out, long *status) {",
        f"    enum {{ N = {n}, NX = {2 * n}, B = {BLOCK} }};",
        "    double x[B * NX], xt[B * NX], k1[B * NX], k2[B * NX], k3[B * NX], k4[B * NX];",
        "    double tau[B * N], integ[B * N], r[N];",
        "    for (int j = 0; j < m; ++j) {",
        "        status[first + j] = 0;",
        "        for (int i = 0; i < NX; ++i)",
        "            x[j * NX + i] = x_out[(first + j) * (steps + 1) * NX + i] = x0[(first + j) * NX + i];",
        "        for (int i = 0; i < N; ++i) integ[j * N + i] = 0.0;",
        "    }",
        "    for (long k = 0; k < steps; ++k) {",
        "        /* per trajectory: integral += e_q dt, then the sampled law */",
        "        for (int j = 0; j < m; ++j) {",
        f"            {prefix}error_rate(k, x + j * NX, reference, r);",
        "            for (int i = 0; i < N; ++i) integ[j * N + i] += r[i] * dt;",
        f"            {law}(k, x + j * NX, integ + j * N, {args}{own}, tau + j * N);",
        "        }",
        "        if (method == 0) {",
        "            /* RK4 over the block: x += dt/6 (k1 + 2 k2 + 2 k3 + k4) */",
        *RK4.c_lines("            ", [("x", "xt", "m * NX", "k")],
                     lambda i, at: [f"            {sd}(0, m, {at[0]}, tau{blk}, k{i + 1}, 0);"]),
        "        } else {",
        *semi_implicit_c_lines("            ", "x", "k1",
                               [f"            {sd}(0, m, x, tau{blk}, k1, 0);"])[:2],
        "            for (int j = 0; j < m; ++j) {",
        *semi_implicit_c_lines("                ", "x", "k1", [], "j * NX + ")[1:],
        "            }",
        "        }",
        "        for (int j = 0; j < m; ++j) {",
        "            if (status[first + j]) continue;",
        "            double *row = x_out + ((first + j) * (steps + 1) + k + 1) * NX;",
        "            for (int i = 0; i < NX; ++i) {",
        "                if (!isfinite(x[j * NX + i])) {",
        "                    /* stopped: restart it at zero so that it costs no libm fallbacks */",
        "                    status[first + j] = k + 1;",
        "                    for (int l = 0; l < NX; ++l) x[j * NX + l] = 0.0;",
        "                    break;",
        "                }",
        "                row[i] = x[j * NX + i];",
        "            }",
        "            if (tau_out && !status[first + j])",
        "                for (int i = 0; i < N; ++i)",
        "                    tau_out[((first + j) * steps + k) * N + i] = tau[j * N + i];",
        "        }",
        "    }",
        "}",
        "",
        *_ensemble_driver(n, prefix, runtime, args),
    ]
    return "\n".join(lines) + "\n"


def _ensemble_driver(n: int, prefix: str, runtime: int, args: str) -> list[str]:
    """C lines of ``PREFIXsimulate_ensemble``: the blocks of trajectories on OpenMP threads."""
    return [
        f"/* count trajectories of {n}-joint dynamics, {BLOCK} per block, blocks on `threads` threads. */",
        ensemble_signature(prefix, runtime) + " {",
        f"    const long blocks = (count + {BLOCK - 1}) / {BLOCK};",
        "    long failed = 0;",
        "#ifdef _OPENMP",
        "#pragma omp parallel for num_threads(threads > 0 ? threads : 1) schedule(dynamic)",
        "#endif",
        "    for (long b = 0; b < blocks; ++b) {",
        f"        const int m = count - {BLOCK} * b < {BLOCK} ? (int)(count - {BLOCK} * b) : {BLOCK};",
        f"        {prefix}ensemble_block({BLOCK} * b, m, steps, dt, method, x0, {args}, "
        f"{'params, ' if runtime else ''}x_out, tau_out, status);",
        "    }",
        "    (void)threads;",
        "    for (long i = 0; i < count; ++i) failed += status[i] != 0;",
        "    return (int)(failed < 2147483647L ? failed : 2147483647L);",
        "}",
    ]


def _law_source(n: int, prefix: str, has_gravity: bool, has_mass: bool,
                runtime: int = 0) -> list[str]:
    """``PREFIXcontrol_law``: the torque at one state from row ``row`` of the sampled inputs
    (:func:`robodyn.codegen.fixed_step.law_c_lines`)."""
    return law_c_lines(n, prefix, has_gravity, has_mass, ", params" if runtime else "",
                       _params_decl(runtime))


def _staged_rk4(prefix: str, args: str, p: str = "") -> list[str]:
    """The body of one RK4 step with the control law evaluated at every stage (C lines).

    ``p``: ``", params"`` when the kernels take runtime parameters (``args`` then ends with it).
    """
    sd, law = f"{prefix}state_derivative", f"{prefix}control_law"
    ind = "            "

    def slopes(i: int, at: tuple[str, ...]) -> list[str]:
        # stage i: the law at the stage's state and sample, then both slopes
        row = "2 * k" + (f" + {RK4.rows[i]}" if RK4.rows[i] else "")
        tau = "tau" if i == 0 else "ts"
        return [f"{ind}{law}({row}, {at[0]}, {at[1]}, {args}, {tau});",
                f"{ind}{sd}({at[0]}, {tau}{p}, k{i + 1});",
                f"{ind}{prefix}error_rate({row}, {at[0]}, reference, r{i + 1});"]

    return RK4.c_lines(ind, [("x", "xt", "NX", "k"), ("integ", "zt", "N", "r")], slopes,
                       "/* x += dt/6 (k1 + 2 k2 + 2 k3 + k4), the same for z */")


def simulation_source(n: int, prefix: str, has_gravity: bool, has_mass: bool,
                      runtime: int = 0) -> str:
    """C source of ``PREFIXsimulate``: fixed-step integration under a state-feedback law.

    The law, with ``e = reference_row - x`` (2 n) and ``e_q`` its first n entries::

        mode 0 (feedback):        tau = feedforward_row + gain e + integral_gain * integral(e_q)
        mode 1 (+ gravity):       the same + g(q)
        mode 2 (computed torque): tau = M(q) (feedforward_row + gain e) + C qd + g + friction

    then clipped to ``+-tau_limit``. ``method`` 0 is classical RK4, 1 semi-implicit (symplectic)
    Euler. With ``continuous`` 0 the law is sampled at the start of every step k (row k) and held
    over the step, as a digital controller running at the integration rate; the integral is
    ``dt sum(e_q)`` including the current sample. With ``continuous`` 1 (RK4 only) the law is
    evaluated at every stage, on the stage's state and time: ``feedforward`` and ``reference``
    then hold 2 steps + 1 rows sampled every dt/2, and the integral is a further state integrated
    by the same RK4; this is a continuous-time controller, tracked to the integrator's order.
    Null pointers mean zero (no feedforward, no reference, no gain, no limit). ``tau_out[k]`` is
    the law at the start of step k. Returns 0, or k + 1 when the state stopped being finite at
    step k. With ``runtime`` > 0 parameters left as kernel inputs it takes their values
    ``params`` (runtime,).
    """
    sd = f"{prefix}state_derivative"
    law = f"{prefix}control_law"
    p = ", params" if runtime else ""
    args = "feedforward, reference, gain, integral_gain, mode, tau_limit" + p
    lines = _law_source(n, prefix, has_gravity, has_mass, runtime) + [
        "/* e_q = q_ref - q at sample `row`: the rate of the error integral. */",
        f"static void {prefix}error_rate(long row, const double *x, const double *reference, "
        "double *out) {",
        f"    for (int i = 0; i < {n}; ++i) out[i] = (reference ? reference[row * {2 * n} + i] : 0.0)"
        " - x[i];",
        "}",
        "",
        f"/* Integrate {n}-joint dynamics for `steps` steps of `dt` s (see robodyn.codegen.c). */",
        simulate_signature(prefix, runtime) + " {",
        f"    enum {{ N = {n}, NX = {2 * n} }};",
        "    double x[NX], xt[NX], k1[NX], k2[NX], k3[NX], k4[NX], tau[N], ts[N], integ[N], zt[N];",
        "    double r1[N], r2[N], r3[N], r4[N];",
        "    const int staged = continuous && method == 0;",
        "    for (int i = 0; i < NX; ++i) x[i] = x_out[i] = x0[i];",
        "    for (int i = 0; i < N; ++i) integ[i] = 0.0;",
        "    for (long k = 0; k < steps; ++k) {",
        "        if (staged) {",
        "            /* RK4 with the law at every stage (rows 2k, 2k+1, 2k+1, 2k+2 at t, t+dt/2, t+dt)",
        "               and the error integral z as extra state: z' = e_q */",
        *_staged_rk4(prefix, args, p),
        "        } else {",
        "            /* sampled law, held over the step; integral += e_q dt first */",
        "            const long row = continuous ? 2 * k : k;",
        f"            {prefix}error_rate(row, x, reference, r1);",
        "            for (int i = 0; i < N; ++i) integ[i] += r1[i] * dt;",
        f"            {law}(row, x, integ, {args}, tau);",
        "            if (method == 0) {",
        "                /* RK4: x += dt/6 (k1 + 2 k2 + 2 k3 + k4) */",
        *RK4.c_lines("                ", [("x", "xt", "NX", "k")],
                     lambda i, at: [f"                {sd}({at[0]}, tau{p}, k{i + 1});"]),
        "            } else {",
        *semi_implicit_c_lines("                ", "x", "k1", [f"                {sd}(x, tau{p}, k1);"]),
        "            }",
        "        }",
        "        for (int i = 0; i < NX; ++i) {",
        "            if (!isfinite(x[i])) return (int)(k + 1);",
        "            x_out[(k + 1) * NX + i] = x[i];",
        "        }",
        "        if (tau_out) for (int i = 0; i < N; ++i) tau_out[k * N + i] = tau[i];",
        "    }",
        "    return 0;",
        "}",
    ]
    return "\n".join(lines) + "\n"
