"""MathML of the textbook form (an HTML fragment for the demo report), on the layout of
:mod:`robodyn.symbolic.render`."""

from __future__ import annotations

import html
import re

import sympy as sp
from sympy.printing.mathml import MathMLPresentationPrinter

from robodyn.symbolic.eom import EquationsOfMotion
from robodyn.symbolic.render import Terms, _index, _layout, _Row

__all__ = ["render_mathml"]


class _MathML(MathMLPresentationPrinter):
    """Presentation MathML with dotted joint rates and the Heaviside step written H."""

    def _print_Heaviside(self, expr: sp.Heaviside):  # noqa: N802 - SymPy's printer protocol
        def leaf(tag: str, text: str):
            node = self.dom.createElement(tag)
            node.appendChild(self.dom.createTextNode(text))
            return node

        row = self.dom.createElement("mrow")
        for node in (leaf("mi", "H"), leaf("mo", "("), self._print(expr.args[0]), leaf("mo", ")")):
            row.appendChild(node)
        return row


_RATE = re.compile(r"<msub><mi>(qdd|qd|q)</mi><mi>(\d+)</mi></msub>")
_ACCENT = {"qdd": "&#x00A8;", "qd": "&#x02D9;"}


def _dotted(match: re.Match) -> str:
    kind, k = match.groups()
    if kind == "q":
        return f"<msub><mi>q</mi><mn>{k}</mn></msub>"
    return (f'<msub><mover accent="true"><mi>q</mi><mo>{_ACCENT[kind]}</mo></mover>'
            f"<mn>{k}</mn></msub>")


def _mathml_terms(terms: Terms, printer: _MathML) -> str:
    out = ""
    for k, (coeff, dep) in enumerate(terms):
        negative = coeff.could_extract_minus_sign()
        coeff = -coeff if negative else coeff
        if dep != 1 and coeff.is_Add:
            body = (f"<mrow><mo>(</mo>{printer.doprint(coeff)}<mo>)</mo></mrow>"
                    f"<mo>&InvisibleTimes;</mo>{printer.doprint(dep)}")
        else:
            body = printer.doprint(coeff * dep)
        sign = "<mo>&#x2212;</mo>" if negative else ("<mo>+</mo>" if k else "")
        out += sign + body
    return _RATE.sub(_dotted, out or "<mn>0</mn>")


def _mathml_lhs(row: _Row, n: int) -> str:
    if not row.index:
        return f"<mi>{html.escape(row.lhs)}</mi>"
    base = {"M": '<mi mathvariant="bold">M</mi>', "C": '<mi mathvariant="bold">C</mi>',
            "g": '<mi mathvariant="bold">g</mi>', "tau": "<mi>&#x03C4;</mi>"
            }.get(row.lhs, f"<mi>{html.escape(row.lhs)}</mi>")
    lhs = f"<msub>{base}<mn>{_index(n, row.index)}</mn></msub>"
    if row.mirror:
        lhs += f"<mo>=</mo><msub>{base}<mn>{_index(n, row.index[::-1])}</mn></msub>"
    return lhs


def render_mathml(eom: EquationsOfMotion) -> str:
    """HTML fragment of the equations in presentation MathML (no scripts, no network needed).

    Parameters
    ----------
    eom : EquationsOfMotion

    Returns
    -------
    str
        One ``<h4>`` title and one ``<math display="block">`` table per section, in the
        layouts of :func:`render_text`.
    """
    layout = _layout(eom)
    printer = _MathML()
    parts = []
    for title, rows in layout.sections:
        body = "".join(
            f'<mtr><mtd columnalign="right">{_mathml_lhs(row, eom.dof)}</mtd>'
            f'<mtd><mo>=</mo></mtd><mtd columnalign="left"><mrow>'
            f"{_mathml_terms(row.terms, printer)}</mrow></mtd></mtr>"
            for row in rows
        )
        parts.append(f"<h4>{html.escape(title[0].upper() + title[1:])}</h4>\n"
                     f'<math display="block"><mtable>{body}</mtable></math>')
    return "\n".join(parts) + "\n"


# ----------------------------------------------------------------------------------------------
# JSON
# ----------------------------------------------------------------------------------------------
