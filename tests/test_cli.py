"""The ``robodyn`` command line and the text/LaTeX/JSON renderers."""

from __future__ import annotations

import ast
import csv
import json
import math
import operator
import re
import tempfile
import warnings

import numpy as np
import pytest
import sympy as sp

import robodyn as rd
from robodyn.cli import main
from robodyn.errors import DescriptionError
from robodyn.report.agreement import Agreement
from robodyn.symbolic.render import render_json, render_latex, render_text
from robodyn.symbolic.render_mathml import render_mathml

NEGATIVE_MASS = """\
name: bad_arm
parameters: {l1: 1.0}
joints:
  - name: j1
    type: revolute
    dh: {a: l1, alpha: 0, d: 0, theta: 0}
    link:
      name: upper
      mass: -2.0
      com: [-0.5, 0, 0]
      inertia: {ixx: 0.01, iyy: 0.01, izz: 0.01, ixy: 0, ixz: 0, iyz: 0}
"""


def run(argv: list[str]) -> int:
    """``main(argv)``; argparse errors and ``--help`` exit through SystemExit."""
    try:
        return main(argv)
    except SystemExit as exc:
        return int(exc.code or 0)


def load_quietly(name: str) -> rd.Robot:
    """Load without the plausibility warnings of the source data (see puma560.yaml)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return rd.load(name)


@pytest.fixture(scope="module")
def trolley_kane() -> rd.EquationsOfMotion:
    return rd.derive(rd.load("trolley_pendulum"), "kane")


@pytest.fixture(scope="module")
def puma_ne() -> rd.EquationsOfMotion:
    return rd.derive(load_quietly("puma560"), "newton_euler")


# ----------------------------------------------------------------------------------------------
# command line
# ----------------------------------------------------------------------------------------------


def test_list_shows_builtins(capsys):
    assert run(["list"]) == 0
    out = capsys.readouterr().out
    assert re.search(r"^puma560\s+6\s+RRRRRR", out, re.M)
    assert re.search(r"^trolley_pendulum\s+2\s+PR", out, re.M)


def test_show_prints_joint_and_link_tables(capsys):
    assert run(["show", "planar_2r"]) == 0
    out = capsys.readouterr().out
    assert re.search(r"^1\s+q1\s+revolute\s+dh\s+a=l1 alpha=0 d=0 theta=0", out, re.M)
    assert re.search(r"^2\s+q2\s+revolute\s+dh\s+a=l2", out, re.M)
    assert re.search(r"^1\s+link1\s+m1\s+\(-l1/2, 0, 0\)", out, re.M)
    assert "gravity: (0, -g, 0)" in out
    assert re.search(r"^g\s+9\.81$", out, re.M)


def test_derive_text_is_the_textbook_form(capsys):
    assert run(["derive", "trolley_pendulum", "--method", "kane", "--format", "text"]) == 0
    out = capsys.readouterr().out
    assert "cos(q2)" in out
    # seed eqs. 2.46-2.47 solved for the joint forces
    assert "tau1 = (M + m)*qdd1 + l*m*qdd2*cos(q2)/2 - l*m*qd2**2*sin(q2)/2" in out
    assert "M11 = M + m" in out  # sin^2 + cos^2 simplified away
    assert out.startswith("# robodyn")


def test_derive_json_parses(capsys):
    assert run(["derive", "trolley_pendulum", "--format", "json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["robot"] == "trolley_pendulum" and doc["dof"] == 2
    assert len(doc["M"]) == 2 and all(len(row) == 2 for row in doc["M"])
    assert len(doc["C"]) == 2 and len(doc["g"]) == 2 and len(doc["tau"]) == 2
    assert set(doc["op_counts"]) == {"tau", "M", "g"}
    m, length, q2 = sp.symbols("m l q2")
    assert sp.simplify(sp.sympify(doc["M"][0][1]) - m * length * sp.cos(q2) / 2) == 0


def test_derive_writes_file(tmp_path, capsys):
    target = tmp_path / "trolley.tex"
    assert run(["derive", "trolley_pendulum", "--format", "latex", "-o", str(target)]) == 0
    assert capsys.readouterr().out == ""
    assert r"\end{document}" in target.read_text()


def test_check_planar_2r_agrees(capsys):
    assert run(["check", "planar_2r", "--samples", "5"]) == 0
    captured = capsys.readouterr()
    assert "the three formulations agree" in captured.out
    assert re.search(r"newton_euler vs lagrange\s+\S+\s+\S+\s+\S+\s+yes\s+ok", captured.out)
    assert "deriving kane..." in captured.err


def test_agreement_flags_a_difference():
    assert not Agreement("a", "b", {"M": 1e-6, "g": 0.0, "tau": 0.0}).ok
    assert not Agreement("a", "b", {"M": 0.0, "g": 0.0, "tau": 0.0}, symbolic=False).ok
    assert Agreement("a", "b", {"M": 1e-15, "g": 0.0, "tau": 0.0}, symbolic=True).ok


def test_unknown_robot_exits_2(capsys):
    assert run(["show", "no_such_robot"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert "no_such_robot" in err and "Traceback" not in err


def test_negative_mass_exits_2_naming_the_field(tmp_path, capsys):
    path = tmp_path / "bad_arm.yaml"
    path.write_text(NEGATIVE_MASS)
    assert run(["derive", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert "bad_arm.yaml" in err and "mass" in err


def test_a_bug_is_not_reported_as_bad_input(monkeypatch, tmp_path, capsys):
    # an error that is not a RobodynError (or a file that cannot be read/written) is a bug:
    # exit 1, one line that says so, and the traceback in a log file
    def broken(*args, **kwargs):
        raise ValueError("an internal inconsistency")

    monkeypatch.setattr(rd, "load", broken)
    monkeypatch.setenv("TMPDIR", str(tmp_path))
    monkeypatch.delenv("ROBODYN_DEBUG", raising=False)
    tempfile.tempdir = None  # let tempfile read TMPDIR again
    try:
        assert run(["show", "puma560"]) == 1
    finally:
        tempfile.tempdir = None
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "internal error" in err and "Traceback" not in err
    logs = list(tmp_path.glob("robodyn-internal-error-*.log"))
    assert len(logs) == 1 and str(logs[0]) in err
    text = logs[0].read_text()
    assert "Traceback" in text and "an internal inconsistency" in text and "show puma560" in text
    # a user-facing error of the same Python type is still bad input
    def bad(*args, **kwargs):
        raise DescriptionError("arm.yaml: joints[0].mass: must be >= 0")

    monkeypatch.setattr(rd, "load", bad)
    assert run(["show", "puma560"]) == 2


def test_bad_option_exits_2(capsys):
    assert run(["derive", "planar_2r", "--method", "hamilton"]) == 2
    assert "hamilton" in capsys.readouterr().err


@pytest.mark.parametrize("argv", [[], ["derive"], ["check"], ["demo"]])
def test_help_has_examples(argv, capsys):
    assert run([*argv, "--help"]) == 0
    out = capsys.readouterr().out
    assert "usage: robodyn" in out and "example" in out


@pytest.mark.slow
@pytest.mark.slow
def test_demo_writes_report(tmp_path, capsys):
    assert run(["demo", "-o", str(tmp_path), "--samples", "3"]) == 0
    out = capsys.readouterr().out
    assert str(tmp_path / "report.html") in out
    names = {p.name for p in tmp_path.iterdir()}
    assert {"report.html", "comparison.csv", "comparison.md", "puma560_newton_euler.txt",
            "puma560_equations.tex", "trolley_pendulum.tex"} <= names
    assert {f"puma560_{m}.json" for m in ("newton_euler", "lagrange", "kane")} <= names
    with (tmp_path / "comparison.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    assert [r["method"] for r in rows] == ["newton_euler", "lagrange", "kane"]
    assert all(float(r["derivation_time_s"]) > 0 and int(r["tau_multiplications"]) > 0
               for r in rows)
    page = (tmp_path / "report.html").read_text()
    assert page.startswith("<!DOCTYPE html>") and "<math" in page and "<script" not in page
    assert "http://" not in page and "https://" not in page  # opens without network
    assert "the three formulations agree" in page
    # self-contained: every figure is embedded, none is a file beside the page
    assert page.count("<img ") >= 3 and page.count("<img ") == page.count('<img src="data:image/')
    text = re.sub(r'src="data:[^"]*"', "", page)  # base64 may spell anything
    assert "seed" not in text.lower()  # no internal jargon: "the thesis"


# ----------------------------------------------------------------------------------------------
# renderers
# ----------------------------------------------------------------------------------------------


def test_latex_is_a_complete_document(trolley_kane):
    tex = render_latex(trolley_kane)
    assert tex.startswith("% robodyn")
    assert r"\documentclass" in tex and r"\usepackage{amsmath}" in tex
    assert tex.count(r"\begin{document}") == 1 and tex.rstrip().endswith(r"\end{document}")
    assert tex.count(r"\begin{align*}") == tex.count(r"\end{align*}") == 4
    assert r"\ddot{q}_{1}" in tex and r"\dot{q}_{2}" in tex and r"\cos {q_{2}}" in tex
    assert "trolley\\_pendulum" in tex  # escaped in text


def test_text_of_large_arm_is_recursive(puma_ne):
    text = render_text(puma_ne)
    lines = text.splitlines()
    assert any(line.startswith("w2_") or line.startswith("wp2_") for line in lines)
    assert sum(line.startswith("tau") for line in lines) == 6
    assert any(line.startswith("M11 = ") for line in lines)
    assert any(line.startswith("x0 = ") for line in lines)
    assert "recursive Newton-Euler" in text


def test_text_of_large_arm_from_kane_says_where_the_recursion_comes_from():
    text = render_text(rd.derive(load_quietly("puma560"), "kane"))
    assert "derived with newton_euler for this listing" in text


def test_latex_of_large_arm(puma_ne):
    tex = render_latex(puma_ne)
    assert r"\allowdisplaybreaks" in tex and tex.rstrip().endswith(r"\end{document}")
    assert r"\tau_{6} &=" in tex
    assert r"\\" + "\n  &\\quad" in tex  # long entries are broken over lines


def _evaluate(text: str, env: dict[str, float]) -> float:
    """A JSON entry evaluated numerically by walking its syntax tree (numbers, names, + - * / **,
    sin, cos, Heaviside(x, h0)): an evaluator independent of SymPy and of robodyn's parser."""
    functions = {"sin": math.sin, "cos": math.cos,
                 "Heaviside": lambda x, h0: h0 if x == 0 else float(x > 0)}
    binary = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul,
              ast.Div: operator.truediv, ast.Pow: operator.pow}

    def walk(node: ast.AST) -> float:
        if isinstance(node, ast.Constant) and isinstance(node.value, int | float):
            return float(node.value)
        if isinstance(node, ast.Name):
            return env[node.id]
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub):
            return -walk(node.operand)
        if isinstance(node, ast.BinOp) and type(node.op) in binary:
            return binary[type(node.op)](walk(node.left), walk(node.right))
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id in functions:
            return functions[node.func.id](*(walk(a) for a in node.args))
        raise AssertionError(f"unexpected construct {ast.dump(node)[:80]} in {text[:80]!r}")

    return walk(ast.parse(text, mode="eval").body)


