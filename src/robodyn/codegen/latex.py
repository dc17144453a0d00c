r"""LaTeX: every kernel as a sequence of equations, in one standalone ``<robot>.tex`` document.

Each kernel is a section with an ``align*`` environment (split into several after
:data:`ROWS_PER_ALIGN` rows, so that TeX's memory never runs out on the regressor): the
intermediate variables in evaluation order, then the nonzero output entries. Names are typeset
from the program's identifiers: ``t12`` as :math:`t_{12}`, ``a2_x`` as :math:`a_{2,x}`,
``wyy2`` as :math:`\mathrm{wyy}_{2}`; inputs as :math:`q_j`, :math:`\dot q_j`, :math:`\ddot q_j`,
:math:`\tau_j`; outputs in bold. Sums longer than :data:`LINE_BUDGET` characters of LaTeX source
continue on the next row. Coulomb friction's step function is an Iverson bracket ``[x > 0]``.

The document needs only ``amsmath`` (part of every LaTeX installation); compile with ``pdflatex <robot>.tex``.
"""

from __future__ import annotations

import re

import sympy as sp
from sympy.printing.latex import LatexPrinter

from robodyn.codegen.base import GeneratedFile, identifier, provenance
from robodyn.codegen.kernels import Kernel, KernelSet
from robodyn.text import latex_document, tex_escape

#: Longest row of LaTeX source before a sum continues on the next row.
LINE_BUDGET = 110
#: Rows per ``align*`` environment.
ROWS_PER_ALIGN = 150

_OUTPUT_NAMES = {"tau": r"\boldsymbol{\tau}", "qdd": r"\ddot{\mathbf{q}}", "xd": r"\dot{\mathbf{x}}"}
_INPUT = re.compile(r"(qdd|qd|q|u)(\d+)")
_INPUT_TEX = {"q": "q", "qd": r"\dot{q}", "qdd": r"\ddot{q}", "u": r"\tau"}
_LOCAL = re.compile(r"([A-Za-z]+)(\d*)((?:_[A-Za-z0-9]+)*)")


class _LatexExpr(LatexPrinter):
    """SymPy's LaTeX printer with an Iverson bracket for the unit step."""

    def _print_Piecewise(self, expr: sp.Piecewise) -> str:  # noqa: N802 - SymPy's hook name
        (value, cond), (otherwise, _) = expr.args
        if value == 1 and otherwise == 0:
            # [cond] is 1 where cond holds, else 0
            return rf"\left[{self._print(cond)}\right]"
        return super()._print_Piecewise(expr)


def local_name(name: str) -> str:
    """LaTeX for a program identifier: ``t12`` -> ``t_{12}``, ``M_fM3_2_x`` -> ``M_{\\mathrm{fM3},2,x}``."""
    match = _INPUT.fullmatch(name)
    if match:
        return f"{_INPUT_TEX[match[1]]}_{{{match[2]}}}"
    match = _LOCAL.fullmatch(name)
    if not match:
        return rf"\mathtt{{{tex_escape(name)}}}"
    head, digits, rest = match.groups()
    subs = [digits] if digits else []
    subs += [p if re.fullmatch(r"\d+|[A-Za-z]", p) else rf"\mathrm{{{p}}}" for p in rest.split("_") if p]
    base = head if len(head) == 1 else rf"\mathrm{{{head}}}"
    return f"{base}_{{{','.join(subs)}}}" if subs else base


def _symbol_names(kernel: Kernel) -> dict[sp.Symbol, str]:
    """Typeset names of every symbol of a kernel, distinct (``\\mathtt`` where two would clash)."""
    names: dict[sp.Symbol, str] = {}
    taken: set[str] = set()
    symbols = [s for a in kernel.inputs for s in a.entries] + list(kernel.locals)
    for sym in symbols:
        if sym in names:
            continue
        tex = local_name(sym.name)
        if tex in taken:
            tex = rf"\mathtt{{{tex_escape(sym.name)}}}"
        taken.add(tex)
        names[sym] = tex
    return names


