"""Readable forms of equations of motion: plain text, a LaTeX document, MathML and JSON.

Two layouts, chosen by the number of joints:

* small arms (``dof <= SMALL_DOF``): the textbook form. Every entry of M, C, g and tau is
  expanded, its terms are grouped by the joint accelerations and velocities (``qdd1``, ``qd2**2``,
  ``qd1*qd2``, ...) and each coefficient is simplified with ``trigsimp`` and ``factor_terms``;
  floating-point round-off (coefficients below 1e-12 of the largest in the entry) is dropped.
  Named parameters stay symbolic.
* larger arms: nothing is simplified (rendering the PUMA 560 takes seconds). tau is listed in
  the recursive Newton-Euler form, one intermediate variable per line (``w2_x = ...``); M (upper
  triangle) and g follow after common-subexpression elimination (``x0 = ...``). An eom from
  Lagrange or Kane has no recursive form: the Newton-Euler one is derived for the listing and
  the header says so.

JSON holds the expressions as SymPy ``str`` text. For larger arms the entries of M, C, g and tau
refer to the common subexpressions listed in ``"subexpressions"`` (evaluate them in order); for
small arms that list is empty and every entry stands alone.
"""

from __future__ import annotations

import json
import re
from collections.abc import Callable, Iterator, Sequence
from dataclasses import asdict, dataclass, field

import sympy as sp
from sympy.core.function import AppliedUndef
from sympy.printing.latex import LatexPrinter

from robodyn.symbolic.eom import EquationsOfMotion, derive
from robodyn.text import latex_document, tex_escape

__all__ = ["SMALL_DOF", "render_json", "render_latex", "render_text"]

#: Largest number of joints printed in the simplified textbook form.
SMALL_DOF = 3

#: Target width of one line of a LaTeX display, in (roughly) printed characters.
_LATEX_WIDTH = 80
_TEX_MARKUP = re.compile(r"\\(?:left|right|frac|dot|ddot|operatorname|mathbf|quad)|[{} ]")

#: One entry: ``(coefficient, rate monomial)`` pairs in printing order; the value is their sum.
Terms = list[tuple[sp.Expr, sp.Expr]]

_ENTRY_NAMES = ("M", "C", "g", "tau")


# ----------------------------------------------------------------------------------------------
# layout shared by every format
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class _Row:
    """One printed equation ``lhs = sum of terms``.

    ``lhs`` is "M", "C", "g" or "tau" with a 0-based ``index``, or the name of an intermediate
    variable (empty ``index``); ``mirror`` marks an off-diagonal entry of a symmetric matrix.
    """

    lhs: str
    index: tuple[int, ...]
    terms: Terms
    mirror: bool = False


@dataclass(frozen=True)
class _Layout:
    form: str
    sections: list[tuple[str, list[_Row]]]
    variables: list[tuple[sp.Symbol, sp.Expr]]
    #: LaTeX of left-hand sides that are neither indexed nor variables (``v_n2(s)``)
    tex: dict[str, str] = field(default_factory=dict)


def _version() -> str:
    from robodyn._version import __version__

    return __version__


def _joint_types(eom: EquationsOfMotion) -> str:
    return "".join("P" if j.type == "prismatic" else "R" for j in eom.robot.joints)


def _header(eom: EquationsOfMotion, form: str) -> list[str]:
    """Header lines (without comment markers)."""
    robot = eom.robot
    return [
        f"robodyn {_version()}: equations of motion of {robot.name}",
        f"method: {eom.method}; dof: {eom.dof} ({_joint_types(eom)}); "
        f"derivation time: {eom.derivation_time:.3f} s",
        f"source: {robot.source}",
        f"description sha256: {robot.description_hash}",
        f"form: {form}",
    ]


def _index(n: int, idx: tuple[int, ...]) -> str:
    """1-based index suffix: ``12`` for arms below 10 joints, ``1_12`` otherwise."""
    parts = [str(i + 1) for i in idx]
    return "".join(parts) if n < 10 else "_".join(parts)


