"""Every third-party package robodyn imports is declared in pyproject.toml, optional ones in the
extra robodyn.extras names, and a missing extra is one clear error naming the pip command."""

from __future__ import annotations

import ast
import re
import sys
import tomllib
from importlib.metadata import packages_distributions
from pathlib import Path

import pytest

from robodyn.errors import MissingExtraError, RobodynError
from robodyn.extras import EXTRAS, require

ROOT = Path(__file__).resolve().parent.parent
LIBRARY = ROOT / "src" / "robodyn" / "robot" / "library"


def _requirement_names(reqs: list[str]) -> set[str]:
    return {re.split(r"[\[<>=!~ ;]", r, maxsplit=1)[0].lower().replace("_", "-") for r in reqs}


def _declared() -> tuple[set[str], dict[str, set[str]]]:
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    extras = {k: _requirement_names(v) for k, v in project["optional-dependencies"].items()}
    return _requirement_names(project["dependencies"]), extras


def _imported_modules() -> set[str]:
    out = set()
    for path in (ROOT / "src" / "robodyn").rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                out |= {a.name.split(".")[0] for a in node.names}
            elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
                out.add(node.module.split(".")[0])
    return {m for m in out if m not in sys.stdlib_module_names and m != "robodyn"}


def test_every_direct_import_is_declared() -> None:
    core, extras = _declared()
    dists = packages_distributions()
    undeclared = []
    for module in sorted(_imported_modules() | set(EXTRAS)):
        names = {d.lower().replace("_", "-") for d in dists.get(module, [module])}
        wanted = extras[EXTRAS[module]] if module in EXTRAS else core
        if not names & wanted:
            undeclared.append(f"{module} ({', '.join(sorted(names))})")
    assert undeclared == []


#: Modules that may import an optional package at their top: each is itself imported only
#: inside the feature, after robodyn.extras.require has checked the extra.
LAZY_MODULES = {"robodyn.studies.shipping"}  # imported inside rd.sweep after require("distributed")


def test_optional_modules_are_not_imported_at_module_level() -> None:
    # an optional package is imported where the feature runs (robodyn.extras.require), so the
    # rest of robodyn works without it
    offenders = []
    for path in (ROOT / "src" / "robodyn").rglob("*.py"):
        module = ".".join(path.relative_to(ROOT / "src").with_suffix("").parts)
        for node in ast.parse(path.read_text(encoding="utf-8")).body:
            names = ([a.name for a in node.names] if isinstance(node, ast.Import)
                     else [node.module] if isinstance(node, ast.ImportFrom) and node.module else [])
            offenders += [f"{module}: {n}" for n in names
                          if (n.split(".")[0] in EXTRAS and module not in LAZY_MODULES)
                          or n in LAZY_MODULES]
    assert offenders == [], offenders


def test_a_missing_extra_names_the_pip_command(monkeypatch) -> None:
    monkeypatch.setitem(sys.modules, "mcap", None)  # import mcap now raises ImportError
    with pytest.raises(MissingExtraError, match=r"pip install 'robodyn\[ros\]'") as info:
        require("mcap", "rd.read_recording('run.mcap')")
    assert isinstance(info.value, RobodynError) and isinstance(info.value, ImportError)
    assert "rd.read_recording('run.mcap')" in str(info.value)


def test_urdf_files_need_the_urdf_extra_and_nothing_else_does(monkeypatch, tmp_path) -> None:
    # the URDF parser is the `urdf` extra: without it a URDF file is refused with the pip
    # command, while a built-in robot and a YAML description load as before
    import robodyn as rd

    urdf = tmp_path / "arm.urdf"
    urdf.write_text('<robot name="arm"><link name="base"/><link name="l1"><inertial><mass value="1"/>'
                    '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>'
                    '</link><joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>'
                    '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
                    '</robot>', encoding="utf-8")
    assert rd.load(str(urdf)).dof == 1  # with the extra installed (the test environment)
    monkeypatch.setitem(sys.modules, "yourdfpy", None)  # import yourdfpy now raises ImportError
    with pytest.raises(MissingExtraError, match=r"pip install 'robodyn\[urdf\]'") as info:
        rd.load(str(urdf))
    assert str(urdf) in str(info.value)
    assert rd.load("puma560").dof == 6
    assert rd.load(str(LIBRARY / "planar_2r.yaml")).dof == 2


def test_html_reports_need_the_report_extra(monkeypatch) -> None:
    # Jinja2 (and markupsafe) is the `report` extra: without it a report is refused with the pip
    # command when its module loads, while the library itself (no report) works as before
    import importlib

    import robodyn as rd

    for name in [m for m in sys.modules if m.startswith("robodyn.report")]:
        monkeypatch.delitem(sys.modules, name)
    monkeypatch.setitem(sys.modules, "jinja2", None)  # import jinja2 now raises ImportError
    with pytest.raises(MissingExtraError, match=r"pip install 'robodyn\[report\]'") as info:
        importlib.import_module("robodyn.report.identification_report")
    assert "an HTML report" in str(info.value)
    assert rd.compile_model(rd.load("planar_2r"), backend="numpy").dof == 2
