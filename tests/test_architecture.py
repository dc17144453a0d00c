"""robodyn's layers, read from the import graph of src/robodyn (docs/architecture.md).

Every ``import`` and ``from ... import`` of a robodyn module counts, also those inside functions
(they are dependencies all the same); only imports under ``if TYPE_CHECKING:`` do not. The graph
must have no cycle between files or between packages, and no import may run up the layers.
"""

from __future__ import annotations

import ast
import re
import subprocess
import sys
from collections import defaultdict
from pathlib import Path

SRC = Path(__file__).resolve().parent.parent / "src" / "robodyn"

#: Layer of every top-level package or module of robodyn, from the bottom. A module may import
#: only from its own layer or below (and the graph stays acyclic within a layer).
LAYERS: dict[str, int] = {
    "_version": 0, "spatial": 0, "text": 0, "keywords": 0, "cache": 0,
    "robot": 1, "errors": 1, "output_names": 1, "extras": 1,           # the description, immutable data
    "symbolic": 2,                                        # equations (hydro terms included)
    "codegen": 3, "export": 3,                            # code and file writers
    "numeric": 4,                                         # compiled models
    "simulation": 5, "measure": 5,                        # algorithms
    "calibration": 6, "validation": 6,
    "identification": 7,
    "studies": 8,                                         # case studies, experiment design, sweeps
    "report": 9,                                          # HTML, figures, the demo
    "<root>": 10,                                         # the public facade (lazy)
    "cli": 11,                                            # the robodyn command
}


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(SRC.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _package(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else "<root>"


def _imports(path: Path, known: set[str]) -> set[str]:
    """The robodyn modules ``path`` imports (the longest known prefix of each name)."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    hidden = {id(x) for node in ast.walk(tree)
              if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test)
              for sub in node.body for x in ast.walk(sub)}
    out = set()
    for node in ast.walk(tree):
        if id(node) in hidden:
            continue
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            subs = [f"{node.module}.{a.name}" for a in node.names]
            names = [s for s in subs if s in known] or [node.module]
        else:
            continue
        for name in names:
            parts = name.split(".")
            while parts and ".".join(parts) not in known:
                parts.pop()
            if parts and parts[0] == "robodyn":
                out.add(".".join(parts))
    return out


def _graph() -> dict[str, set[str]]:
    files = {_module_name(p): p for p in SRC.rglob("*.py")}
    known = set(files)
    return {m: _imports(p, known) - {m} for m, p in files.items()}


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components with more than one node (Tarjan, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[list[str]] = []
    counter = 0
    for root in sorted(graph):
        if root in index:
            continue
        work = [(root, iter(sorted(graph.get(root, ()))))]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on.add(root)
        while work:
            node, it = work[-1]
            nxt = next(it, None)
            if nxt is not None:
                if nxt not in index:
                    index[nxt] = low[nxt] = counter
                    counter += 1
                    stack.append(nxt)
                    on.add(nxt)
                    work.append((nxt, iter(sorted(graph.get(nxt, ())))))
                elif nxt in on:
                    low[node] = min(low[node], index[nxt])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                comp = []
                while True:
                    w = stack.pop()
                    on.discard(w)
                    comp.append(w)
                    if w == node:
                        break
                if len(comp) > 1:
                    out.append(sorted(comp))
    return out


def test_every_package_has_a_layer() -> None:
    packages = {_package(m) for m in _graph()}
    assert packages <= set(LAYERS), sorted(packages - set(LAYERS))


def test_no_cycle_between_files() -> None:
    assert _cycles(_graph()) == []


def test_no_cycle_between_packages() -> None:
    packages: dict[str, set[str]] = defaultdict(set)
    for a, targets in _graph().items():
        packages[_package(a)] |= {_package(b) for b in targets} - {_package(a)}
    assert _cycles(packages) == []


def test_no_import_runs_up_the_layers() -> None:
    upward = sorted(f"{a} -> {b}" for a, targets in _graph().items() for b in targets
                    if LAYERS.get(_package(b), 99) > LAYERS.get(_package(a), -1))
    assert upward == []


def test_the_checks_can_fail() -> None:
    # a cycle and an upward import, made up, are found
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert LAYERS["robot"] < LAYERS["studies"]


#: Size limits of issue 21 (shared/DESIGN.md's style): lines per file, lines per function body
#: (docstring excluded).
MAX_FILE_LINES, MAX_FUNCTION_LINES = 600, 80


def test_every_file_under_the_size_limit() -> None:
    long = {str(p.relative_to(SRC)): n for p in SRC.rglob("*.py")
            if (n := len(p.read_text(encoding="utf-8").splitlines())) > MAX_FILE_LINES}
    assert long == {}


def test_every_function_body_under_the_size_limit() -> None:
    long = []
    for path in SRC.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if not isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                continue
            first = node.body[0]
            start = first.lineno
            if (isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant)
                    and isinstance(first.value.value, str) and len(node.body) > 1):
                start = node.body[1].lineno  # the docstring does not count
            if node.end_lineno - start + 1 > MAX_FUNCTION_LINES:
                long.append(f"{path.relative_to(SRC)}:{node.lineno} {node.name}")
    assert long == []


def test_the_library_never_switches_the_matplotlib_backend() -> None:
    """Figures are object-oriented (``matplotlib.figure.Figure``): no ``matplotlib.use`` and no
    pyplot anywhere in the library, so a notebook user's backend is left as it was."""
    offenders = [f"{path.relative_to(SRC)}:{k}" for path in sorted(SRC.rglob("*.py"))
                 for k, line in enumerate(path.read_text().splitlines(), 1)
                 if re.search(r"matplotlib\.use\(|import matplotlib\.pyplot|from matplotlib import pyplot",
                              line)]
    assert not offenders, offenders
    code = ("import matplotlib; matplotlib.use('pdf'); "
            "import robodyn.report.underwater, robodyn.report.study_report, "
            "robodyn.studies.simulation_plots, robodyn.cli.record, robodyn.report.calibration_report; "
            "print(matplotlib.get_backend())")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "pdf"
