"""Whitelist expression parser: accepted syntax, exactness, and every rejected construct."""

from __future__ import annotations

import pytest
import sympy as sp

from robodyn.robot.errors import DescriptionError
from robodyn.robot.expressions import parameter_symbol, parse_value

L, M, G = (parameter_symbol(n) for n in ("l", "m", "g"))
NAMES = {"l": L, "m": M, "g": G}
WHERE = "arm.yaml: joints[2].link.mass"


def parse(value: object) -> sp.Expr:
    return parse_value(value, NAMES, where=WHERE)


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("l/2", L / 2),
        ("2*pi/3", 2 * sp.pi / 3),
        ("-m*g", -M * G),
        ("sqrt(2)/2", sp.sqrt(2) / 2),
        ("l**2", L**2),
        ("l^2", L**2),
        ("+l - -m", L + M),
        ("(l + m) * (l - m)", (L + M) * (L - M)),
        ("m*l^2/12", M * L**2 / 12),
        ("atan2(1, 1)", sp.pi / 4),
        ("abs(-l)", sp.Abs(L)),
        ("sin(pi/6)", sp.Rational(1, 2)),
        ("cos(l) + tan(l) + asin(l) + acos(l) + atan(l)",
         sp.cos(L) + sp.tan(L) + sp.asin(L) + sp.acos(L) + sp.atan(L)),
        ("exp(l) * log(m)", sp.exp(L) * sp.log(M)),
        ("  7  ", sp.Integer(7)),
    ],
)
def test_accepted_expressions(text: str, expected: sp.Expr) -> None:
    assert sp.simplify(parse(text) - expected) == 0
    assert parse(text) == expected  # structurally identical, not only equal in value


def test_integer_division_is_exact() -> None:
    assert parse("1/3") == sp.Rational(1, 3)
    assert isinstance(parse("1/3"), sp.Rational)
    assert parse("pi/2") == sp.pi / 2
    assert sp.cos(parse("pi/2")) == 0
    assert sp.sin(parse("-pi/2")) == -1
    assert parse("2^-1") == sp.Rational(1, 2)


def test_numbers() -> None:
    three = parse(3)
    assert three == 3 and isinstance(three, sp.Integer)
    half = parse(0.5)
    assert isinstance(half, sp.Float) and float(half) == 0.5
    small = parse("1.5e-3")
    assert isinstance(small, sp.Float) and float(small) == pytest.approx(1.5e-3, rel=1e-15)
    assert float(parse("200e-6")) == pytest.approx(2e-4, rel=1e-15)
    assert parse(-4) == -4


def test_parameter_symbols_are_real() -> None:
    e = parse("l")
    assert e is L or e == L
    assert e.is_real
    assert sp.Abs(parse("l")) == sp.Abs(sp.Symbol("l", real=True))
    assert parse("l") != sp.Symbol("l")  # a plain (complex) symbol is a different symbol