def _rate_order(dep: sp.Expr, qd: Sequence[sp.Symbol], qdd: Sequence[sp.Symbol]) -> tuple:
    """Textbook order: accelerations, then velocity products, then the rest (gravity, friction)."""
    free = dep.free_symbols
    if free & set(qdd):
        group = 0
    elif free & set(qd) and dep.is_polynomial(*qd):
        group = 1
    elif dep == 1:
        group = 2
    else:
        group = 3
    return group, sp.default_sort_key(dep)


def _chop(expr: sp.Expr, threshold: float) -> sp.Expr:
    """Replace floats smaller than ``threshold`` in magnitude by zero."""
    small = {f: sp.Integer(0) for f in expr.atoms(sp.Float) if abs(float(f)) < threshold}
    return sp.sympify(expr.xreplace(small)) if small else expr


def _tidy(expr: sp.Expr, qd: Sequence[sp.Symbol], qdd: Sequence[sp.Symbol],
          threshold: float = 0.0) -> Terms:
    """Textbook form: terms grouped by products of the rates, each coefficient simplified.

    Floats below ``threshold`` (round-off) are dropped.
    """
    groups: dict[sp.Expr, sp.Expr] = {}
    for term in sp.Add.make_args(_chop(sp.expand(sp.sympify(expr)), threshold)):
        coeff, dep = term.as_independent(*qd, *qdd, as_Add=False)
        groups[dep] = groups.get(dep, sp.Integer(0)) + coeff
    terms = []
    for dep in sorted(groups, key=lambda d: _rate_order(d, qd, qdd)):
        coeff = _chop(sp.factor_terms(sp.trigsimp(groups[dep])), threshold)
        if coeff != 0:
            terms.append((coeff, dep))
    return terms


def _split(expr: sp.Expr) -> Terms:
    """An unsimplified expression as terms (its Add arguments in stored order: no sorting)."""
    return [(t, sp.Integer(1)) for t in sp.Add.make_args(sp.sympify(expr)) if t != 0]


def _textbook(eom: EquationsOfMotion) -> dict[str, list[list[Terms]]]:
    """M, C (n x n), g and tau (n x 1) of a small arm in textbook form.

    Round-off: floats below 1e-12 of the largest float of the expanded matrix are dropped.
    """
    def tidy(mat: sp.MatrixBase) -> list[list[Terms]]:
        floats = sp.ImmutableMatrix(mat).applyfunc(sp.expand).atoms(sp.Float)
        threshold = 1e-12 * max((abs(float(f)) for f in floats), default=0.0)
        return [[_tidy(mat[i, j], eom.qd, eom.qdd, threshold) for j in range(mat.cols)]
                for i in range(mat.rows)]

    return {"M": tidy(eom.M), "C": tidy(eom.C), "g": tidy(eom.g), "tau": tidy(eom.tau)}


def _fresh_names(prefix: str, used: set[str]) -> Iterator[sp.Symbol]:
    """``prefix0``, ``prefix1``, ... skipping names in ``used``."""
    k = 0
    while True:
        name = f"{prefix}{k}"
        k += 1
        if name not in used:
            yield sp.Symbol(name, real=True)


def _used_names(eom: EquationsOfMotion, *extra: Sequence[tuple[sp.Symbol, sp.Expr]]) -> set[str]:
    used = {s.name for s in eom.q + eom.qd + eom.qdd} | set(eom.robot.parameters)
    for assignments in extra:
        used |= {s.name for s, _ in assignments}
    return used


def _cse(exprs: Sequence[sp.Expr], used: set[str]
         ) -> tuple[list[tuple[sp.Symbol, sp.Expr]], list[sp.Expr]]:
    """``sympy.cse`` with ``x0, x1, ...`` names that clash with nothing in ``used``."""
    replacements, reduced = sp.cse(list(exprs), symbols=_fresh_names("x", used), order="none")
    return list(replacements), list(reduced)