class LatexDocumentPrinter:
    """Kernels as LaTeX equations (not a :class:`~robodyn.codegen.base.Printer`: no functions)."""

    language = "LaTeX"

    def rows(self, kernel: Kernel) -> list[str]:
        """``lhs &= rhs`` rows of one kernel, long sums continued on further rows."""
        printer = _LatexExpr({"symbol_names": _symbol_names(kernel)})
        out = kernel.outputs[0]
        out_tex = _OUTPUT_NAMES.get(out.name, rf"\mathbf{{{out.name}}}")
        rows = []
        for sym, e in kernel.body:
            rows += self._split(printer, printer._print(sym), e)
        for k, e in enumerate(out.entries):
            e = sp.sympify(e)
            if e == 0:
                continue
            index = (k,) if len(out.shape) == 1 else divmod(k, out.shape[1])
            lhs = f"{out_tex}_{{{','.join(str(i + 1) for i in index)}}}"
            rows += self._split(printer, lhs, e)
        return rows

    @staticmethod
    def _split(printer: _LatexExpr, lhs: str, e: sp.Expr) -> list[str]:
        terms = e.as_ordered_terms() if e.is_Add else [e]
        pieces = []
        for k, term in enumerate(terms):
            negative = term.could_extract_minus_sign()
            sign = "- " if negative else ("+ " if k else "")
            pieces.append(sign + printer.doprint(-term if negative else term))
        rows, current = [], f"{lhs} &= {pieces[0]}"
        for piece in pieces[1:]:
            if len(current) + len(piece) + 1 > LINE_BUDGET:
                rows.append(current)
                # {} keeps the sign binary at the start of a continuation row
                current = rf"&\qquad {{}}{piece}"
            else:
                current += " " + piece
        rows.append(current)
        return rows

    def section(self, kernel: Kernel) -> str:
        """One kernel as a section with its equations."""
        title = kernel.name.replace("_", " ").capitalize()
        ins = ", ".join(rf"\texttt{{{tex_escape(a.name)}}} ({'x'.join(map(str, a.shape))})"
                        for a in kernel.inputs)
        out = kernel.outputs[0]
        rows = self.rows(kernel)
        parts = [rf"\section*{{{tex_escape(title)}}}",
                 f"{tex_escape(kernel.summary)}. Inputs: {ins}; output "
                 rf"\texttt{{{tex_escape(out.name)}}} ({'x'.join(map(str, out.shape))}), "
                 f"{len(kernel.body)} intermediate variables. Output entries not listed are zero.", ""]
        for start in range(0, len(rows), ROWS_PER_ALIGN):
            chunk = rows[start:start + ROWS_PER_ALIGN]
            parts += [r"\begin{align*}", " \\\\\n".join(chunk), r"\end{align*}"]
        return "\n".join(parts) + "\n"

    def document(self, kset: KernelSet) -> str:
        """The whole standalone document."""
        header = provenance(kset, self.language)
        params = ", ".join(f"{k} = {v:g}" for k, v in kset.parameters) or "none"
        parts = [
            rf"Robot {tex_escape(kset.robot_name)} ({kset.dof} joints), description hash\\",
            rf"\texttt{{{tex_escape(kset.description_hash)}}}.\\",
            rf"Parameter values: {tex_escape(params)}.",
            "",
            r"Inputs: joint positions $q_j$, velocities $\dot{q}_j$, accelerations $\ddot{q}_j$ and "
            r"torques (or forces) $\tau_j$, $j = 1, \dots, " + str(kset.dof) + r"$, in chain order from "
            r"the base; SI units, radians. Each kernel is a straight-line program: the intermediate "
            r"variables are evaluated top to bottom, then the entries of the bold output. "
            r"$[x > 0]$ is 1 where the condition holds and 0 elsewhere (Coulomb friction).",
            "",
        ]
        parts += [self.section(k) for k in kset.kernels]
        return latex_document(header, parts,
                              title=f"Dynamics and kinematics of {tex_escape(kset.robot_name)}")


def latex_files(kset: KernelSet) -> list[GeneratedFile]:
    """``<robot>.tex``, a standalone document."""
    return [GeneratedFile(f"{identifier(kset.robot_name)}.tex", LatexDocumentPrinter().document(kset))]
