"""Python/NumPy: one module, every kernel vectorised over leading batch dimensions.

Each function takes arrays whose last axis holds the joint values (``q[..., j]``) and returns an
array of shape ``batch + output shape``, so one state and a batch of states use the same code.
"""

from __future__ import annotations

import sympy as sp
from sympy.printing.numpy import NumPyPrinter

from robodyn.codegen.base import GeneratedFile, Printer, identifier
from robodyn.codegen.kernels import Argument, Kernel, KernelSet


class PythonPrinter(Printer):
    """NumPy printer (``numpy`` imported as ``numpy``)."""

    language = "Python/NumPy"
    comment = "#"

    def __init__(self, prefix: str = "") -> None:
        super().__init__(prefix)
        self._printer = NumPyPrinter({"fully_qualified_modules": True, "allow_unknown_functions": False})

    def expr(self, e: sp.Expr) -> str:
        if e.is_Number:
            return repr(float(e))
        return self._printer.doprint(e)

    def open_function(self, kernel: Kernel) -> list[str]:
        args = ", ".join(a.name for a in kernel.inputs)
        shapes = "; ".join(f"{a.name}: (..., {', '.join(map(str, a.shape))})"
                           for a in (*kernel.inputs, *kernel.outputs))
        return [f"def {self.prefix}{kernel.name}({args}):", f'    """{kernel.summary}.', "",
                f"    Shapes: {shapes}.", '    """']

    def close_function(self, kernel: Kernel) -> list[str]:
        return [f"    return {', '.join(a.name for a in kernel.outputs)}", ""]

    def unpack(self, arg: Argument, index: int, symbol: sp.Symbol) -> str:
        return f"{symbol.name} = {arg.name}[..., {index}]"

    def assign(self, symbol: sp.Symbol, e: sp.Expr) -> str:
        return f"{symbol.name} = {self.expr(e)}"

    def store(self, arg: Argument, index: tuple[int, ...], e: sp.Expr) -> str:
        where = ", ".join(str(i) for i in index)
        return f"{arg.name}[..., {where}] = {self.expr(e)}"

    def function(self, kernel: Kernel) -> str:
        text = super().function(kernel)
        # allocate the outputs once the batch shape is known (after unpacking the inputs)
        batch = " + ".join(f"{a.name}.shape[:-1]" for a in kernel.inputs)
        ins = ", ".join(f"{a.name}.shape[:-1]" for a in kernel.inputs)
        alloc = [f"    _batch = numpy.broadcast_shapes({ins})" if len(kernel.inputs) > 1
                 else f"    _batch = {batch}"]
        alloc += [f"    {a.name} = numpy.empty(_batch + {a.shape!r})" for a in kernel.outputs]
        lines = text.splitlines()
        first_store = next(i for i, ln in enumerate(lines)
                           if any(ln.startswith(f"    {a.name}[...") for a in kernel.outputs))
        return "\n".join(lines[:first_store] + alloc + lines[first_store:]) + "\n"

    def module(self, kset: KernelSet) -> str:
        """The whole module text."""
        parts = [self.header(kset), "import numpy\n", f"DOF = {kset.dof}\n"]
        parts += [self.function(k) for k in kset.kernels]
        return "\n\n".join(parts)


def python_files(kset: KernelSet) -> list[GeneratedFile]:
    """``<robot>.py`` for a kernel set."""
    return [GeneratedFile(f"{identifier(kset.robot_name)}.py", PythonPrinter().module(kset))]
