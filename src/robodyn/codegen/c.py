"""C99: reentrant kernels (no globals, no allocation), batched loops and in-C integrators.

For each kernel ``k`` the source defines::

    void PREFIXk(const double *in1, ..., double *out);                    one state
    void PREFIXk_batch(long count, const double *in1, ..., double *out);  count states, looped in C

plus :func:`simulation_source`'s ``PREFIXsimulate``: a whole trajectory (RK4 or semi-implicit
Euler) with a sampled (zero-order-hold) state-feedback controller, in one call.
"""

from __future__ import annotations

import sympy as sp
from sympy.printing.c import C99CodePrinter

from robodyn.codegen.base import GeneratedFile, Printer
from robodyn.codegen.kernels import Argument, Kernel, KernelSet


class _CExpr(C99CodePrinter):
    """SymPy's C99 printer with one-line conditionals and exact doubles."""

    def _print_Piecewise(self, expr: sp.Piecewise) -> str:  # noqa: N802 - SymPy's hook name
        (value, cond), (otherwise, _) = expr.args
        return (f"(({self._print(cond)}) ? {self._print(sp.Float(value))} : "
                f"{self._print(sp.Float(otherwise))})")


class CPrinter(Printer):
    """C99 printer; ``prefix`` starts every exported function name."""

    language = "C99"
    comment = "//"

    def __init__(self, prefix: str = "robodyn_") -> None:
        super().__init__(prefix)
        self._printer = _CExpr({"precision": 17})

    def expr(self, e: sp.Expr) -> str:
        return self._printer.doprint(e)

    def signature(self, kernel: Kernel, batch: bool = False) -> str:
        """The C prototype (without the trailing semicolon)."""
        args = [f"const double *restrict {a.name}" for a in kernel.inputs]
        args += [f"double *restrict {a.name}" for a in kernel.outputs]
        if batch:
            return f"void {self.prefix}{kernel.name}_batch(long count, {', '.join(args)})"
        return f"void {self.prefix}{kernel.name}({', '.join(args)})"

    def open_function(self, kernel: Kernel) -> list[str]:
        shapes = ", ".join(f"{a.name}{list(a.shape)}" for a in (*kernel.inputs, *kernel.outputs))
        return [f"/* {kernel.summary}. Arrays: {shapes}. */", self.signature(kernel) + " {"]

    def close_function(self, kernel: Kernel) -> list[str]:
        return ["}"]

    def unpack(self, arg: Argument, index: int, symbol: sp.Symbol) -> str:
        return f"const double {symbol.name} = {arg.name}[{index}];"

    def assign(self, symbol: sp.Symbol, e: sp.Expr) -> str:
        return f"const double {symbol.name} = {self.expr(e)};"

    def store(self, arg: Argument, index: tuple[int, ...], e: sp.Expr) -> str:
        flat = index[0] if len(index) == 1 else index[0] * arg.shape[1] + index[1]
        return f"{arg.name}[{flat}] = {self.expr(e)};"

    def batch(self, kernel: Kernel) -> str:
        """The loop over ``count`` states, calling the one-state function."""
        strides = [a.size for a in (*kernel.inputs, *kernel.outputs)]
        names = [a.name for a in (*kernel.inputs, *kernel.outputs)]
        call = ", ".join(f"{nm} + k * {st}" for nm, st in zip(names, strides, strict=True))
        return "\n".join([
            f"/* {kernel.name} for count states stored one after another. */",
            self.signature(kernel, batch=True) + " {",
            "    for (long k = 0; k < count; ++k) {",
            f"        {self.prefix}{kernel.name}({call});",
            "    }",
            "}",
        ]) + "\n"

    def declarations(self, kset: KernelSet, with_simulation: bool = True) -> str:
        """Prototypes of every exported function, one per line (a header, and cffi's cdef)."""
        lines = []
        for kernel in kset.kernels:
            lines.append(self.signature(kernel).replace("restrict ", "") + ";")
            lines.append(self.signature(kernel, batch=True).replace("restrict ", "") + ";")
        if with_simulation and "state_derivative" in kset.names:
            lines.append(simulate_signature(self.prefix) + ";")
        return "\n".join(lines) + "\n"

    def source(self, kset: KernelSet, with_simulation: bool = True) -> str:
        """The whole translation unit."""
        parts = [self.header(kset), "#include <math.h>\n"]
        for kernel in kset.kernels:
            parts.append(self.function(kernel))
            parts.append(self.batch(kernel))
        if with_simulation and "state_derivative" in kset.names:
            parts.append(simulation_source(kset.dof, self.prefix, "gravity" in kset.names,
                                           "mass_matrix" in kset.names))
        return "\n".join(parts)


def simulate_signature(prefix: str) -> str:
    """Prototype of the in-C trajectory integrator."""
    return (f"int {prefix}simulate(long steps, double dt, int method, const double *x0, "
            "const double *feedforward, const double *reference, const double *gain, "
            "const double *integral_gain, int mode, const double *tau_limit, "
            "double *x_out, double *tau_out)")


