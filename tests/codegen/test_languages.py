"""Generated code in every target language against robodyn's NumPy backend.

Per robot (a revolute arm, a cart with a double pendulum, a prismatic arm) the kernels are built
once; every language is generated; C, Fortran, Octave and MEX are compiled and run at random
states and compared with ``rd.compile_model(robot, backend="numpy")`` to 1e-10 relative (the
difference divided by max(1, the largest reference entry)). Julia cannot be installed here and
Simulink does not exist for Octave: those files are checked structurally, the Julia kernels also
by evaluating a transliteration of their text, the S-function also through a stand-in for the
Simulink block object in Octave. A missing tool skips only the tests that need it (marked
``@pytest.mark.tool``); CI installs them all and sets ROBODYN_REQUIRE_ALL=1, which turns those skips
into failures.
"""

from __future__ import annotations

import math
import re
import shutil
import subprocess
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import cffi
import numpy as np
import pytest

import robodyn as rd
from robodyn.codegen.c import CPrinter
from robodyn.codegen.emit import LANGUAGES, generate
from robodyn.codegen.kernels import Kernel, KernelSet

ROBOTS = ("puma560", "trolley_double_pendulum", "aa300")
N_STATES = 4
REL = 1e-10
SIM_STEPS, SIM_DT = 40, 1e-3

GCC = shutil.which("gcc") or shutil.which("cc")
GFORTRAN = shutil.which("gfortran")
OCTAVE = shutil.which("octave-cli")
MKOCTFILE = shutil.which("mkoctfile")
PDFLATEX = shutil.which("pdflatex")
OCTAVE_ARGS = ("--no-gui", "--no-init-file", "--no-site-file", "--quiet", "--no-history")


# --- shared set-up: kernels, files, background builds ---------------------------------------------


@dataclass
class Bundle:
    """Everything generated for one robot, plus the builds started in the background."""

    name: str
    robot: rd.Robot
    model: rd.Model
    kset: KernelSet
    root: Path
    files: dict[str, list[Path]]
    inputs: dict[str, list[np.ndarray]]
    expected: dict[str, np.ndarray]
    builds: dict[str, subprocess.Popen] = field(default_factory=dict)
    logs: dict[str, str] = field(default_factory=dict)

    def wait(self, name: str) -> None:
        """Wait for a background build; fail with the compiler's message."""
        proc = self.builds[name]
        if name not in self.logs:
            self.logs[name] = proc.communicate()[0]
        assert proc.returncode == 0, f"{name} failed for {self.name}:\n{self.logs[name][-4000:]}"

    def dir(self, lang: str) -> Path:
        return self.root / lang


def _random_inputs(kset: KernelSet, rng: np.random.Generator) -> dict[str, list[np.ndarray]]:
    """Random arguments of every kernel, (N_STATES, width) each."""
    n = kset.dof
    q = rng.uniform(-math.pi, math.pi, (N_STATES, n))
    qd = rng.normal(0.0, 1.5, (N_STATES, n))
    values = {"q": q, "qd": qd, "qdd": rng.normal(0.0, 2.0, (N_STATES, n)),
              "tau": rng.normal(0.0, 5.0, (N_STATES, n)), "x": np.hstack([q, qd]),
              "u": rng.normal(0.0, 5.0, (N_STATES, n))}
    return {k.name: [values[a.name] for a in k.inputs] for k in kset.kernels}


def _start(cmd: list[str], cwd: Path) -> subprocess.Popen:
    return subprocess.Popen(cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)