def _evaluate_document(doc: dict, q, qd, qdd) -> dict[str, np.ndarray]:
    """tau, M and g of a JSON document at one state: subexpressions first, in order."""
    env = dict(doc["parameters"])
    env |= dict(zip(doc["q"], q, strict=True)) | dict(zip(doc["qd"], qd, strict=True))
    env |= dict(zip(doc["qdd"], qdd, strict=True))
    for name, text in doc["subexpressions"]:
        env[name] = _evaluate(text, env)
    return {"tau": np.array([_evaluate(e, env) for e in doc["tau"]]),
            "M": np.array([[_evaluate(e, env) for e in row] for row in doc["M"]]),
            "g": np.array([_evaluate(e, env) for e in doc["g"]])}


def test_json_textbook_entries_evaluate(trolley_kane):
    doc = json.loads(render_json(trolley_kane))
    assert doc["subexpressions"] == [] and doc["method"] == "kane"
    assert doc["q"] == ["q1", "q2"] and doc["parameters"]["l"] == 1.0
    model = rd.compile_model(rd.load("trolley_pendulum"), backend="numpy")
    rng = np.random.default_rng(4)
    for q, qd, qdd in rng.uniform(-2, 2, (3, 3, 2)):
        got = _evaluate_document(doc, q, qd, qdd)
        np.testing.assert_allclose(got["tau"], model.inverse_dynamics(q, qd, qdd), rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(got["M"], model.mass_matrix(q), rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(got["g"], model.gravity(q), rtol=1e-12, atol=1e-12)


def test_json_recursive_entries_evaluate(puma_ne):
    doc = json.loads(render_json(puma_ne))
    assert len(doc["subexpressions"]) > 100  # a large arm: entries use the subexpressions
    model = rd.compile_model(load_quietly("puma560"))
    rng = np.random.default_rng(5)
    for q, qd, qdd in rng.uniform(-2, 2, (3, 3, 6)):
        got = _evaluate_document(doc, q, qd, qdd)
        np.testing.assert_allclose(got["tau"], model.inverse_dynamics(q, qd, qdd), rtol=1e-10, atol=1e-10)
        np.testing.assert_allclose(got["M"], model.mass_matrix(q), rtol=1e-10, atol=1e-10)
        np.testing.assert_allclose(got["g"], model.gravity(q), rtol=1e-10, atol=1e-10)


def test_mathml_fragment(trolley_kane):
    frag = render_mathml(trolley_kane)
    assert frag.count("<math") == 4 and "&#x00A8;" in frag  # double dot of qdd



@pytest.mark.parametrize(("argv", "code", "out", "err"), [
    (["show", "planar_2r"], 0, "robot planar_2r: 2 joints", ""),
    (["show", "no_such_robot"], 2, "", "robodyn: error: no_such_robot: no such file"),
])
def test_console_command_exit_code_and_streams(argv, code, out, err):
    # the console command (robodyn.cli:run, also `python -m robodyn.cli`) ends without the
    # interpreter's teardown: its exit code and everything printed must still arrive
    import subprocess
    import sys

    proc = subprocess.run([sys.executable, "-m", "robodyn.cli", *argv], capture_output=True,
                          text=True)
    assert proc.returncode == code
    assert out in proc.stdout and err in proc.stderr
    if code == 0:
        assert proc.stdout.rstrip().splitlines() == _show_lines(argv)


def _show_lines(argv):
    """The same command's output through main() in this process."""
    import contextlib
    import io

    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        assert main(argv) == 0
    return buf.getvalue().rstrip().splitlines()


def test_every_command_group_registers_itself_the_same_way():
    # robodyn.cli's modules share one protocol: register(subparsers, formatter) adds commands
    import argparse
    import importlib
    import pkgutil

    import robodyn.cli as cli

    groups = [m.name for m in pkgutil.iter_modules(cli.__path__) if m.name not in ("args", "__main__")]
    assert len(groups) == 8
    registered = []
    for name in groups:
        parser = argparse.ArgumentParser()
        sub = parser.add_subparsers()
        importlib.import_module(f"robodyn.cli.{name}").register(sub, argparse.HelpFormatter)
        assert sub.choices, name
        for command in sub.choices.values():
            assert command.format_help()
        registered += list(sub.choices)
    # every command of `robodyn` comes from one group, none from robodyn.cli itself
    everything = cli._parser()._subparsers._group_actions[0].choices
    assert sorted(registered) == sorted(everything)
