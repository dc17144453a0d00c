"""Physical and naming checks of robot descriptions."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import sympy as sp

from robodyn.robot.errors import DescriptionError, DescriptionWarning
from robodyn.robot.expressions import parameter_symbol
from robodyn.robot.model import Link
from robodyn.robot.validation import (
    check_link,
    check_parameter_names,
    check_unique_names,
    evaluate,
    inertia_problems,
)

M, L = parameter_symbol("m"), parameter_symbol("l")
DEFAULTS = {"m": 2.0, "l": 0.6}
WHERE = "arm.yaml: joints[1].link"


def make_link(mass=1, inertia=None, com=(0, 0, 0), name="rod") -> Link:
    return Link(
        name=name,
        mass=sp.sympify(mass),
        com=sp.ImmutableMatrix([sp.sympify(c) for c in com]),
        inertia=sp.ImmutableMatrix(sp.zeros(3) if inertia is None else inertia),
    )


def check(link: Link, strict: bool = False, defaults=DEFAULTS) -> None:
    check_link(link, where=WHERE, strict=strict, defaults=defaults)


def test_plausible_links_do_not_warn() -> None:
    rod = make_link(M, sp.diag(M * L**2 / 12, M * L**2 / 12, 0))  # thin rod along z
    point = make_link(M)  # point mass, zero inertia
    box = make_link(3, sp.diag(0.1, 0.2, 0.25), com=(0.1, L, -0.2))
    plate = make_link(1, sp.diag(sp.Rational(1, 12), sp.Rational(1, 6), sp.Rational(1, 4)))
    rotated = sp.ImmutableMatrix([[0.3, 0.05, 0.0], [0.05, 0.2, 0.01], [0.0, 0.01, 0.25]])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for link in (rod, point, box, plate, make_link(1, rotated)):
            check(link)
            check(link, strict=True)


def test_puma_link1_inertia_warns_and_strict_raises() -> None:
    # published PUMA 560 link 1 data: only Iyy = 0.35 is given, Ixx = Izz = 0
    link = make_link(0, sp.diag(0, sp.Rational(35, 100), 0), name="link1")
    with pytest.warns(DescriptionWarning, match=r"link 'link1'.*triangle inequality") as rec:
        check(link)
    assert len(rec) == 1
    assert str(rec[0].message).startswith(WHERE)
    assert "0 < 0.35" in str(rec[0].message)
    with pytest.raises(DescriptionError, match=r"link 'link1'.*triangle inequality.*strict"):
        check(link, strict=True)


def test_not_positive_semidefinite_warns() -> None:
    link = make_link(1, sp.diag(0.2, 0.2, -0.1), name="bad")
    with pytest.warns(DescriptionWarning, match=r"link 'bad'.*not positive semi-definite"):
        check(link)
    with pytest.raises(DescriptionError, match=r"not positive semi-definite"):
        check(link, strict=True)


def test_tiny_negative_eigenvalue_from_rounding_is_accepted() -> None:
    link = make_link(1, sp.diag(0.1, 0.1, -1e-15))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check(link)


def test_checks_use_parameter_defaults() -> None:
    # ixx = m - 3 is negative only at the default m = 2
    link = make_link(M, sp.diag(M - 3, 1, 1), name="p")
    with pytest.warns(DescriptionWarning, match="not positive semi-definite"):
        check(link)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check(link, defaults={"m": 4.0, "l": 1.0})


def test_negative_mass_is_an_error() -> None:
    pattern = r"joints\[1\]\.link\.mass: mass of link 'rod' is negative"
    with pytest.raises(DescriptionError, match=pattern):
        check(make_link(-1))
    with pytest.raises(DescriptionError, match=r"is negative \(-m = -2\)"):
        check(make_link(-M))


def test_non_symmetric_inertia_is_an_error() -> None:
    inertia = sp.Matrix([[1, 0.1, 0], [0, 1, 0], [0, 0, 1]])
    pattern = r"link\.inertia: inertia of link 'rod' is not symmetric: entry \(0, 1\)"
    with pytest.raises(DescriptionError, match=pattern):
        check(make_link(1, inertia))
    symbolic = sp.Matrix([[1, L, 0], [2 * L, 1, 0], [0, 0, 1]])
    with pytest.raises(DescriptionError, match="not symmetric"):
        check(make_link(1, symbolic))


def test_undeclared_symbol_is_an_error() -> None:
    pattern = r"link\.com\[2\]: depends on undeclared symbol\(s\) h"
    with pytest.raises(DescriptionError, match=pattern):
        check(make_link(1, com=(0, 0, parameter_symbol("h"))))


def test_non_finite_value_at_defaults_is_an_error() -> None:
    with pytest.raises(DescriptionError, match=r"link\.mass: value .* is not a finite real number"):
        check(make_link(1 / (L - sp.Rational(3, 5))))


def test_evaluate() -> None:
    assert evaluate(M * L, DEFAULTS, where="x") == pytest.approx(1.2)
    assert evaluate(sp.pi / 2, {}, where="x") == pytest.approx(np.pi / 2)


def test_inertia_problems_lists_each_condition() -> None:
    assert inertia_problems(np.zeros((3, 3))) == []
    assert inertia_problems(np.diag([1.0, 1.0, 2.0])) == []  # thin plate: equality holds
    both = inertia_problems(np.diag([-1.0, 0.5, 3.0]))
    assert len(both) == 2
    assert "semi-definite" in both[0] and "triangle" in both[1]


def test_unique_names() -> None:
    check_unique_names(["a", "b", "c"], what="joint", where="arm.yaml")
    with pytest.raises(
        DescriptionError,
        match=r"arm\.yaml: joints\[2\]\.name: duplicate joint name 'a' "
        r"\(first used at joints\[0\]\.name\)",
    ):
        check_unique_names(
            ["a", "b", "a"], what="joint", where="arm.yaml",
            paths=["joints[0].name", "joints[1].name", "joints[2].name"],
        )
    pattern = r"link #1: duplicate link name 'x' \(first used at link #0\)"
    with pytest.raises(DescriptionError, match=pattern):
        check_unique_names(["x", "x"], what="link", where="arm.urdf")


def test_valid_parameter_names() -> None:
    check_parameter_names(["l", "m1", "g", "L_2", "q", "qd", "q1a", "dq1", "Q1"], where="a.yaml")


@pytest.mark.parametrize(
    ("name", "reason"),
    [
        ("pi", "is reserved"),
        ("sqrt", "is reserved"),
        ("abs", "is reserved"),
        ("q1", "reserved for joint-state symbols"),
        ("qd12", "reserved for joint-state symbols"),
        ("qdd3", "reserved for joint-state symbols"),
        ("lambda", "is a reserved word"),
        ("2l", "is not valid"),
        ("_l", "is not valid"),
        ("l-1", "is not valid"),
        ("längd", "is not valid"),
        ("", "is not valid"),
        (3, "is not valid"),
    ],
)
def test_invalid_parameter_names(name, reason: str) -> None:
    with pytest.raises(DescriptionError, match=rf"a\.yaml: parameters: parameter name .*{reason}"):
        check_parameter_names(["ok", name], where="a.yaml: parameters")