@pytest.fixture(scope="module", params=ROBOTS)
def bundle(request, tmp_path_factory) -> Bundle:
    name = request.param
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the PUMA's published inertias trip a plausibility warning
        robot = rd.load(name)
    model = rd.compile_model(robot, backend="numpy")
    kset = model.kernels
    root = tmp_path_factory.mktemp(name)
    files = {lang: generate(kset, lang, root / lang) for lang in LANGUAGES}
    inputs = _random_inputs(kset, np.random.default_rng(sum(map(ord, name))))
    expected = {k: getattr(model, k)(*args) for k, args in inputs.items()}
    b = Bundle(name, robot, model, kset, root, files, inputs, expected)
    # compile in the background while the first tests run (2 cores are plenty)
    if GCC:
        c_dir = b.dir("c")
        b.builds["c_sim"] = _start([GCC, "-O1", "-std=c99", "-pedantic", "-Wall", "-Werror",
                                    f"{name}_sim.c", f"{name}.c", "-lm", "-o", "sim"], c_dir)
        b.builds["c_lib"] = _start([GCC, "-O1", "-std=c99", "-Wall", "-Werror", "-fPIC", "-shared",
                                    f"{name}.c", "-lm", "-o", f"lib{name}_c.so"], c_dir)
    if GFORTRAN:
        b.builds["fortran"] = _start([GFORTRAN, "-O1", "-std=f2008", "-pedantic", "-Wall",
                                      "-Wno-unused-dummy-argument", "-Werror", "-fPIC", "-shared",
                                      f"{name}.f90", "-o", f"lib{name}_f.so"], b.dir("fortran"))
    if MKOCTFILE:
        b.builds["mex"] = _start([MKOCTFILE, "--mex", f"{name}_mex.c", "-o", f"{name}_mex.mex"],
                                 b.dir("mex"))
    yield b
    for name, proc in b.builds.items():
        if name not in b.logs:
            proc.kill()
            proc.communicate()


def _rel_error(actual: np.ndarray, expected: np.ndarray) -> float:
    """max |actual - expected| / max(1, max |expected|)."""
    assert actual.shape == expected.shape, f"shape {actual.shape}, expected {expected.shape}"
    return float(np.max(np.abs(actual - expected)) / max(1.0, float(np.max(np.abs(expected)))))


def _check_all(results: dict[str, np.ndarray], b: Bundle, what: str) -> None:
    errors = {k: _rel_error(results[k], b.expected[k]) for k in b.kset.names}
    worst = max(errors, key=errors.get)
    print(f"\n{what} {b.name}: max relative difference {errors[worst]:.2e} ({worst})")
    bad = {k: e for k, e in errors.items() if not e <= REL}
    assert not bad, f"{what} {b.name}: kernels off by more than {REL}: {bad}"


# --- every language: files and headers ------------------------------------------------------------


def test_every_language_writes_files_with_provenance(bundle):
    n = bundle.kset.dof
    expected_names = {
        "c": {f"{bundle.name}.c", f"{bundle.name}.h", f"{bundle.name}_sim.c"},
        "python": {f"{bundle.name}.py"},
        "octave": {f"{bundle.name}_{k}.m" for k in bundle.kset.names},
        "fortran": {f"{bundle.name}.f90"},
        "julia": {f"{bundle.name}.jl"},
        "latex": {f"{bundle.name}.tex"},
        "mex": {f"{bundle.name}.c", f"{bundle.name}.h", f"{bundle.name}_mex.c", f"{bundle.name}_sfun.m"},
    }
    for lang, paths in bundle.files.items():
        assert {p.name for p in paths} == expected_names[lang], lang
        for path in paths:
            head = "\n".join(path.read_text().splitlines()[:12])
            assert "generated by robodyn" in head, path
            assert bundle.kset.description_hash in head, path
            assert f"{bundle.name} ({n} joints)" in head, path


def test_generate_rejects_bad_requests(bundle, tmp_path):
    with pytest.raises(ValueError, match="unknown language"):
        generate(bundle.kset, "cobol", tmp_path)
    with pytest.raises(ValueError, match="parameters"):
        generate(bundle.kset, "c", tmp_path, parameters={"m": 1.0})
    with pytest.raises(TypeError):
        generate("puma560", "c", tmp_path)
    assert not list(tmp_path.iterdir())


def test_generate_from_robot_with_parameters(tmp_path):
    robot = rd.load("trolley_pendulum")
    paths = generate(robot, "fortran", tmp_path, parameters={"m": 2.5})
    head = [ln for ln in paths[0].read_text().splitlines() if ln.startswith("!")][:6]
    assert any("Parameter values folded in" in ln and "m=2.5" in ln for ln in head)


# --- C: the emitted library and the standalone simulator --------------------------------------------


def _load(path: Path, kset: KernelSet, prefix: str):
    ffi = cffi.FFI()
    ffi.cdef(CPrinter(prefix).declarations(kset, with_simulation=False))
    return ffi, ffi.dlopen(str(path))


