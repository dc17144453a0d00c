"""Julia: one module ``<robot>.jl`` with in-place kernels and allocating wrappers.

For each kernel ``k`` (outputs first, as Julia's ``!`` convention has it)::

    k!(out, in1, ...)    fill ``out`` for one state, return it (no allocation)
    k(in1, ...)          allocate and return ``out`` (vectors in, one state)
    k(in1, ...)          matrices in: one state per column; ``n x N``, ``r x c x N`` out

Indices are 1-based and matrices are indexed naturally, ``M[i, j]`` (Julia arrays are
column-major; nothing here depends on memory order). The element type of the outputs is promoted
from the inputs, so dual numbers (ForwardDiff) pass through.

Julia is not installed where robodyn is tested (no Debian or PyPI package), so this printer is
checked structurally only: every kernel present, blocks balanced, every index within its array.
"""

from __future__ import annotations

import sympy as sp
from sympy.printing.julia import JuliaCodePrinter

from robodyn.codegen.base import NATURAL, GeneratedFile, Printer, identifier
from robodyn.codegen.fortran import float_literal
from robodyn.codegen.kernels import Argument, Kernel, KernelSet


class _JuliaExpr(JuliaCodePrinter):
    """SymPy's Julia printer for scalars: exact literals, no broadcasting dots, a ternary step."""

    def _print_Float(self, expr: sp.Float) -> str:  # noqa: N802 - SymPy's hook name
        return float_literal(float(expr))

    def _print_Rational(self, expr: sp.Rational) -> str:  # noqa: N802
        # p // q would be a Rational{Int}: print a Float64 quotient instead
        return str(expr.p) if expr.q == 1 else f"({expr.p} / {expr.q})"

    def _print_Piecewise(self, expr: sp.Piecewise) -> str:  # noqa: N802
        (value, cond), (otherwise, _) = expr.args
        val = float_literal(float(value)) if value.is_Number else self._print(value)
        other = float_literal(float(otherwise)) if otherwise.is_Number else self._print(otherwise)
        return f"({self._print(cond)} ? {val} : {other})"


def _doc(text: str) -> str:
    """``text`` safe inside a Julia docstring (``$`` would interpolate)."""
    return text.replace("\\", "\\\\").replace("$", "\\$")


def _module_name(robot_name: str) -> str:
    """``trolley_double_pendulum`` -> ``TrolleyDoublePendulum``."""
    parts = [p for p in identifier(robot_name).split("_") if p]
    return "".join(p[:1].upper() + p[1:] for p in parts)