def _layout(eom: EquationsOfMotion) -> _Layout:
    """What to print: the textbook form (small arms) or the recursive/CSE form."""
    n = eom.dof
    if n <= SMALL_DOF and eom.hydro is not None:
        return _underwater_layout(eom)
    if n <= SMALL_DOF:
        parts = _textbook(eom)
        sections = [
            ("inertia matrix M(q) (symmetric)",
             [_Row("M", (i, j), parts["M"][i][j], i != j) for i in range(n) for j in range(i, n)]),
            ("Coriolis and centrifugal matrix C(q, qd) (Christoffel symbols)",
             [_Row("C", (i, j), parts["C"][i][j]) for i in range(n) for j in range(n)]),
            ("gravity load g(q)", [_Row("g", (i,), parts["g"][i][0]) for i in range(n)]),
            ("inverse dynamics tau(q, qd, qdd)",
             [_Row("tau", (i,), parts["tau"][i][0]) for i in range(n)]),
        ]
        return _Layout("textbook (each entry simplified, grouped by joint accelerations and "
                       "velocities)", sections, [])
    if eom.program is not None:
        ne, form = eom, "recursive Newton-Euler"
    else:
        ne = derive(eom.robot, "newton_euler")
        form = (f"tau in recursive Newton-Euler form, derived with newton_euler for this listing "
                f"({eom.method} gives no recursive form); M and g are {eom.method}'s")
    assert ne.program is not None
    program = list(ne.program.assignments)
    # under water: the hydrodynamic torques (added mass, buoyancy, drag, lift) after their own
    # common-subexpression elimination (h0, h1, ...), evaluated before tau
    hydro: list[tuple[sp.Symbol, sp.Expr]] = []
    extra = [sp.Integer(0)] * n
    if eom.hydro is not None:
        hydro, extra = sp.cse(list(eom.hydro.tau), order="none",
                              symbols=_fresh_names("h", _used_names(eom, program)))
        hydro = list(hydro)
    tau_rows = [_Row("tau", (k,), _split(ne.program.outputs[k] + ne.rotor[k] + ne.friction[k]
                                         + extra[k])) for k in range(n)]
    program += hydro
    pairs = [(i, j) for i in range(n) for j in range(i, n)]
    subs, reduced = _cse([eom.M[i, j] for i, j in pairs] + list(eom.g),
                         _used_names(eom, program))
    mg_rows = [_Row(s.name, (), _split(rhs)) for s, rhs in subs]
    mg_rows += [_Row("M", ij, _split(e)) for ij, e in zip(pairs, reduced, strict=False)]
    mg_rows += [_Row("g", (k,), _split(e)) for k, e in enumerate(reduced[len(pairs):])]
    sections = [
        (f"inverse dynamics tau: recursive Newton-Euler, {len(program)} intermediate variables "
         "evaluated in order", [_Row(s.name, (), _split(rhs)) for s, rhs in program] + tau_rows),
        ("inertia matrix M(q) (upper triangle) and gravity load g(q) after common-subexpression "
         "elimination", mg_rows),
    ]
    return _Layout(form, sections, program + subs)


def _underwater_layout(eom: EquationsOfMotion) -> _Layout:
    """Textbook form of a small underwater arm, each hydrodynamic term on its own
    (:mod:`robodyn.symbolic.hydro.textbook`)."""
    from robodyn.symbolic.hydro.textbook import underwater_textbook

    book = underwater_textbook(eom)
    sections = [(sec.title, [_Row(ln.name, ln.index, list(ln.terms), ln.mirror)
                             for ln in sec.lines]) for sec in book.sections]
    tex = {f"{f.func.__name__}(s)": sp.latex(f) for f in book.functions}
    return _Layout("textbook, under water: (M + M_A) qdd + (C + C_A) qd + tau_Ac + g + g_B + tau_D "
                   "+ tau_F + tau_L (+ friction) = tau, each hydrodynamic term separately", sections, [], tex)


def _continued(text: str) -> str:
    """A term text as it continues a sum: `` + a`` or `` - a``."""
    return f" - {text[1:].lstrip()}" if text.startswith("-") else f" + {text}"


def _join(texts: Sequence[str]) -> str:
    """``a + b - c`` from term texts."""
    return "".join(_continued(t) if k else t for k, t in enumerate(texts))