def _call_library(ffi, lib, b: Bundle, prefix: str) -> tuple[dict, dict]:
    """Every kernel through the C ABI: one state at a time, and batched."""
    single, batch = {}, {}
    for kernel in b.kset.kernels:
        args = [np.ascontiguousarray(a) for a in b.inputs[kernel.name]]
        shape = kernel.outputs[0].shape
        out = np.empty((N_STATES, *shape))
        for k in range(N_STATES):
            res = np.empty(shape)
            getattr(lib, f"{prefix}{kernel.name}")(
                *[ffi.from_buffer("double[]", np.ascontiguousarray(a[k])) for a in args],
                ffi.from_buffer("double[]", res))
            out[k] = res
        single[kernel.name] = out
        out_b = np.empty((N_STATES, *shape))
        getattr(lib, f"{prefix}{kernel.name}_batch")(
            N_STATES, *[ffi.from_buffer("double[]", a) for a in args], ffi.from_buffer("double[]", out_b))
        batch[kernel.name] = out_b
    return single, batch


@pytest.mark.slow
@pytest.mark.tool("gcc|cc")
def test_c_library_matches_numpy(bundle):
    bundle.wait("c_lib")
    ffi, lib = _load(bundle.dir("c") / f"lib{bundle.name}_c.so", bundle.kset, f"{bundle.name}_")
    single, batch = _call_library(ffi, lib, bundle, f"{bundle.name}_")
    _check_all(single, bundle, "C (one state)")
    _check_all(batch, bundle, "C (batch)")


@pytest.mark.tool("gcc|cc")
def test_c_simulator_matches_compiled_model(bundle):
    bundle.wait("c_sim")
    n = bundle.kset.dof
    rng = np.random.default_rng(7)
    x0 = np.concatenate([rng.uniform(-1.0, 1.0, n), rng.normal(0.0, 0.5, n)])
    cmd = [str(bundle.dir("c") / "sim"), repr(SIM_STEPS * SIM_DT), repr(SIM_DT),
           *(repr(float(v)) for v in x0)]
    proc = subprocess.run(cmd, capture_output=True, text=True, check=False, timeout=60)
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    header = [f"q{j}" for j in range(1, n + 1)] + [f"qd{j}" for j in range(1, n + 1)]
    assert lines[0] == ",".join(["t", *header])
    table = np.array([[float(v) for v in line.split(",")] for line in lines[1:]])
    assert table.shape == (SIM_STEPS + 1, 1 + 2 * n)
    np.testing.assert_allclose(table[:, 0], SIM_DT * np.arange(SIM_STEPS + 1), rtol=0, atol=1e-15)
    x_ref, _ = rd.rollout(rd.compile_model(bundle.robot), x0, rd.RolloutOptions(SIM_STEPS, SIM_DT))
    err = _rel_error(table[:, 1:], x_ref)
    print(f"\nC simulator {bundle.name}: max relative difference {err:.2e} over {SIM_STEPS} RK4 steps")
    assert err <= REL
    # bad arguments are refused with a message and exit status 2
    bad = subprocess.run([cmd[0], "1", "0"], capture_output=True, text=True, check=False)
    assert bad.returncode == 2 and "dt > 0" in bad.stderr
    bad = subprocess.run([cmd[0], "1", "1e-3", "0.5"], capture_output=True, text=True, check=False)
    assert bad.returncode == 2 and "x0" in bad.stderr  # one value: neither q nor [q; qd]


# --- Fortran ----------------------------------------------------------------------------------------


def test_fortran_lines_and_literals(bundle):
    text = bundle.files["fortran"][0].read_text()
    assert max(len(line) for line in text.splitlines()) <= 132
    # every real literal is double precision (d exponent), never a default-real 1.5 or 1.5e0
    code = "\n".join(line for line in text.splitlines() if not line.lstrip().startswith("!"))
    code = re.sub(r'"[^"]*"', "", code)
    assert not re.search(r"(?<![\w.])\d+\.\d*(?:e[+-]?\d+)?(?![\w.])", code)
    for k in bundle.kset.names:
        assert f"subroutine {bundle.name}_{k}(" in text
        assert f"subroutine {bundle.name}_{k}_batch(count" in text


