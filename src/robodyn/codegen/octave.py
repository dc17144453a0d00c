"""MATLAB/Octave: one function file ``<robot>_<kernel>.m`` per kernel, vectorised over states.

Inputs are column vectors (one state) or ``n x N`` matrices (``N`` states as columns); every
statement works on ``1 x N`` rows with element-wise operators, so a batch costs one pass through
the code, not a loop. Outputs::

    vectors        n x N           (n x 1 for one state)
    matrices       r x c x N       (r x c for one state: MATLAB drops the trailing 1)

Matrices are indexed naturally, ``M(i, j, k)`` is entry ``(i, j)`` of state ``k``.
"""

from __future__ import annotations

import sympy as sp
from sympy.printing.octave import OctaveCodePrinter

from robodyn.codegen.base import NATURAL, GeneratedFile, Printer, identifier, provenance
from robodyn.codegen.fortran import float_literal
from robodyn.codegen.kernels import Argument, Kernel, KernelSet
from robodyn.robot.errors import InputError


class _OctaveExpr(OctaveCodePrinter):
    """SymPy's Octave printer (element-wise operators) with exact double literals."""

    def _print_Float(self, expr: sp.Float) -> str:  # noqa: N802 - SymPy's hook name
        return float_literal(float(expr))


class OctavePrinter(Printer):
    """MATLAB/Octave printer; function names are ``prefix + kernel name``."""

    language = "MATLAB/Octave"
    comment = "%"
    layout = NATURAL
    indent = "  "

    def __init__(self, prefix: str = "robodyn_") -> None:
        super().__init__(prefix)
        self._printer = _OctaveExpr({"inline": True})
        self._provenance: list[str] = []

    def expr(self, e: sp.Expr) -> str:
        return self._printer.doprint(sp.sympify(e))

    def open_function(self, kernel: Kernel) -> list[str]:
        name = f"{self.prefix}{kernel.name}"
        out = kernel.outputs[0]
        ins = [a.name for a in kernel.inputs]
        dims = "x".join(map(str, out.shape))
        sizes = ", ".join(f"{a.name} {a.shape[0]}xN" for a in kernel.inputs)
        lines = [
            f"function {out.name} = {name}({', '.join(ins)})",
            f"%{name.upper()} {kernel.summary}.",
            f"%   {out.name} = {name}({', '.join(ins)}) with {sizes} (N states as columns)",
            f"%   returns {out.name} {dims}xN ({dims} for one state).",
            *(f"%   {line}" for line in self._provenance),
            f"  if nargin ~= {len(ins)}",
            f"    error('robodyn:nargin', '{name} takes {len(ins)} input{'s' * (len(ins) > 1)} "
            f"({', '.join(ins)}), got %d', nargin);",
            "  end",
        ]
        for k, a in enumerate(kernel.inputs):
            lines += [
                f"  if ~isa({a.name}, 'double') || ~isreal({a.name}) || ndims({a.name}) ~= 2 "
                f"|| size({a.name}, 1) ~= {a.shape[0]}",
                f"    error('robodyn:size', '{name}: {a.name} must be a real {a.shape[0]}xN matrix, "
                f"got %s', mat2str(size({a.name})));",
                "  end",
            ]
            if k == 0:
                lines.append(f"  N = size({a.name}, 2);")
            else:
                lines += [f"  if size({a.name}, 2) ~= N",
                          f"    error('robodyn:size', '{name}: {a.name} must have %d columns like "
                          f"{ins[0]}, got %d', N, size({a.name}, 2));",
                          "  end"]
        # outputs as (entries, N), reshaped at the end
        lines.append(f"  {out.name} = zeros({out.size}, N);")
        return lines

    def close_function(self, kernel: Kernel) -> list[str]:
        out = kernel.outputs[0]
        lines = []
        if len(out.shape) == 2:
            lines.append(f"  {out.name} = reshape({out.name}, {out.shape[0]}, {out.shape[1]}, N);")
        return [*lines, "end"]

    def unpack(self, arg: Argument, index: int, symbol: sp.Symbol) -> str:
        return f"{symbol.name} = {arg.name}({index + 1}, :);"

    def assign(self, symbol: sp.Symbol, e: sp.Expr) -> str:
        return f"{symbol.name} = {self.expr(e)};"

    def store(self, arg: Argument, index: tuple[int, ...], e: sp.Expr) -> str:
        # entry (i, j) of an r x c matrix is row i + (j - 1) r of the column-major (r c) x N array
        row = index[0] + 1 if len(index) == 1 else index[0] + index[1] * arg.shape[0] + 1
        return f"{arg.name}({row}, :) = {self.expr(e)};"

    def files(self, kset: KernelSet) -> list[GeneratedFile]:
        """One function file per kernel; the provenance header is part of each help text."""
        too_long = [f"{self.prefix}{k}" for k in kset.names if len(f"{self.prefix}{k}") > 63]
        if too_long:
            raise InputError(f"MATLAB names are at most 63 characters (namelengthmax): "
                             f"{', '.join(too_long)}; pass a shorter prefix to octave_files")
        self._provenance = [*provenance(kset, self.language, self.layout),
                            "In this file matrices are indexed naturally, M(i, j, k) (column-major)."]
        return [GeneratedFile(f"{self.prefix}{kernel.name}.m", self.function(kernel))
                for kernel in kset.kernels]


def octave_files(kset: KernelSet, prefix: str | None = None) -> list[GeneratedFile]:
    """``<robot>_<kernel>.m`` for every kernel (function names prefixed ``<robot>_``)."""
    printer = OctavePrinter(f"{identifier(kset.robot_name)}_" if prefix is None else prefix)
    return printer.files(kset)