def _term_texts(terms: Terms, show: Callable[[sp.Expr], str], group: tuple[str, str]
                ) -> list[str]:
    """Printed terms: a sum coefficient is bracketed (``group``) in front of its rate monomial."""
    out = []
    for coeff, dep in terms:
        if dep == 1:
            out.append(show(coeff))
        elif coeff.is_Add:
            out.append(f"{group[0]}{show(coeff)}{group[1]}{show(dep)}")
        elif coeff.could_extract_minus_sign() and (-coeff).is_Add:
            out.append(f"-{group[0]}{show(-coeff)}{group[1]}{show(dep)}")
        else:
            out.append(show(coeff * dep))
    return out or ["0"]


# ----------------------------------------------------------------------------------------------
# text
# ----------------------------------------------------------------------------------------------


def _s(expr: sp.Expr) -> str:
    return sp.sstr(expr, full_prec=False)


def render_text(eom: EquationsOfMotion) -> str:
    """Plain-text listing of the equations of motion.

    Parameters
    ----------
    eom : EquationsOfMotion

    Returns
    -------
    str
        Comment header (``#`` lines: robot, method, source, description hash, robodyn version),
        then ``name = expression`` lines. Small arms: M (upper triangle), C, g and tau in
        textbook form. Larger arms: the recursive Newton-Euler assignments and ``tau1..taun``,
        then M (upper triangle) and g after common-subexpression elimination.
    """
    layout = _layout(eom)
    lines = [f"# {h}" for h in _header(eom, layout.form)]
    lines.append("# M(q) qdd + C(q, qd) qd + g(q) = tau_rigid;  tau = tau_rigid + rotor inertia "
                 "G^2 Jm qdd + friction (M includes the rotor inertia)")
    joints = ", ".join(f"q{k + 1} = {j.name} ({j.type})" for k, j in enumerate(eom.robot.joints))
    lines.append(f"# joints: {joints}; qd = dq/dt, qdd = d2q/dt2")
    if eom.robot.parameters:
        params = ", ".join(f"{k} = {v:g}" for k, v in eom.robot.parameters.items())
        lines.append(f"# parameters (default values): {params}")
    for title, rows in layout.sections:
        lines += ["", f"# {title}"]
        for row in rows:
            lhs = row.lhs + _index(eom.dof, row.index)
            lines.append(f"{lhs} = {_join(_term_texts(row.terms, _s, ('(', ')*')))}")
    return "\n".join(lines) + "\n"


# ----------------------------------------------------------------------------------------------
# LaTeX
# ----------------------------------------------------------------------------------------------


class _Latex(LatexPrinter):
    """LaTeX printer that writes the Heaviside step as H (SymPy's theta clashes with angles)."""

    def _print_Heaviside(self, expr: sp.Heaviside, exp: str | None = None) -> str:
        tex = rf"\operatorname{{H}}\left({self._print(expr.args[0])}\right)"
        return f"{tex}^{{{exp}}}" if exp else tex

    def _print_Function(self, expr: sp.Function, exp: str | None = None) -> str:  # noqa: N802
        if not isinstance(expr, AppliedUndef):
            return super()._print_Function(expr, exp)
        # v_n2(s) (hydro textbook): keep the brackets that fold_func_brackets would drop
        fold = self._settings["fold_func_brackets"]
        self._settings["fold_func_brackets"] = False
        try:
            return super()._print_Function(expr, exp)
        finally:
            self._settings["fold_func_brackets"] = fold


#: Left-hand sides of the hydrodynamic terms (:mod:`robodyn.symbolic.hydro.textbook`).
_HYDRO_TEX = {"M_A": r"\mathbf{M}^{\mathrm{A}}", "C_A": r"\mathbf{C}^{\mathrm{A}}",
              "g_B": r"\mathbf{g}^{\mathrm{B}}", "tau_D": r"\tau^{\mathrm{D}}",
              "tau_F": r"\tau^{\mathrm{F}}", "tau_L": r"\tau^{\mathrm{L}}",
              "tau_Ac": r"\tau^{\mathrm{Ac}}", "friction": r"\tau^{\mathrm{f}}"}

_NAME = re.compile(r"^([A-Za-z]+)(\d*)((?:_[A-Za-z0-9]+)*)$")


def _symbol_tex(name: str) -> str | None:
    """``w2_x`` -> ``w_{2,x}``, ``c2`` -> ``c_{2}``; None for names SymPy prints well itself."""
    match = _NAME.match(name)
    if not match or not (match.group(2) or match.group(3)):
        return None
    base, digits, rest = match.groups()
    subs = ([digits] if digits else []) + [p for p in rest.split("_") if p]
    return f"{base}_{{{','.join(subs)}}}"