class JuliaPrinter(Printer):
    """Julia printer; ``prefix`` starts every function name (none by default: a module scopes them)."""

    language = "Julia"
    comment = "#"
    layout = NATURAL

    def __init__(self, prefix: str = "") -> None:
        super().__init__(prefix)
        self._printer = _JuliaExpr({"inline": True})

    def expr(self, e: sp.Expr) -> str:
        text = self._printer.doprint(sp.sympify(e))
        # every value is a scalar: plain operators instead of broadcasting ones
        return text.replace(" .* ", " * ").replace(" ./ ", " / ").replace(" .^ ", " ^ ")

    def open_function(self, kernel: Kernel) -> list[str]:
        out = kernel.outputs[0]
        ins = ", ".join(a.name for a in kernel.inputs)
        sizes = "; ".join(f"`{a.name}` {' x '.join(map(str, a.shape))}"
                          for a in (*kernel.inputs, *kernel.outputs))
        lines = ['"""', f"    {self.prefix}{kernel.name}!({out.name}, {ins}) -> {out.name}", "",
                 f"{_doc(kernel.summary)}. Sizes: {sizes}.", '"""']
        typed = ", ".join(f"{a.name}::AbstractArray" for a in (*kernel.outputs, *kernel.inputs))
        lines.append(f"function {self.prefix}{kernel.name}!({typed})")
        for a in (*kernel.inputs, *kernel.outputs):
            shape = ", ".join(map(str, a.shape))
            lines.append(f"    size({a.name}) == ({shape},) || throw(DimensionMismatch("
                         f"\"{a.name} must be {' x '.join(map(str, a.shape))}, got $(size({a.name}))\"))")
        lines.append("    @inbounds begin")
        return lines

    def close_function(self, kernel: Kernel) -> list[str]:
        return ["    end", f"    return {kernel.outputs[0].name}", "end"]

    def unpack(self, arg: Argument, index: int, symbol: sp.Symbol) -> str:
        return f"    {symbol.name} = {arg.name}[{index + 1}]"

    def assign(self, symbol: sp.Symbol, e: sp.Expr) -> str:
        return f"    {symbol.name} = {self.expr(e)}"

    def store(self, arg: Argument, index: tuple[int, ...], e: sp.Expr) -> str:
        where = ", ".join(str(i + 1) for i in index)
        return f"    {arg.name}[{where}] = {self.expr(e)}"

    def wrappers(self, kernel: Kernel) -> str:
        """The allocating methods: one state (vectors) and a batch (one state per column)."""
        out = kernel.outputs[0]
        name = f"{self.prefix}{kernel.name}"
        ins = ", ".join(a.name for a in kernel.inputs)
        eltype = ", ".join(f"eltype({a.name})" for a in kernel.inputs)
        shape = ", ".join(map(str, out.shape))
        colons = ", ".join([":"] * len(out.shape))
        dims = " x ".join(map(str, out.shape))
        vec = ", ".join(f"{a.name}::AbstractVector" for a in kernel.inputs)
        mat = ", ".join(f"{a.name}::AbstractMatrix" for a in kernel.inputs)
        views = ", ".join(f"view({a.name}, :, k)" for a in kernel.inputs)
        checks = [f"    size({a.name}, 2) == count || throw(DimensionMismatch("
                  f"\"{a.name} must have $count columns like {kernel.inputs[0].name}\"))"
                  for a in kernel.inputs[1:]]
        return "\n".join([
            '"""',
            f"    {name}({ins}) -> {out.name}",
            "",
            f"{_doc(kernel.summary)}. Vectors in: one state, `{out.name}` {dims} out.",
            f"Matrices in (one state per column, `count` columns): `{out.name}` {dims} x count out.",
            '"""',
            f"function {name}({vec})",
            f"    S = promote_type({eltype}, Float64)",
            f"    return {name}!(zeros(S, {shape}), {ins})",
            "end",
            "",
            f"function {name}({mat})",
            f"    S = promote_type({eltype}, Float64)",
            f"    count = size({kernel.inputs[0].name}, 2)",
            *checks,
            f"    {out.name} = zeros(S, {shape}, count)",
            "    for k in 1:count",
            f"        {name}!(view({out.name}, {colons}, k), {views})",
            "    end",
            f"    return {out.name}",
            "end",
        ]) + "\n"

    def module(self, kset: KernelSet) -> str:
        """The whole module text."""
        mod = _module_name(kset.robot_name)
        exports = [f"{self.prefix}{k.name}{bang}" for k in kset.kernels for bang in ("!", "")]
        parts = [
            self.header(kset).rstrip(),
            "# In this file indices are 1-based and matrices are indexed naturally, M[i, j].",
            "",
            f"module {mod}",
            "",
            f"export {', '.join(exports)}",
            "",
            f"\"Number of joints of {kset.robot_name}.\"",
            f"const DOF = {kset.dof}",
            "",
        ]
        for kernel in kset.kernels:
            parts.append(self.function(kernel))
            parts.append(self.wrappers(kernel))
        parts.append(f"end # module {mod}\n")
        return "\n".join(parts)


def julia_files(kset: KernelSet) -> list[GeneratedFile]:
    """``<robot>.jl`` (module ``CamelCaseRobotName``) for a kernel set."""
    return [GeneratedFile(f"{identifier(kset.robot_name)}.jl", JuliaPrinter().module(kset))]
