"""Fortran 90: one module ``<robot>.f90`` with a ``subroutine`` per kernel, callable from C.

For each kernel ``k`` of robot ``r`` the module defines (explicit-shape ``real(c_double)`` arrays,
that is ``real(8)`` with gfortran; locals are ``real(c_double)`` too)::

    subroutine r_k(in1, ..., out)                   one state
    subroutine r_k_batch(count, in1, ..., out)      count states: inputs (n, count), outputs (..., count)

Every subroutine is ``bind(c)`` with the same name in lower case, so it has the prototype of the
C function of :mod:`robodyn.codegen.c` with prefix ``r_`` (``count`` is passed by value as a
``long``): the C header ``c_files(kset, prefix="r_")[0]`` declares the Fortran library too.

The code is Fortran 90 apart from ``bind(c)`` and ``iso_c_binding`` (Fortran 2003, in every
current compiler); gfortran accepts it with ``-std=f2003 -pedantic``.

Memory order: an output matrix of ``rows x cols`` entries is declared ``A(cols, rows)`` and
``A(j, i)`` holds entry ``(i, j)``, so the Fortran array occupies memory exactly as the C
row-major array does (Fortran code that wants the matrix itself takes ``transpose(A)``; the mass
matrix is symmetric anyway). Batched outputs add a last dimension ``count``.
"""

from __future__ import annotations

import textwrap

import sympy as sp
from sympy.printing.fortran import FCodePrinter

from robodyn.codegen.base import GeneratedFile, Printer, identifier
from robodyn.codegen.kernels import Argument, Kernel, KernelSet
from robodyn.robot.errors import InputError

#: Longest line written before the printer's own wrapping (Fortran free form allows 132).
_WIDTH = 100
#: Longest Fortran 2003 name.
_NAME_LIMIT = 63


def float_literal(value: float, exponent: str = "e") -> str:
    """The shortest decimal that reads back as ``value``, with ``exponent`` as exponent letter.

    ``float_literal(0.5, "d") == "0.5d0"``: a double-precision Fortran literal.
    """
    text = repr(float(value))
    mantissa, _, exp = text.partition("e")
    if "." not in mantissa and mantissa.lstrip("-").isdigit():
        mantissa += ".0"
    if exponent == "d":
        return f"{mantissa}d{exp or '0'}"
    return f"{mantissa}e{exp}" if exp else mantissa


class _FExpr(FCodePrinter):
    """SymPy's Fortran printer with exact double literals and ``merge`` for the step function."""

    def _format_code(self, lines: list[str]) -> list[str]:
        # whole statements are wrapped once, by FortranPrinter._wrap
        return lines

    def _print_Float(self, expr: sp.Float) -> str:  # noqa: N802 - SymPy's hook name
        return float_literal(float(expr), "d")

    def _print_Piecewise(self, expr: sp.Piecewise) -> str:  # noqa: N802
        (value, cond), (otherwise, _) = expr.args
        # merge(tsource, fsource, mask): both sources real(c_double)
        return (f"merge({self._print(sp.Float(value) if value.is_Number else value)}, "
                f"{self._print(sp.Float(otherwise) if otherwise.is_Number else otherwise)}, "
                f"{self._print(cond)})")


def _fortran_shape(arg: Argument) -> tuple[int, ...]:
    """Declared shape: vectors as they are, matrices transposed (C memory order)."""
    return arg.shape if len(arg.shape) == 1 else (arg.shape[1], arg.shape[0])


def _join_declaration(head: str, names: list[str], indent: str) -> list[str]:
    """``head :: a, b, ...`` split over as many lines as needed."""
    lines, current = [], []
    for name in names:
        if current and len(indent + head + ", ".join([*current, name])) > _WIDTH:
            lines.append(f"{indent}{head} :: {', '.join(current)}")
            current = []
        current.append(name)
    if current:
        lines.append(f"{indent}{head} :: {', '.join(current)}")
    return lines


