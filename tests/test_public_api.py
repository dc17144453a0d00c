"""The public names of ``robodyn`` (DESIGN.md) and their lazy import."""

import subprocess
import sys

import pytest

import robodyn as rd


def test_every_public_name_resolves():
    for name in rd.__all__:
        assert getattr(rd, name) is not None, name
    assert sorted(dir(rd)) == sorted(set(dir(rd)) | set(rd.__all__))


def test_functions_named_like_their_subpackage_stay_functions():
    # importing the subpackages binds them on robodyn; the public functions must keep the names
    import robodyn.calibration.models  # noqa: F401
    import robodyn.identification  # noqa: F401
    import robodyn.simulation.controllers  # noqa: F401
    import robodyn.validation  # noqa: F401

    for name in ("simulate", "calibrate", "identify", "validate"):
        assert callable(getattr(rd, name)) and getattr(rd, name).__name__ == name


def test_import_robodyn_x_always_gives_a_module():
    # no package shares a public function's name, so `import robodyn.X as m` binds a module
    import pkgutil
    import types

    import robodyn.calibration as calibration
    import robodyn.identification as identification
    import robodyn.simulation as simulation
    import robodyn.validation as validation

    for m in (calibration, identification, simulation, validation):
        assert isinstance(m, types.ModuleType)
    packages = {info.name for info in pkgutil.iter_modules(rd.__path__)}
    assert not packages & set(rd.__all__), packages & set(rd.__all__)


def test_no_package_rebinds_a_submodule_name():
    # `from robodyn.simulation.linearize import linearize` in simulation/__init__.py made
    # `import robodyn.simulation.linearize as m` bind the function (the attribute wins): every
    # name a package's __init__ binds must differ from its submodules' names, unless it is that
    # submodule (read from the source, nothing imported)
    import ast
    from pathlib import Path

    root = Path(rd.__file__).parent
    traps = []
    for init in root.rglob("__init__.py"):
        package = ".".join(init.parent.relative_to(root.parent).parts)
        subs = {p.stem for p in init.parent.glob("*.py") if p.stem != "__init__"}
        subs |= {p.name for p in init.parent.iterdir() if (p / "__init__.py").exists()}
        for node in ast.parse(init.read_text()).body:  # module-level bindings
            if isinstance(node, ast.ImportFrom):
                source = node.module or ""
                for alias in node.names:
                    name = alias.asname or alias.name
                    if name in subs and f"{source}.{alias.name}" != f"{package}.{name}":
                        traps.append(f"{package}.{name}")
            elif isinstance(node, (ast.FunctionDef, ast.ClassDef)) and node.name in subs:
                traps.append(f"{package}.{node.name}")
            elif isinstance(node, ast.Assign):
                traps += [f"{package}.{t.id}" for t in node.targets
                          if isinstance(t, ast.Name) and t.id in subs]
    assert traps == []


def test_import_is_light():
    # `import robodyn` (and so the command line's start-up) pulls in none of the heavy stacks
    code = ("import sys, robodyn; heavy = [m for m in ('sympy', 'scipy', 'cvxpy', 'dask', 'pandas',"
            " 'matplotlib') if m in sys.modules]; print(','.join(heavy))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == ""


def test_every_input_error_has_one_base(tmp_path):
    import robodyn.errors as errors

    classes = [getattr(errors, name) for name in errors.__all__ if name.endswith("Error")]
    assert errors.RobodynError in classes and len(classes) >= 9
    for cls in classes:
        assert issubclass(cls, errors.RobodynError)
        # bad input is a ValueError; a missing optional package (pip extra) an ImportError
        assert cls is errors.RobodynError or issubclass(cls, ValueError) or (
            cls is errors.MissingExtraError and issubclass(cls, ImportError))
    # one except clause catches what the library raises about its input
    run = tmp_path / "run.csv"
    run.write_text("t,q1\n0,0\n")
    with pytest.raises(errors.RobodynError, match="neither a built-in spec"):
        rd.read_recording(run, spec="nonesuch")
