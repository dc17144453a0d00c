"""Test-suite policy: optional oracles, toolchains and data skip one test at a time, never a module.

A test that needs something outside robodyn says so with a marker, and only that test skips when
it is missing; every other test in the module still runs::

    @pytest.mark.oracle("pinocchio")         # an importable Python module (a test-only oracle)
    @pytest.mark.tool("gfortran")            # an executable on PATH
    @pytest.mark.data(GEN3)                  # a file outside the repository (../shared/data)

Modules import an oracle with ``try: import pinocchio as pin / except ImportError: pin = None``
so that importing the module never skips anything; a test that uses ``pin`` without the marker
fails loudly instead of vanishing.

Environment:

``ROBODYN_REQUIRE_ALL=1``
    (set by ``.ci/run``) a missing oracle, tool or data file is a test *failure*, not a skip:
    CI cannot pass while silently not exercising what it is meant to exercise.
``ROBODYN_TEST_HIDE=pinocchio,mujoco,gfortran``
    treat these modules/executables as missing (modules are made unimportable), to check which
    tests still run on a machine without them.
"""

from __future__ import annotations

import functools
import importlib
import importlib.abc
import importlib.util
import os
import shutil
import sys
from pathlib import Path

import pytest

REQUIRE_ALL = os.environ.get("ROBODYN_REQUIRE_ALL", "") == "1"
HIDDEN = frozenset(filter(None, (n.strip() for n in os.environ.get("ROBODYN_TEST_HIDE", "").split(","))))


class _Hide(importlib.abc.MetaPathFinder):
    """Makes the modules named in ROBODYN_TEST_HIDE unimportable (simulated absence)."""

    def find_spec(self, name, path, target=None):
        if name.partition(".")[0] in HIDDEN:
            raise ModuleNotFoundError(f"{name} is hidden by ROBODYN_TEST_HIDE", name=name)
        return None


if HIDDEN:
    sys.meta_path.insert(0, _Hide())


@functools.cache
def module_missing(name: str) -> str | None:
    """Why the Python module ``name`` cannot be used, or None when it can."""
    if name in HIDDEN:
        return f"Python module {name!r} hidden by ROBODYN_TEST_HIDE"
    try:
        importlib.import_module(name)
    except ImportError as exc:
        return f"Python module {name!r} not importable ({exc})"
    return None


@functools.cache
def tool_missing(name: str) -> str | None:
    """Why the executable ``name`` (or one of ``"a|b"``) cannot be used, or None when it is on PATH."""
    choices = name.split("|")
    if any(c not in HIDDEN and shutil.which(c) for c in choices):
        return None
    hidden = " (hidden by ROBODYN_TEST_HIDE)" if any(c in HIDDEN for c in choices) else ""
    return f"executable {' or '.join(map(repr, choices))} not on PATH{hidden}"


def data_missing(path: str | os.PathLike) -> str | None:
    """Why the data file ``path`` cannot be used, or None when it exists."""
    return None if Path(path).exists() else f"data file {path} not found"


_CHECKS = {"oracle": module_missing, "tool": tool_missing, "data": data_missing}
_MISSING = pytest.StashKey[str]()


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line("markers", "oracle(*modules): needs these importable Python modules (oracles)")
    config.addinivalue_line("markers", "tool(*executables): needs these executables on PATH")
    config.addinivalue_line("markers", "data(*paths): needs these data files outside the repository")


def _why_not(item: pytest.Item) -> str | None:
    """Why ``item`` cannot run here (its first missing oracle, tool or data file), or None."""
    for kind, check in _CHECKS.items():
        for mark in item.iter_markers(kind):
            if not mark.args:
                raise pytest.UsageError(f"{item.nodeid}: @pytest.mark.{kind} needs at least one argument")
            for arg in mark.args:
                reason = check(arg)
                if reason is not None:
                    return reason
    return None


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Mark what cannot run here: a skip (reported at the test's own line), or under
    ROBODYN_REQUIRE_ALL a failure raised when the test is set up."""
    for item in items:
        reason = _why_not(item)
        if reason is None:
            continue
        if REQUIRE_ALL:
            item.stash[_MISSING] = reason
        else:
            item.add_marker(pytest.mark.skip(reason=reason))


@pytest.hookimpl(tryfirst=True)
def pytest_runtest_setup(item: pytest.Item) -> None:
    """Before any fixture runs: under ROBODYN_REQUIRE_ALL, a missing requirement fails the test."""
    reason = item.stash.get(_MISSING, None)
    if reason is not None:
        pytest.fail(f"{reason}, and ROBODYN_REQUIRE_ALL=1 requires it", pytrace=False)


def pytest_terminal_summary(terminalreporter, exitstatus, config) -> None:
    """One line that says how many tests did not run, and whether that was allowed."""
    skipped = len(terminalreporter.stats.get("skipped", []))
    mode = "ROBODYN_REQUIRE_ALL=1: missing oracles/tools/data fail" if REQUIRE_ALL else (
        "set ROBODYN_REQUIRE_ALL=1 to make missing oracles/tools/data fail")
    hidden = f"; hidden: {', '.join(sorted(HIDDEN))}" if HIDDEN else ""
    terminalreporter.write_line(f"robodyn: {skipped} test(s) skipped ({mode}{hidden})")


@pytest.fixture(scope="session")
def renderer():
    """``benchmarks/render_readme.py`` as a module (:func:`tests.readme_results.load_renderer`)."""
    from tests.readme_results import load_renderer

    return load_renderer()


@pytest.fixture(scope="session")
def sections():
    """README's marked benchmark sections by name (:func:`tests.readme_results.readme_sections`)."""
    from tests.readme_results import readme_sections

    return readme_sections()