class FortranPrinter(Printer):
    """Fortran 90 (free form) printer; ``prefix`` starts every subroutine name."""

    language = "Fortran 90/2003"
    comment = "!"
    indent = "    "

    def __init__(self, prefix: str = "robodyn_") -> None:
        super().__init__(prefix)
        self._printer = _FExpr({"source_format": "free", "standard": 95, "name_mangling": False})

    def expr(self, e: sp.Expr) -> str:
        return self._printer.doprint(sp.sympify(e))

    def header(self, kset: KernelSet) -> str:
        """The provenance header, wrapped to stay within free form's 132 columns."""
        lines = []
        for line in super().header(kset).splitlines():
            lines += textwrap.wrap(line, _WIDTH, subsequent_indent="!   ", break_long_words=False)
        return "\n".join(lines) + "\n"

    def _wrap(self, line: str) -> str:
        """One statement, continued with ``&`` where longer than the printer's width."""
        return "\n".join(self._printer._wrap_fortran([line]))

    def _signature(self, name: str, args: list[str]) -> list[str]:
        # the bind(c) label goes on a continuation line of its own: never split inside a string
        return [f"  subroutine {name}({', '.join(args)}) &",
                f"      bind(c, name=\"{name.lower()}\")"]

    def open_function(self, kernel: Kernel) -> list[str]:
        name = f"{self.prefix}{kernel.name}"
        shapes = ", ".join(f"{a.name}{list(a.shape)}" for a in (*kernel.inputs, *kernel.outputs))
        lines = [f"  ! {kernel.summary}.", f"  ! Arrays (row-major entries): {shapes}."]
        lines += self._signature(name, [a.name for a in (*kernel.inputs, *kernel.outputs)])
        dims = [f"{a.name}({', '.join(map(str, a.shape))})" for a in kernel.inputs]
        lines += _join_declaration("real(c_double), intent(in)", dims, self.indent)
        outs = [f"{a.name}({', '.join(map(str, _fortran_shape(a)))})" for a in kernel.outputs]
        lines += _join_declaration("real(c_double), intent(out)", outs, self.indent)
        scalars = [s.name for _, _, s in kernel.used_inputs()] + [s.name for s in kernel.locals]
        lines += _join_declaration("real(c_double)", scalars, self.indent)
        return lines

    def close_function(self, kernel: Kernel) -> list[str]:
        return [f"  end subroutine {self.prefix}{kernel.name}"]

    def unpack(self, arg: Argument, index: int, symbol: sp.Symbol) -> str:
        return f"{symbol.name} = {arg.name}({index + 1})"

    def assign(self, symbol: sp.Symbol, e: sp.Expr) -> str:
        return self._wrap(f"{symbol.name} = {self.expr(e)}")

    def store(self, arg: Argument, index: tuple[int, ...], e: sp.Expr) -> str:
        # matrices are declared transposed: A(j, i) holds entry (i, j)
        where = ", ".join(str(i + 1) for i in reversed(index))
        return self._wrap(f"{arg.name}({where}) = {self.expr(e)}")

    def batch(self, kernel: Kernel) -> str:
        """The loop over ``count`` states (the last dimension of every array)."""
        name = f"{self.prefix}{kernel.name}"
        args = [a.name for a in (*kernel.inputs, *kernel.outputs)]
        ind = self.indent
        lines = [f"  ! {kernel.name} for count states: inputs (n, count), outputs (..., count)."]
        lines += self._signature(f"{name}_batch", ["count", *args])
        lines.append(f"{ind}integer(c_long), value, intent(in) :: count")
        dims = [f"{a.name}({', '.join(map(str, a.shape))}, count)" for a in kernel.inputs]
        lines += _join_declaration("real(c_double), intent(in)", dims, ind)
        outs = [f"{a.name}({', '.join(map(str, _fortran_shape(a)))}, count)" for a in kernel.outputs]
        lines += _join_declaration("real(c_double), intent(out)", outs, ind)
        lines.append(f"{ind}integer(c_long) :: k")
        sections = [f"{a.name}({', '.join([':'] * len(a.shape))}, k)"
                    for a in (*kernel.inputs, *kernel.outputs)]
        lines += [f"{ind}do k = 1, count",
                  self._wrap(f"{ind}{ind}call {name}({', '.join(sections)})"),
                  f"{ind}end do",
                  f"  end subroutine {name}_batch"]
        return "\n".join(lines) + "\n"

    def module(self, kset: KernelSet) -> str:
        """The whole module text."""
        mod = identifier(kset.robot_name)
        names = [f"{self.prefix}{k.name}{suffix}" for k in kset.kernels for suffix in ("", "_batch")]
        too_long = [nm for nm in [mod, *names] if len(nm) > _NAME_LIMIT]
        if too_long:
            raise InputError(f"Fortran names are at most {_NAME_LIMIT} characters: {', '.join(too_long)}; "
                             "pass a shorter prefix to fortran_files or rename the robot")
        parts = [
            self.header(kset).rstrip(),
            "! Matrix outputs A (rows x cols) are declared A(cols, rows) with A(j, i) = entry (i, j):",
            "! the same memory as the C row-major array. Every subroutine is bind(c), same name.",
            f"module {mod}",
            "    use, intrinsic :: iso_c_binding, only: c_double, c_long",
            "    implicit none",
            "    private",
            f"    integer, parameter, public :: {self.prefix}dof = {kset.dof}",
            *_join_declaration("public", names, "    "),
            "contains",
            "",
        ]
        for kernel in kset.kernels:
            parts.append(self.function(kernel))
            parts.append(self.batch(kernel))
        parts.append(f"end module {mod}\n")
        return "\n".join(parts)


def fortran_files(kset: KernelSet, prefix: str | None = None) -> list[GeneratedFile]:
    """``<robot>.f90`` for a kernel set (subroutines prefixed ``<robot>_`` unless ``prefix``)."""
    stem = identifier(kset.robot_name)
    printer = FortranPrinter(f"{stem}_" if prefix is None else prefix)
    return [GeneratedFile(f"{stem}.f90", printer.module(kset))]
