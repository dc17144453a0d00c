"""The README's benchmark sections and the results files they name (for the tests that check them).

``benchmarks/render_readme.py`` renders one marked README section per benchmark from a results
file (issue 22); ``tests/conftest.py`` offers :func:`load_renderer` and :func:`readme_sections`
as the fixtures ``renderer`` and ``sections``.
"""

from __future__ import annotations

import functools
import importlib.util
import json
import re
import sys
from pathlib import Path
from types import ModuleType
from typing import Any

ROOT = Path(__file__).resolve().parent.parent


@functools.cache
def benchmark_module(name: str) -> ModuleType:
    """``benchmarks/<name>.py`` loaded as a module (``benchmarks/`` is not a package), registered
    in ``sys.modules`` under ``name`` (its dataclasses look their module up there)."""
    spec = importlib.util.spec_from_file_location(name, ROOT / "benchmarks" / f"{name}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


def load_renderer() -> ModuleType:
    """``benchmarks/render_readme.py`` loaded as a module."""
    return benchmark_module("render_readme")


def readme_sections() -> dict[str, re.Match[str]]:
    """README's marked sections by benchmark name (the regex match of each)."""
    text = (ROOT / "README.md").read_text()
    return {m["name"]: m for m in load_renderer().MARKER.finditer(text)}


def section_data(sections: dict[str, re.Match[str]], name: str) -> dict[str, Any]:
    """The results file that README's section ``name`` names (asserted to exist)."""
    assert name in sections, f"README has no <!-- results:{name} PATH --> section"
    path = ROOT / sections[name]["path"]
    assert path.is_file(), f"README names {sections[name]['path']}, which is not committed"
    return json.loads(path.read_text())