def _symbol_names(eom: EquationsOfMotion,
                  variables: Sequence[tuple[sp.Symbol, sp.Expr]]) -> dict[sp.Symbol, str]:
    names: dict[sp.Symbol, str] = {}
    for k in range(eom.dof):
        names[eom.q[k]] = f"q_{{{k + 1}}}"
        names[eom.qd[k]] = rf"\dot{{q}}_{{{k + 1}}}"
        names[eom.qdd[k]] = rf"\ddot{{q}}_{{{k + 1}}}"
    for sym, _ in variables:
        tex = _symbol_tex(sym.name)
        if tex is not None:
            names[sym] = tex
    return names


def _printed_len(tex: str) -> int:
    """Rough printed width of LaTeX source: markup, braces and spaces do not count."""
    return len(_TEX_MARKUP.sub("", tex))


def _tex_lines(texts: Sequence[str]) -> list[str]:
    """Term texts joined into lines of about ``_LATEX_WIDTH`` printed characters."""
    lines: list[str] = []
    current = ""
    for tex in texts:
        piece = _continued(tex) if current else tex
        if current and _printed_len(current) + _printed_len(piece) > _LATEX_WIDTH:
            lines.append(current)
            current = piece.lstrip()
        else:
            current += piece
    lines.append(current)
    return lines


def _tex_lhs(row: _Row, n: int, names: dict[sp.Symbol, str]) -> str:
    if not row.index:
        return names.get(sp.Symbol(row.lhs, real=True), row.lhs)
    macro = {"M": r"\mathbf{M}", "C": r"\mathbf{C}", "g": r"\mathbf{g}", "tau": r"\tau",
             **_HYDRO_TEX}[row.lhs]
    lhs = f"{macro}_{{{_index(n, row.index)}}}"
    if row.mirror:
        lhs += f" = {macro}_{{{_index(n, row.index[::-1])}}}"
    return lhs


def _tex_align(rows: Sequence[_Row], n: int, printer: _Latex,
               names: dict[sp.Symbol, str]) -> str:
    """An ``align*`` environment: one ``lhs &= rhs`` row each, long rows broken with ``\\\\``."""
    out = [r"\begin{align*}"]
    for k, row in enumerate(rows):
        texts = _term_texts(row.terms, printer.doprint, (r"\left(", r"\right) "))
        pieces = _tex_lines(texts)
        body = f"{_tex_lhs(row, n, names)} &= {pieces[0]}"
        for piece in pieces[1:]:
            body += f" \\\\\n  &\\quad {piece}"
        out.append(body + (r" \\" if k < len(rows) - 1 else ""))
    out.append(r"\end{align*}")
    return "\n".join(out)


def render_latex(eom: EquationsOfMotion) -> str:
    """A complete LaTeX document (article class, amsmath) of the equations of motion.

    Parameters
    ----------
    eom : EquationsOfMotion

    Returns
    -------
    str
        Compilable source with a ``%`` comment header. The equations sit in ``align*``
        environments, long entries broken over lines with ``\\\\``; joint variables print as
        ``q_{1}``, ``\\dot{q}_{1}``, ``\\ddot{q}_{1}``. Same layouts as :func:`render_text`.
    """
    layout = _layout(eom)
    robot = eom.robot
    names = _symbol_names(eom, layout.variables)
    names.update({sp.Symbol(lhs, real=True): tex for lhs, tex in layout.tex.items()})
    printer = _Latex({"symbol_names": names, "fold_func_brackets": True})
    joints = ", ".join(f"$q_{{{k + 1}}}$: joint \\texttt{{{tex_escape(j.name)}}} ({j.type})"
                       for k, j in enumerate(robot.joints))
    params = ""
    if robot.parameters:
        params = "Parameters (kept symbolic; default values): " + ", ".join(
            f"${printer.doprint(sp.Symbol(k, real=True))} = {v:g}$"
            for k, v in robot.parameters.items()) + "."
    doc = [
        rf"\section*{{Equations of motion of \texttt{{{tex_escape(robot.name)}}}}}",
        rf"Generated by robodyn {tex_escape(_version())} with the "
        rf"\texttt{{{tex_escape(eom.method)}}} formulation from "
        rf"\texttt{{{tex_escape(robot.source)}}} "
        rf"(description SHA-256 \texttt{{{robot.description_hash[:16]}}}\ldots). "
        rf"Form: {tex_escape(layout.form)}.",
        "",
        r"\[ \mathbf{M}(q)\,\ddot{q} + \mathbf{C}(q,\dot{q})\,\dot{q} + \mathbf{g}(q)"
        r" = \tau_{\mathrm{rigid}}, \qquad"
        r" \tau = \tau_{\mathrm{rigid}} + G^2 J_m \ddot{q} + \tau_f(\dot{q}) \]",
        rf"Joints: {joints}. $\operatorname{{H}}$ is the Heaviside step "
        r"($\operatorname{H}(0) = 0$).",
        params,
    ]
    for title, rows in layout.sections:
        title = title[0].upper() + title[1:]
        doc += [rf"\subsection*{{{tex_escape(title)}}}",
                _tex_align(rows, eom.dof, printer, names)]
    return latex_document(_header(eom, layout.form), doc)