def simulation_source(n: int, prefix: str, has_gravity: bool, has_mass: bool) -> str:
    """C source of ``PREFIXsimulate``: fixed-step integration with a sampled controller.

    At every step ``k`` (zero-order hold over the step, as a digital controller running at the
    integration rate), with ``e = reference_k - x`` (2 n) and ``e_q`` its first n entries::

        mode 0 (feedback):        tau = feedforward_k + gain e + integral_gain * sum(e_q dt)
        mode 1 (+ gravity):       the same + g(q)
        mode 2 (computed torque): tau = M(q) (feedforward_k + gain e) + C qd + g + friction

    then clipped to ``+-tau_limit``. ``method`` 0 is classical RK4, 1 semi-implicit (symplectic)
    Euler. Null pointers mean zero (no feedforward, no reference, no gain, no limit). Returns 0,
    or k + 1 when the state stopped being finite at step k.
    """
    sd = f"{prefix}state_derivative"
    lines = [
        f"/* Integrate {n}-joint dynamics for `steps` steps of `dt` s (see robodyn.codegen.c). */",
        simulate_signature(prefix) + " {",
        f"    enum {{ N = {n}, NX = {2 * n} }};",
        "    double x[NX], xt[NX], k1[NX], k2[NX], k3[NX], k4[NX], tau[N], integ[N], e[NX];",
        "    for (int i = 0; i < NX; ++i) x[i] = x_out[i] = x0[i];",
        "    for (int i = 0; i < N; ++i) integ[i] = 0.0;",
        "    for (long k = 0; k < steps; ++k) {",
        "        /* e = reference_k - x */",
        "        for (int i = 0; i < NX; ++i) e[i] = (reference ? reference[k * NX + i] : 0.0) - x[i];",
        "        for (int i = 0; i < N; ++i) integ[i] += e[i] * dt;",
        "        /* v = feedforward_k + gain e + integral_gain * integral(e_q) */",
        "        double v[N];",
        "        for (int i = 0; i < N; ++i) {",
        "            double s = feedforward ? feedforward[k * N + i] : 0.0;",
        "            if (gain) for (int j = 0; j < NX; ++j) s += gain[i * NX + j] * e[j];",
        "            if (integral_gain) s += integral_gain[i] * integ[i];",
        "            v[i] = s;",
        "        }",
    ]
    if has_mass:
        lines += [
            "        if (mode == 2) {",
            "            /* computed torque: tau = M(q) v + (C qd + g + friction) */",
            "            double m[N * N], h[N], zero[N];",
            "            for (int i = 0; i < N; ++i) zero[i] = 0.0;",
            f"            {prefix}mass_matrix(x, m);",
            f"            {prefix}inverse_dynamics(x, x + N, zero, h);",
            "            for (int i = 0; i < N; ++i) {",
            "                double s = h[i];",
            "                for (int j = 0; j < N; ++j) s += m[i * N + j] * v[j];",
            "                tau[i] = s;",
            "            }",
            "        } else {",
            "            for (int i = 0; i < N; ++i) tau[i] = v[i];",
            "        }",
        ]
    else:
        lines += ["        for (int i = 0; i < N; ++i) tau[i] = v[i];"]
    if has_gravity:
        lines += [
            "        if (mode == 1) {",
            "            /* gravity compensation: tau += g(q) */",
            "            double gq[N];",
            f"            {prefix}gravity(x, gq);",
            "            for (int i = 0; i < N; ++i) tau[i] += gq[i];",
            "        }",
        ]
    lines += [
        "        if (tau_limit) for (int i = 0; i < N; ++i) {",
        "            if (tau[i] > tau_limit[i]) tau[i] = tau_limit[i];",
        "            if (tau[i] < -tau_limit[i]) tau[i] = -tau_limit[i];",
        "        }",
        "        if (method == 0) {",
        "            /* RK4: x += dt/6 (k1 + 2 k2 + 2 k3 + k4) */",
        f"            {sd}(x, tau, k1);",
        "            for (int i = 0; i < NX; ++i) xt[i] = x[i] + 0.5 * dt * k1[i];",
        f"            {sd}(xt, tau, k2);",
        "            for (int i = 0; i < NX; ++i) xt[i] = x[i] + 0.5 * dt * k2[i];",
        f"            {sd}(xt, tau, k3);",
        "            for (int i = 0; i < NX; ++i) xt[i] = x[i] + dt * k3[i];",
        f"            {sd}(xt, tau, k4);",
        "            for (int i = 0; i < NX; ++i)",
        "                x[i] += dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);",
        "        } else {",
        "            /* semi-implicit Euler: qd += dt qdd(q, qd); q += dt qd (new qd) */",
        f"            {sd}(x, tau, k1);",
        "            for (int i = 0; i < N; ++i) x[N + i] += dt * k1[N + i];",
        "            for (int i = 0; i < N; ++i) x[i] += dt * x[N + i];",
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


def c_files(kset: KernelSet, prefix: str = "robodyn_", with_simulation: bool = True) -> list[GeneratedFile]:
    """``<robot>.h`` and ``<robot>.c`` for a kernel set."""
    printer = CPrinter(prefix)
    stem = kset.robot_name
    guard = f"ROBODYN_{stem.upper()}_H".replace("-", "_")
    header = "\n".join([printer.header(kset).rstrip(), f"#ifndef {guard}", f"#define {guard}",
                        printer.declarations(kset, with_simulation).rstrip(), "#endif", ""])
    source = printer.source(kset, with_simulation)
    return [GeneratedFile(f"{stem}.h", header), GeneratedFile(f"{stem}.c", source)]
