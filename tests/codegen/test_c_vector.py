"""The vectorised sine/cosine of the generated C batch functions.

``PREFIXsincos_block`` replaces libm's sin and cos in every kernel's batch loop: it must stay
within a couple of ulp of libm everywhere (libm itself beyond 1e5 rad and for inf/NaN) and the
compiler must actually vectorise it with the flags robodyn compiles with.
"""

from __future__ import annotations

import math
import re
import shutil
import subprocess

import numpy as np
import pytest

from robodyn.codegen.build import CFLAGS, compile_library
from robodyn.codegen.c import sincos_source

GCC = shutil.which("gcc")
WRAPPER = "void t_sincos(int n, const double *x, double *s, double *c) { t_sincos_block(n, x, s, c); }\n"


@pytest.fixture(scope="module")
def sincos():
    lib = compile_library("#include <math.h>\n" + sincos_source("t_") + WRAPPER,
                          "void t_sincos(int n, const double *x, double *s, double *c);")

    def run(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        x = np.ascontiguousarray(x, dtype=float)
        s, c = np.empty_like(x), np.empty_like(x)
        ptr = [lib.ffi.from_buffer("double[]", a) for a in (x, s, c)]
        lib.lib.t_sincos(len(x), *ptr)
        return s, c

    return run


def _ulp(actual: np.ndarray, expected: np.ndarray) -> float:
    return float(np.max(np.abs(actual - expected) / np.spacing(np.abs(expected))))


@pytest.mark.tool("gcc|cc")
@pytest.mark.parametrize("span", [1.0, 4.0, 100.0, 1e5])
def test_sincos_block_is_within_two_ulp_of_libm(sincos, span):
    rng = np.random.default_rng(int(span))
    x = rng.uniform(-span, span, 20_011)  # not a multiple of any vector width
    x[:8] = np.arange(8) * (math.pi / 2)  # near the quadrant edges
    # halfway between them, where x 2/pi rounds to the quadrant at a tie (either is within 1 ulp)
    k = int(span / (math.pi / 2) - 0.5)
    x[8:40] = (rng.integers(-k - 1, k + 1, 32) + 0.5) * (math.pi / 2)
    x[40:72] = np.nextafter(x[8:40], np.inf)
    s, c = sincos(x)
    assert _ulp(s, np.array([math.sin(v) for v in x])) <= 2.0
    assert _ulp(c, np.array([math.cos(v) for v in x])) <= 2.0


@pytest.mark.tool("gcc|cc")
def test_sincos_block_falls_back_to_libm_for_large_and_special_arguments(sincos):
    x = np.array([0.0, 1e-300, 5e-324, 1e5, -1e5, 1.0000001e5, 2.0**30, 1e300, -1e300])
    s, c = sincos(x)
    np.testing.assert_array_equal(s, [math.sin(v) for v in x])
    np.testing.assert_array_equal(c, [math.cos(v) for v in x])
    s, c = sincos(np.array([np.inf, -np.inf, np.nan]))
    assert np.isnan(s).all() and np.isnan(c).all()
    assert sincos(np.array([]))[0].shape == (0,)


@pytest.mark.tool("gcc")  # needs gcc's -fopt-info-vec
def test_sincos_block_is_vectorised_with_robodyn_flags(tmp_path):
    src = tmp_path / "sincos.c"
    src.write_text("#include <math.h>\n" + sincos_source("t_") + WRAPPER)
    flags = [f for f in CFLAGS if f != "-shared"]
    proc = subprocess.run([GCC, *flags, "-fopt-info-vec-optimized", "-c", str(src), "-o",
                           str(tmp_path / "sincos.o")], capture_output=True, text=True, check=True)
    # the polynomial loop is the first loop of the function
    loop_line = 1 + next(k for k, line in enumerate(src.read_text().splitlines())
                         if line.lstrip().startswith("for ("))
    assert f"sincos.c:{loop_line}:" in proc.stderr and "loop vectorized" in proc.stderr, proc.stderr


# --- kernel bodies vectorised across the states of a block ------------------------------------
# Every batch kernel against the NumPy backend (an independent printer of the same programs,
# evaluated one NumPy operation at a time, libm's sin/cos) on batch sizes around the block and
# vector widths; then the bits of one state alone against the same state inside a batch.

KERNEL_ROBOTS = ["puma560", "trolley_double_pendulum"]  # revolute + Coulomb; prismatic + revolute
SIZES = [1, 7, 8, 9, 16, 17, 1000]


@pytest.fixture(scope="module", params=KERNEL_ROBOTS)
def models(request):
    import robodyn as rd

    robot = rd.load(request.param)
    return rd.compile_model(robot), rd.compile_model(robot, backend="numpy")


def _inputs(model, name: str, count: int, seed: int = 5) -> list[np.ndarray]:
    from robodyn.codegen.kernels import kernel_signature

    rng = np.random.default_rng(seed)
    widths = [w for _, w in kernel_signature(name, model.dof)[0]]
    # torques large enough to matter next to gravity; positions over several turns
    return [rng.uniform(-7.0, 7.0, (count, w)) * (30.0 if k == len(widths) - 1 and name in
                                                   ("forward_dynamics", "state_derivative") else 1.0)
            for k, w in enumerate(widths)]


KERNELS = ["inverse_dynamics", "mass_matrix", "gravity", "coriolis", "forward_dynamics",
           "state_derivative", "forward_kinematics", "jacobian", "regressor"]


@pytest.mark.tool("gcc|cc")
@pytest.mark.parametrize("name", KERNELS)
def test_vectorised_kernel_matches_numpy_backend_on_every_batch_size(models, name):
    c_model, np_model = models
    for count in SIZES:
        args = _inputs(c_model, name, count, seed=count)
        got = getattr(c_model, name)(*args)
        want = getattr(np_model, name)(*args)
        assert got.shape == want.shape == (count, *want.shape[1:])
        # relative to the largest entry of each state's output (entries that cancel to ~0 have
        # no relative accuracy of their own)
        scale = np.max(np.abs(want.reshape(count, -1)), axis=1)
        err = np.max(np.abs((got - want).reshape(count, -1)), axis=1)
        assert np.all(err <= 1e-12 * np.maximum(scale, 1e-300)), (name, count, np.max(err / scale))


@pytest.mark.tool("gcc|cc")
@pytest.mark.parametrize("name", KERNELS)
def test_one_state_alone_has_the_bits_it_has_in_any_block_position(models, name):
    c_model, _ = models
    args = _inputs(c_model, name, 37, seed=11)
    batch = getattr(c_model, name)(*args)
    for k in range(37):
        alone = getattr(c_model, name)(*[a[k] for a in args])
        np.testing.assert_array_equal(alone, batch[k], err_msg=f"{name} state {k}")
    # and the same states at other offsets of a block
    shifted = getattr(c_model, name)(*[a[3:] for a in args])
    np.testing.assert_array_equal(shifted, batch[3:])


@pytest.mark.tool("gcc|cc")
@pytest.mark.parametrize("name", ["inverse_dynamics", "mass_matrix", "forward_dynamics", "regressor"])
def test_non_contiguous_and_odd_stride_inputs(models, name):
    c_model, np_model = models
    args = _inputs(c_model, name, 40, seed=2)
    want = getattr(np_model, name)(*[a[::3] for a in args])
    # every third row; a column slice of a wider array; Fortran order; a reversed view
    wide = [np.concatenate([a, a], axis=1)[:, : a.shape[1]] for a in args]
    variants = [[a[::3] for a in args],
                [w[::3] for w in wide],
                [np.asfortranarray(a[::3]) for a in args],
                [a[::-3][::-1] for a in args]]
    for variant in variants:
        assert not all(v.flags.c_contiguous for v in variant)
        before = [v.copy() for v in variant]
        got = getattr(c_model, name)(*variant)
        np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12 * np.max(np.abs(want)))
        for v, b in zip(variant, before, strict=True):
            np.testing.assert_array_equal(v, b)  # inputs untouched


@pytest.mark.slow
@pytest.mark.tool("gcc")  # needs gcc's -fopt-info-vec
def test_kernel_block_loops_are_vectorised(tmp_path):
    import robodyn as rd
    from robodyn.codegen.c import BLOCK, CPrinter
    from robodyn.numeric.model import _kernels_cached

    if BLOCK == 1:
        pytest.skip("ROBODYN_BLOCK=1: scalar code, one state per block, no block loop to vectorise")

    robot = rd.load("puma560")
    src = tmp_path / "puma.c"
    src.write_text(CPrinter("t_").source(_kernels_cached(robot, robot.parameters)))
    flags = [f for f in CFLAGS if f != "-shared"]
    proc = subprocess.run([GCC, *flags, "-fopt-info-vec-optimized", "-c", str(src), "-o",
                           str(tmp_path / "puma.o")], capture_output=True, text=True, check=True)
    lines = src.read_text().splitlines()
    blocks = [k + 2 for k, line in enumerate(lines) if "_block(int m_" in line]
    assert len(blocks) == len(KERNELS)
    for line in blocks:  # the loop over the block's states, the first line of each block core
        assert re.search(rf"puma.c:{line}:\d+: optimized: loop vectorized", proc.stderr), lines[line - 2]