@pytest.mark.parametrize(
    ("value", "reason"),
    [
        ("lx", r"name 'lx' is not a declared parameter \(declared: g, l, m\)"),
        ("e", r"name 'e' is not a declared parameter"),
        ("os.system", r"construct Attribute is not allowed"),
        ("l.real", r"construct Attribute is not allowed"),
        ("x[0]", r"construct Subscript is not allowed"),
        ("(1, 2)", r"construct Tuple is not allowed"),
        ("[l]", r"construct List is not allowed"),
        ("lambda: 1", r"construct Lambda is not allowed"),
        ("'abc'", r"constant 'abc' of type str is not allowed"),
        ("True", r"constant True of type bool is not allowed"),
        ("None", r"constant None of type NoneType is not allowed"),
        ("1j", r"constant 1j of type complex is not allowed"),
        ("l < 2", r"construct Compare is not allowed"),
        ("l if m else g", r"construct IfExp is not allowed"),
        ("l and m", r"construct BoolOp is not allowed"),
        ("l % 2", r"operator Mod is not allowed"),
        ("l // 2", r"operator FloorDiv is not allowed"),
        ("l @ m", r"operator MatMult is not allowed"),
        ("~l", r"operator Invert is not allowed"),
        ("not l", r"operator Not is not allowed"),
        ("sin(x=1)", r"keyword arguments are not allowed in sin"),
        ("sqrt(*l)", r"construct Starred is not allowed"),
        ("foo(1)", r"function 'foo' is not allowed \(allowed: abs, acos"),
        ("__import__('os').system('ls')", r"construct Attribute is not allowed"),
        ("__import__('os')", r"function '__import__' is not allowed"),
        ("eval('1')", r"function 'eval' is not allowed"),
        ("l.__class__()", r"construct Attribute is not allowed as a function"),
        ("sin", r"function 'sin' must be called"),
        ("atan2(1)", r"atan2\(\) takes 2 arguments, got 1"),
        ("sqrt(1, 2)", r"sqrt\(\) takes 1 argument, got 2"),
        ("f'{l}'", r"construct JoinedStr is not allowed"),
        ("(l := 2)", r"construct NamedExpr is not allowed"),
        ("1/0", r"the value is not finite"),
        ("log(0)", r"the value is not finite"),
        ("1e999", r"number inf is not finite"),
        ("sqrt(-1)", r"the value is not real"),
        ("10**10**10", r"exponent 10000000000 is too large"),
        ("(", r"syntax error"),
        ("l m", r"syntax error"),
        ("import os", r"syntax error"),
    ],
)
def test_rejected_text(value: str, reason: str) -> None:
    with pytest.raises(DescriptionError, match=reason) as info:
        parse(value)
    message = str(info.value)
    assert message.startswith(WHERE + ": ")
    assert repr(value) in message  # the offending text is quoted


@pytest.mark.parametrize(
    ("value", "reason"),
    [
        (True, r"got the boolean True"),
        (None, r"got nothing \(null\)"),
        ([1, 2], r"got a list"),
        ({"a": 1}, r"got a mapping"),
        (float("nan"), r"expected a finite number, got nan"),
        (float("inf"), r"expected a finite number, got inf"),
        ("", r"got an empty text"),
        ("l+" * 600 + "l", r"too long"),
    ],
)
def test_rejected_values(value: object, reason: str) -> None:
    with pytest.raises(DescriptionError, match=reason) as info:
        parse(value)
    assert str(info.value).startswith(WHERE + ": ")


def test_no_names_declared() -> None:
    pattern = r"name 'l' is not a declared parameter \(declared: none\)"
    with pytest.raises(DescriptionError, match=pattern):
        parse_value("l", {}, where="x.yaml: parameters.a")


def test_rejection_has_no_side_effects(tmp_path) -> None:
    # a would-be payload must not run: the parser never evaluates Python
    target = tmp_path / "pwned"
    payload = f"__import__('pathlib').Path({str(target)!r}).touch()"
    with pytest.raises(DescriptionError):
        parse(payload)
    assert not target.exists()


@pytest.mark.parametrize(
    "value",
    [
        "-" * 998 + "1",  # 999 levels of unary minus: RecursionError before the depth bound
        "+" * 500 + "-" * 498 + "l",
        "sin(" * 150 + "l" + ")" * 150,  # within the parser's parenthesis limit
    ],
)
def test_deeply_nested_expression_is_a_clear_error(value: str) -> None:
    with pytest.raises(DescriptionError, match=r"nested \d+ levels deep \(at most 100\)") as info:
        parse(value)
    assert str(info.value).startswith(WHERE + ": invalid expression ")


def test_nesting_within_the_bound_is_accepted() -> None:
    assert parse("-" * 98 + "l") == L  # 99 levels: an even number of minus signs
    assert parse("sqrt(" * 40 + "l" + ")" * 40) == L ** sp.Rational(1, 2**40)


@pytest.mark.parametrize(
    ("value", "reason"),
    [
        ("((9**99)**99)**99", r"constant power of about 10\*\*9353 is out of range"),
        ("(0.5**99)**99", r"constant power of about 10\*\*-2950 is out of range"),
    ],
)
def test_huge_constant_powers_are_rejected(value: str, reason: str) -> None:
    # each exponent is small; the exact integer result would have millions of digits
    with pytest.raises(DescriptionError, match=reason):
        parse(value)
