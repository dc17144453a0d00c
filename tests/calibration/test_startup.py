"""Start-up of the command line: what building the parser imports (structural, no timing).

``robodyn --help`` and ``robodyn calibrate`` must not pay for SymPy's printing, the symbolic
layer, matplotlib, Dask, pandas, cffi or the URDF loader before they start their work. The
parser's choices are kept as literals in the ``cli*`` modules for that reason; they are checked
here against the modules that own them.
"""

from __future__ import annotations

import json
import subprocess
import sys

HEAVY = ("sympy", "matplotlib", "dask", "pandas", "cffi", "jinja2", "yourdfpy", "trimesh", "tqdm",
         "scipy.optimize", "robodyn.symbolic", "robodyn.simulation", "robodyn.identification",
         "robodyn.calibration", "robodyn.codegen")


def _imported_after(code: str) -> list[str]:
    """The HEAVY modules present in ``sys.modules`` after running ``code`` in a fresh process."""
    probe = f"{code}\nimport json, sys\nprint(json.dumps([m for m in {HEAVY!r} if m in sys.modules]))"
    out = subprocess.run([sys.executable, "-c", probe], check=True, capture_output=True, text=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_importing_the_cli_imports_nothing_heavy():
    assert _imported_after("import robodyn.cli") == []


def test_building_the_parser_imports_nothing_heavy():
    argv = ["calibrate", "puma560", "--data", "x.csv", "-o", "out"]
    code = f"import robodyn.cli\nrobodyn.cli._parser().parse_args({argv!r})"
    assert _imported_after(code) == []


def test_loading_a_builtin_robot_does_not_import_the_urdf_loader():
    loaded = _imported_after("import robodyn\nrobodyn.load('planar_2r')")
    assert "yourdfpy" not in loaded and "trimesh" not in loaded
    assert "sympy" in loaded  # the description itself holds SymPy expressions: the probe works


def test_calibrate_reaches_its_solver_without_sympy_on_a_cached_robot(tmp_path, monkeypatch):
    """``robodyn calibrate``'s work before the solve (robodyn.cli.workflows.calibration_inputs),
    in a fresh process, once the robot's numbers are cached: no SymPy, no symbolic or code
    generation layer, no compiler interface. The first process (nothing cached) loads in full."""
    monkeypatch.setenv("ROBODYN_CACHE", str(tmp_path / "cache"))
    data = tmp_path / "poses.csv"
    data.write_text("q1,q2,q3,q4,q5,q6,x,y,z\n" + "\n".join(
        ",".join(f"{0.1 * (i + k) % 1.3:.3f}" for k in range(6)) + f",{0.5 + 0.01 * i},0.2,0.3"
        for i in range(30)) + "\n")
    argv = ["calibrate", "puma560", "--data", str(data), "-o", str(tmp_path / "out"),
            "--nongeometric", "compliance"]
    code = ("import robodyn.cli\nfrom robodyn.cli.workflows import calibration_inputs\n"
            f"inputs = calibration_inputs(robodyn.cli._parser().parse_args({argv!r}))\n"
            "assert inputs.data.q.shape == (30, 6), inputs.data.q.shape")
    assert "sympy" in _imported_after(code)  # nothing cached yet: the description is loaded
    loaded = _imported_after(code)
    assert {"sympy", "robodyn.symbolic", "robodyn.codegen", "cffi", "scipy.optimize"}.isdisjoint(loaded)
    assert "robodyn.calibration" in loaded  # the probe sees what was imported


def test_parser_literals_match_their_sources():
    from robodyn.calibration.models import MODELS
    from robodyn.calibration.nongeometric import DEFLECTIONS
    from robodyn.cli import cache as cli_cache
    from robodyn.cli import equations as cli
    from robodyn.cli import identify as cli_identify
    from robodyn.cli import workflows as cli_workflows
    from robodyn.codegen.build import DEFAULT_CACHE_MAX_MB
    from robodyn.identification import options
    from robodyn.identification.friction import FRICTION_MODELS
    from robodyn.report.agreement import TOLERANCE
    from robodyn.simulation.simulation import ADAPTIVE, FIXED_STEP, MAX_SAMPLES
    from robodyn.symbolic.eom import METHODS
    from robodyn.symbolic.render import render_json, render_latex, render_text

    assert cli.METHODS == METHODS and cli.TOLERANCE == TOLERANCE
    assert set(cli._RENDERERS) == {"text", "latex", "json"}
    assert callable(render_text) and callable(render_latex) and callable(render_json)
    assert (cli_workflows.FIXED_STEP, cli_workflows.ADAPTIVE) == (FIXED_STEP, ADAPTIVE)
    assert cli_workflows.MAX_SAMPLES == MAX_SAMPLES
    assert cli_workflows.MODELS == tuple(MODELS)
    assert cli_workflows.DEFLECTIONS == tuple(DEFLECTIONS)
    assert cli_identify.FRICTION_MODELS == tuple(FRICTION_MODELS)
    assert (cli_identify.METHODS, cli_identify.VELOCITIES, cli_identify.SENSORS,
            cli_identify.SPIKES) == (options.METHODS, options.VELOCITIES, options.SENSORS, options.SPIKES)
    assert cli_cache.DEFAULT_CACHE_MAX_MB == DEFAULT_CACHE_MAX_MB


def test_calibration_code_imports_the_solver_and_plots_only_when_used():
    loaded = _imported_after(
        "import robodyn.calibration, robodyn.calibration.io, robodyn.calibration.pipeline")
    assert "scipy.optimize" not in loaded and "matplotlib" not in loaded
    assert "robodyn.calibration" in loaded  # the probe sees what was imported
