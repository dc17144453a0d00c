"""The generated kernels' block width: chosen from the processor, overridden by ROBODYN_BLOCK.

The kernels themselves are checked at other widths by the CI, which runs the kernel tests with
ROBODYN_BLOCK=1 (scalar code) and with the width this processor does not get by default."""

from __future__ import annotations

import pytest

import robodyn.codegen.cpu as cpu
from robodyn.errors import InputError


def test_default_follows_the_vector_width(monkeypatch) -> None:
    monkeypatch.delenv("ROBODYN_BLOCK", raising=False)
    monkeypatch.setattr(cpu, "cpu_flags", lambda: frozenset({"sse2", "avx2", "avx512f"}))
    assert cpu.block_width() == 16
    monkeypatch.setattr(cpu, "cpu_flags", lambda: frozenset({"sse2", "avx2"}))
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