@pytest.mark.tool("gfortran")
def test_fortran_matches_numpy(bundle):
    bundle.wait("fortran")
    ffi, lib = _load(bundle.dir("fortran") / f"lib{bundle.name}_f.so", bundle.kset, f"{bundle.name}_")
    single, batch = _call_library(ffi, lib, bundle, f"{bundle.name}_")
    _check_all(single, bundle, "Fortran (one state)")
    _check_all(batch, bundle, "Fortran (batch)")


# --- Octave: .m files, MEX and the S-function through a stand-in block -------------------------------

_MOCK_BLOCK = """classdef MockBlock < handle
  % Stand-in for Simulink's Level-2 S-function block: only what robodyn's S-function touches.
  properties
    NumDialogPrms = 0; DialogPrmsTunable = {}; NumInputPorts = 0; NumOutputPorts = 0;
    InputPort = struct(); OutputPort = struct(); NumContStates = 0; SampleTimes = [];
    SimStateCompliance = ''; DialogPrm = struct('Data', []);
    ContStates = struct('Data', []); Derivatives = struct('Data', []); Methods = struct();
  end
  methods
    function SetPreCompInpPortInfoToDynamic(obj)
    end
    function SetPreCompOutPortInfoToDynamic(obj)
    end
    function RegBlockMethod(obj, name, handle)
      obj.Methods.(name) = handle;
    end
  end
end
"""


def _octave_script(b: Bundle, with_mex: bool) -> str:
    """One Octave run: every kernel by .m file (batch and one state), by MEX, the S-function."""
    lines = ["more off;", "fmt = '%.17g';", "ids = fopen('error_ids.txt', 'w');",
             "sizes = fopen('sizes.txt', 'w');"]
    for kernel in b.kset.kernels:
        ins = []
        for a, arr in zip(kernel.inputs, b.inputs[kernel.name], strict=True):
            np.savetxt(b.dir("octave") / f"in_{kernel.name}_{a.name}.csv", arr.T, fmt="%.17g",
                       delimiter=",")
            lines.append(f"{a.name} = dlmread('in_{kernel.name}_{a.name}.csv', ',');")
            ins.append(a.name)
        args = ", ".join(ins)
        first = ", ".join(f"{a}(:, 1)" for a in ins)
        lines += [f"r = {b.name}_{kernel.name}({args});",
                  f"dlmwrite('m_{kernel.name}.csv', reshape(r, [], {N_STATES}), 'precision', fmt);",
                  f"r1 = {b.name}_{kernel.name}({first});",
                  f"fprintf(sizes, '{kernel.name} %s\\n', mat2str(size(r1)));",
                  f"dlmwrite('m1_{kernel.name}.csv', r1(:), 'precision', fmt);"]
        if with_mex:
            lines += [f"r = {b.name}_mex('{kernel.name}', {args});",
                      f"dlmwrite('mex_{kernel.name}.csv', reshape(r, [], {N_STATES}), 'precision', fmt);",
                      f"r1 = {b.name}_mex('{kernel.name}', {first});",
                      f"fprintf(sizes, 'mex_{kernel.name} %s\\n', mat2str(size(r1)));"]
    n = b.kset.dof
    bad_calls = [f"{b.name}_mass_matrix(ones({n + 1}, 1))", f"{b.name}_inverse_dynamics(q)",
                 f"{b.name}_coriolis(q, qd(:, 1:end-1))"]
    if with_mex:
        bad_calls += [f"{b.name}_mex('mass_matrix', ones({n + 1}, 1))",
                      f"{b.name}_mex('inverse_dynamics', q)", f"{b.name}_mex('no_such_kernel')",
                      f"{b.name}_mex('gravity', single(q))", f"{b.name}_mex('coriolis', q, qd(:, 1:end-1))"]
        # the S-function, driven as Simulink would: setup, check, initial state, outputs, derivatives
        x0, tau = b.inputs["state_derivative"][0][0], b.inputs["state_derivative"][1][0]
        lines += [
            "blk = MockBlock();",
            f"blk.DialogPrm = struct('Data', {_octave_vector(x0)});",
            f"{b.name}_sfun(blk);",
            "fprintf(sizes, 'sfun %d %d %d %d %d %d\\n', blk.NumDialogPrms, blk.NumInputPorts, "
            "blk.NumOutputPorts, blk.NumContStates, blk.InputPort(1).Dimensions, "
            "blk.OutputPort(2).Dimensions);",
            "f = blk.Methods.CheckParameters; f(blk);",
            "f = blk.Methods.InitializeConditions; f(blk);",
            "f = blk.Methods.Outputs; f(blk);",
            f"blk.InputPort(1).Data = {_octave_vector(tau)};",
            "f = blk.Methods.Derivatives; f(blk);",
            "dlmwrite('sfun.csv', [blk.OutputPort(1).Data(:); blk.OutputPort(2).Data(:); "
            "blk.Derivatives.Data(:)], 'precision', fmt);",
        ]
        bad_calls.append(f"feval(blk.Methods.CheckParameters, struct('DialogPrm', struct('Data', 1:{n})))")
    for call in bad_calls:
        lines.append(f"try, {call}; fprintf(ids, 'none\\n'); "
                     "catch err, fprintf(ids, '%s\\n', err.identifier); end")
    lines += ["fclose(ids); fclose(sizes);"]
    return "\n".join(lines) + "\n"