# ----------------------------------------------------------------------------------------------
# JSON (MathML for HTML pages: robodyn.symbolic.render_mathml)
# ----------------------------------------------------------------------------------------------


def _j(expr: sp.Expr) -> str:
    return sp.sstr(expr, order="none")


def render_json(eom: EquationsOfMotion) -> str:
    """JSON document of the equations of motion (SymPy ``str`` text of every entry).

    Parameters
    ----------
    eom : EquationsOfMotion

    Returns
    -------
    str
        An object with keys ``robot``, ``method``, ``dof``, ``joint_names``, ``q``, ``qd``,
        ``qdd``, ``parameters`` (defaults), ``subexpressions`` (``[[name, expr], ...]``, empty for
        small arms), ``M`` and ``C`` (lists of rows), ``g``, ``tau``, ``op_counts`` (per output:
        additions, multiplications, functions, total), ``derivation_time_s``, ``source``,
        ``description_hash`` and ``robodyn_version``. Small arms: entries in textbook form.
        Larger arms: entries may use the symbols of ``subexpressions`` (evaluate in order).
    """
    n = eom.dof
    if n <= SMALL_DOF:
        subs: list[tuple[sp.Symbol, sp.Expr]] = []
        parts = _textbook(eom)
        texts = {key: [[_join(_term_texts(t, _j, ("(", ")*"))) for t in row] for row in mat]
                 for key, mat in parts.items()}
    else:
        # one CSE per quantity: a joint CSE of all four can take many minutes on a 7-joint arm
        # (SymPy compares large equal-but-distinct subtrees), separate ones take seconds
        names = _fresh_names("x", _used_names(eom))
        subs, texts = [], {}
        for key in _ENTRY_NAMES:
            mat = getattr(eom, key)
            block, reduced = sp.cse(list(mat), symbols=names, order="none")
            subs += block
            it = iter(_j(e) for e in reduced)
            texts[key] = [[next(it) for _ in range(mat.cols)] for _ in range(mat.rows)]
    doc = {
        "robot": eom.robot.name,
        "method": eom.method,
        "dof": n,
        "joint_names": list(eom.robot.joint_names),
        "q": [s.name for s in eom.q],
        "qd": [s.name for s in eom.qd],
        "qdd": [s.name for s in eom.qdd],
        "parameters": dict(eom.robot.parameters),
        "subexpressions": [[sym.name, _j(rhs)] for sym, rhs in subs],
        "M": texts["M"],
        "C": texts["C"],
        "g": [row[0] for row in texts["g"]],
        "tau": [row[0] for row in texts["tau"]],
        "op_counts": {key: {**asdict(ops), "total": ops.total}
                      for key, ops in eom.op_counts().items()},
        "derivation_time_s": eom.derivation_time,
        "source": eom.robot.source,
        "description_hash": eom.robot.description_hash,
        "robodyn_version": _version(),
    }
    return json.dumps(doc, indent=1) + "\n"
