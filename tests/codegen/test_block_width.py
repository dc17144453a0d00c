"""The generated kernels' block width: chosen from the processor, overridden by ROBODYN_BLOCK.

The kernels themselves are checked at other widths by the CI, which reruns the suite (less the
slow tests) with ROBODYN_BLOCK=1 (scalar code) and with the width this processor does not get by
default; each width has its own compiled-model cache entries (checked here), so those reruns
test their own width's code and not kernels generated for another."""

from __future__ import annotations

import pytest

import robodyn.codegen.build as build
import robodyn.codegen.cpu as cpu
from robodyn.errors import InputError


def test_default_follows_the_vector_width(monkeypatch) -> None:
    monkeypatch.delenv("ROBODYN_BLOCK", raising=False)
    monkeypatch.setattr(cpu, "cpu_flags", lambda: frozenset({"sse2", "avx2", "avx512f"}))
    assert cpu.block_width() == 16
    monkeypatch.setattr(cpu, "cpu_flags", lambda: frozenset({"sse2", "avx2"}))
    assert cpu.block_width() == 16
    monkeypatch.setattr(cpu, "cpu_flags", lambda: frozenset({"sse2", "avx"}))  # AVX, no AVX2
    assert cpu.block_width() == 8
    monkeypatch.setattr(cpu, "cpu_flags", frozenset)  # no /proc/cpuinfo (macOS, ARM without it)
    assert cpu.block_width() == 8


@pytest.mark.parametrize("width", cpu.WIDTHS)
def test_environment_overrides_the_choice(monkeypatch, width: int) -> None:
    monkeypatch.setenv("ROBODYN_BLOCK", f" {width} ")
    assert cpu.block_width() == width


@pytest.mark.parametrize("text", ["0", "3", "64", "eight", "-16", "1e1"])
def test_a_bad_width_names_the_variable(monkeypatch, text: str) -> None:
    monkeypatch.setenv("ROBODYN_BLOCK", text)
    with pytest.raises(InputError, match=r"ROBODYN_BLOCK=.*one of 1, 2, 4, 8, 16, 32"):
        cpu.block_width()


_SOURCE_OF_A_MODEL = """
import json
import robodyn as rd
model = rd.compile_model(rd.load("planar_2r"))
source = next(p for p in model.sources if p.suffix == ".c")
print(json.dumps({"path": str(source), "text": source.read_text()}))
"""


def test_each_width_has_its_own_cache_entry(tmp_path) -> None:
    # one cache folder for both widths, as in a CI job that reruns the suite at another width:
    # the second process must generate its own width's source, not load the first one's
    import json
    import os
    import subprocess
    import sys

    found = {}
    for width in (4, 8):
        env = {**os.environ, "ROBODYN_BLOCK": str(width), "ROBODYN_CACHE": str(tmp_path)}
        out = subprocess.run([sys.executable, "-c", _SOURCE_OF_A_MODEL], env=env, check=True,
                             capture_output=True, text=True)
        found[width] = json.loads(out.stdout.splitlines()[-1])
        assert f"m_ <= {width} states" in found[width]["text"]
    assert found[4]["path"] != found[8]["path"]


def test_vector_flags_ask_for_256_bits_on_avx2_without_avx512():
    """The full AVX2 width is requested where -march=native's tuning may prefer 128 bits (a
    virtual machine's Zen 3 seen as Zen 1); nothing is added with AVX-512 or without AVX2, and
    the flag is part of the models' flags on this machine exactly when it has AVX2 alone."""
    from robodyn.codegen.build import CFLAGS
    from robodyn.codegen.cpu import cpu_flags, vector_flags

    assert vector_flags(frozenset({"avx", "avx2", "fma"})) == ("-mprefer-vector-width=256",)
    assert vector_flags(frozenset({"avx", "avx2", "fma", "avx512f"})) == ()
    assert vector_flags(frozenset({"sse2", "avx"})) == ()
    here = cpu_flags()
    assert ("-mprefer-vector-width=256" in CFLAGS) == ("avx2" in here and "avx512f" not in here)


@pytest.mark.parametrize(("path", "width", "expected"), [
    ("/usr/bin/gcc", 1, build.GCC_FLAGS + build.SCALAR_GCC_FLAGS),
    ("/usr/bin/x86_64-linux-gnu-gcc-12", 1, build.GCC_FLAGS + build.SCALAR_GCC_FLAGS),
    ("/opt/gcc-13.2/bin/gcc-13.2", 1, build.GCC_FLAGS + build.SCALAR_GCC_FLAGS),
    ("/usr/bin/x86_64-linux-gnu-gcc-12", 8, build.GCC_FLAGS),
    ("/usr/bin/clang-15", 1, ()),
    ("/usr/bin/icx", 1, ()),
])
def test_gcc_builds_align_loops_and_scalar_ones_skip_combine(path: str, width: int, expected) -> None:
    # (paths that do not exist are their own real path)
    assert build.compiler_flags(path, width) == expected


def test_cc_link_to_gcc_counts_as_gcc(tmp_path) -> None:
    gcc = tmp_path / "x86_64-linux-gnu-gcc-12"
    gcc.write_text("")
    (tmp_path / "cc").symlink_to(gcc)
    assert build.compiler_flags(str(tmp_path / "cc"), 1) == build.GCC_FLAGS + build.SCALAR_GCC_FLAGS
    assert build.compiler_flags(str(tmp_path / "cc"), 16) == build.GCC_FLAGS