def _octave_vector(v: np.ndarray) -> str:
    return "[" + "; ".join(repr(float(x)) for x in v) + "]"


@dataclass
class OctaveRun:
    directory: Path
    with_mex: bool


@pytest.fixture(scope="module")
def octave_run(bundle) -> OctaveRun:
    assert OCTAVE is not None, "a test using octave_run needs @pytest.mark.tool('octave-cli')"
    work = bundle.dir("octave")
    with_mex = MKOCTFILE is not None
    if with_mex:
        bundle.wait("mex")
        for path in bundle.dir("mex").iterdir():
            if path.suffix in (".mex", ".m"):
                shutil.copy(path, work / path.name)
        (work / "MockBlock.m").write_text(_MOCK_BLOCK)
    (work / "run_all.m").write_text(_octave_script(bundle, with_mex))
    proc = subprocess.run([OCTAVE, *OCTAVE_ARGS, "--eval", "run_all"], cwd=work, capture_output=True,
                          text=True, check=False, timeout=300)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    return OctaveRun(work, with_mex)


def _read_batch(path: Path, shape: tuple[int, ...]) -> np.ndarray:
    """An Octave ``reshape(r, [], N)`` file back to (N, *shape) with natural indexing."""
    flat = np.loadtxt(path, delimiter=",", ndmin=2).T  # (N, entries), column-major entries
    return flat.reshape((N_STATES, *shape[::-1])).transpose(0, *range(len(shape), 0, -1))


def _sizes(run: OctaveRun) -> dict[str, str]:
    return dict(line.split(" ", 1) for line in (run.directory / "sizes.txt").read_text().splitlines())


@pytest.mark.tool("octave-cli")
def test_octave_m_files_match_numpy(bundle, octave_run):
    results, single = {}, {}
    sizes = _sizes(octave_run)
    for kernel in bundle.kset.kernels:
        shape = kernel.outputs[0].shape
        results[kernel.name] = _read_batch(octave_run.directory / f"m_{kernel.name}.csv", shape)
        one = np.loadtxt(octave_run.directory / f"m1_{kernel.name}.csv", delimiter=",")
        single[kernel.name] = np.broadcast_to(one.reshape(shape[::-1]).T, (N_STATES, *shape))
        want = f"[{shape[0]} {shape[1] if len(shape) == 2 else 1}]"
        assert sizes[kernel.name] == want, kernel.name
    _check_all(results, bundle, "Octave .m (batch)")
    first = {k: v[:1] for k, v in single.items()}
    errors = {k: _rel_error(first[k], bundle.expected[k][:1]) for k in first}
    assert max(errors.values()) <= REL, errors


@pytest.mark.tool("octave-cli")
def test_octave_m_files_reject_bad_input(bundle, octave_run):
    ids = (octave_run.directory / "error_ids.txt").read_text().splitlines()
    assert ids[:3] == ["robodyn:size", "robodyn:nargin", "robodyn:size"]


