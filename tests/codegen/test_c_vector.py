"""The vectorised sine/cosine of the generated C batch functions.

``PREFIXsincos_block`` replaces libm's sin and cos in every kernel's batch loop: it must stay
within a couple of ulp of libm everywhere (libm itself beyond 1e5 rad and for inf/NaN) and the
compiler must actually vectorise it with the flags robodyn compiles with.
"""

from __future__ import annotations

import math
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