@pytest.mark.tool("octave-cli", "mkoctfile")
def test_mex_matches_numpy(bundle, octave_run):
    results = {k.name: _read_batch(octave_run.directory / f"mex_{k.name}.csv", k.outputs[0].shape)
               for k in bundle.kset.kernels}
    _check_all(results, bundle, "MEX (batch)")
    sizes = _sizes(octave_run)
    for kernel in bundle.kset.kernels:
        shape = kernel.outputs[0].shape
        assert sizes[f"mex_{kernel.name}"] == f"[{shape[0]} {shape[1] if len(shape) == 2 else 1}]"


@pytest.mark.tool("octave-cli", "mkoctfile")
def test_mex_rejects_bad_input(bundle, octave_run):
    ids = (octave_run.directory / "error_ids.txt").read_text().splitlines()
    assert ids[3:8] == ["robodyn:mex:size", "robodyn:mex:nargin", "robodyn:mex:kernel",
                        "robodyn:mex:type", "robodyn:mex:size"]


@pytest.mark.tool("octave-cli", "mkoctfile")
def test_sfunction_through_stand_in_block(bundle, octave_run):
    n = bundle.kset.dof
    assert _sizes(octave_run)["sfun"] == f"1 1 2 {2 * n} {n} {n}"
    out = np.loadtxt(octave_run.directory / "sfun.csv", delimiter=",")
    x0 = bundle.inputs["state_derivative"][0][0]
    np.testing.assert_array_equal(out[:2 * n], x0)  # outputs q, qd = the initial state
    err = _rel_error(out[2 * n:], bundle.expected["state_derivative"][0])
    print(f"\nS-function derivatives {bundle.name}: max relative difference {err:.2e}")
    assert err <= REL
    ids = (octave_run.directory / "error_ids.txt").read_text().splitlines()
    assert ids[8] == "robodyn:sfun:x0"


def test_sfunction_structure(bundle):
    text = (bundle.dir("mex") / f"{bundle.name}_sfun.m").read_text()
    n = bundle.kset.dof
    assert text.startswith(f"function {bundle.name}_sfun(block)\n")
    for method in ("CheckParameters", "InitializeConditions", "Outputs", "Derivatives"):
        assert f"block.RegBlockMethod('{method}'," in text
    for line in (f"block.NumContStates = {2 * n};", f"block.InputPort(1).Dimensions = {n};",
                 f"block.OutputPort(k).Dimensions = {n};", "block.NumDialogPrms = 1;",
                 "block.SampleTimes = [0 0];", f"{bundle.name}_mex('state_derivative'"):
        assert line in text
    assert _balanced_blocks(text, r"(function|for|if|while|switch|try)\b", r"end\b")


# --- Julia: structure, and a transliteration evaluated in Python ------------------------------------


def _balanced_blocks(text: str, opener: str, closer: str) -> bool:
    depth = 0
    for raw in text.splitlines():
        line = raw.split("#")[0].split("%")[0].strip()
        if re.match(opener, line) or line.endswith(" begin"):
            depth += 1
        if re.match(closer, line):
            depth -= 1
            if depth < 0:
                return False
    return depth == 0


_JULIA_FUNCTION = re.compile(r"^function (\w+)!\((.*?)\)\n(.*?)^end$", re.M | re.S)


class _OneBased:
    """A NumPy array indexed from 1, as Julia indexes."""

    def __init__(self, array: np.ndarray) -> None:
        self.array = array

    def _index(self, key):
        return tuple(k - 1 for k in key) if isinstance(key, tuple) else key - 1

    def __getitem__(self, key):
        return self.array[self._index(key)]

    def __setitem__(self, key, value):
        self.array[self._index(key)] = value


def _julia_to_python(line: str) -> str:
    line = re.sub(r"\(([^()?]+) \? ([^():]+) : ([^()]+)\)", r"((\2) if (\1) else (\3))", line)
    return line.replace("^", "**")


def test_julia_module_structure(bundle):
    text = bundle.files["julia"][0].read_text()
    assert _balanced_blocks(text, r"(function|module|for|if|while|let|begin)\b", r"end\b")
    found = {m[1]: m for m in _JULIA_FUNCTION.finditer(text)}
    assert set(found) == set(bundle.kset.names)
    for kernel in bundle.kset.kernels:
        assert text.count(f"\nfunction {kernel.name}(") == 2  # one state and a batch
        _check_julia_kernel(kernel, found[kernel.name][2], found[kernel.name][3])


def _check_julia_kernel(kernel: Kernel, signature: str, body: str) -> None:
    """Indices in range, every output entry stored once, every name defined before its use."""
    args = {a.name: a for a in (*kernel.inputs, *kernel.outputs)}
    out = kernel.outputs[0]
    assert [p.split("::")[0] for p in signature.split(", ")] == [out.name, *(a.name for a in kernel.inputs)]
    defined = set(args) | {"sin", "cos", "sqrt", "size", "throw", "DimensionMismatch", "begin", "end",
                           "inbounds", "return", "got"}
    stored = []
    for line in body.splitlines():
        line = line.strip()
        for name, idx in re.findall(r"\b(\w+)\[([\d, ]+)\]", line):
            shape = args[name].shape
            index = tuple(int(i) for i in idx.split(","))
            assert len(index) == len(shape) and all(1 <= i <= s for i, s in zip(index, shape, strict=True)), \
                (kernel.name, line)
        m = re.fullmatch(r"(\w+)(\[[\d, ]+\])? = (.*)", line)
        if not m:
            continue
        rhs = re.sub(r"\d+\.\d*(e-?\d+)?|\d+e-?\d+", "", m[3])
        for token in re.findall(r"[A-Za-z_]\w*", rhs):
            assert token in defined, f"{kernel.name}: {token} used before it is assigned in {line!r}"
        if m[2]:
            assert m[1] == out.name
            stored.append(m[2])
        else:
            defined.add(m[1])
    assert len(stored) == len(set(stored)) == out.size, kernel.name


def test_julia_kernels_evaluate_like_numpy(bundle):
    """The in-place kernels' text, transliterated line by line to Python, computes the same numbers."""
    text = bundle.files["julia"][0].read_text()
    results = {}
    for m in _JULIA_FUNCTION.finditer(text):
        name, body = m[1], m[3]
        kernel = bundle.kset[name]
        lines = [ln.strip() for ln in body.splitlines()
                 if re.fullmatch(r"\s*\w+(\[[\d, ]+\])? = .*", ln)]
        code = compile("\n".join(_julia_to_python(ln) for ln in lines), f"<julia {name}>", "exec")
        shape = kernel.outputs[0].shape
        out = np.empty((N_STATES, *shape))
        for k in range(N_STATES):
            env = {"sin": math.sin, "cos": math.cos, "sqrt": math.sqrt}
            env |= {a.name: _OneBased(arr[k]) for a, arr in zip(kernel.inputs, bundle.inputs[name],
                                                                 strict=True)}
            env[kernel.outputs[0].name] = _OneBased(out[k])
            exec(code, env)  # noqa: S102 - our own generated text
        results[name] = out
    _check_all(results, bundle, "Julia (transliterated)")


# --- LaTeX ------------------------------------------------------------------------------------------


def test_latex_document_structure(bundle):
    text = bundle.files["latex"][0].read_text()
    assert text.count(r"\begin{document}") == text.count(r"\end{document}") == 1
    assert text.count(r"\begin{align*}") == text.count(r"\end{align*}") >= len(bundle.kset.kernels)
    assert text.count(r"\section*{") == len(bundle.kset.kernels)
    assert "t_{" in text or "c_{" in text
    for line in text.splitlines():
        if line.startswith("%"):
            continue
        stripped = line.replace(r"\{", "").replace(r"\}", "")
        assert stripped.count("{") == stripped.count("}"), line
        assert line.count(r"\left") == line.count(r"\right"), line


@pytest.mark.tool("pdflatex")
def test_latex_document_compiles(bundle):
    work = bundle.dir("latex")
    proc = subprocess.run([PDFLATEX, "-interaction=nonstopmode", "-halt-on-error", f"{bundle.name}.tex"],
                          cwd=work, capture_output=True, text=True, check=False, timeout=120)
    assert proc.returncode == 0, proc.stdout[-3000:]
    assert (work / f"{bundle.name}.pdf").stat().st_size > 1000
