"""The natively compiled Pinocchio peer of the kernel benchmark: skip lines and model file.

Compiles nothing and times nothing (the benchmark builds and runs the peer): checks that a
missing C++ compiler or missing headers give one clear line, that the flags are robodyn's, and
that the model file carries the benchmark's Pinocchio model number for number.
"""

from __future__ import annotations

import sys
from types import ModuleType

import numpy as np
import pytest

from robodyn.codegen.build import CFLAGS, SCALAR_GCC_FLAGS, applied_flags
from tests.readme_results import benchmark_module


@pytest.fixture(scope="module")
def peer() -> ModuleType:
    """``benchmarks/native_peer.py`` loaded as a module."""
    return benchmark_module("native_peer")


def test_no_cxx_compiler_is_one_line(peer, monkeypatch):
    monkeypatch.setenv("CXX", "/nonexistent/c++")
    with pytest.raises(peer.NativeUnavailable) as info:
        peer.cxx_compiler()
    assert "\n" not in str(info.value) and "/nonexistent/c++" in str(info.value)


def test_no_headers_is_one_line(peer, monkeypatch, tmp_path):
    monkeypatch.setattr(peer.sysconfig, "get_paths", lambda: {"purelib": str(tmp_path)})
    with pytest.raises(peer.NativeUnavailable, match="no Pinocchio headers") as info:
        peer.include_dirs()
    assert "\n" not in str(info.value)


def test_flags_are_robodyns_optimisation_flags(peer):
    flags = peer.native_flags()
    robodyn = [f for f in CFLAGS if f not in ("-fPIC", "-shared", "-std=c99")]
    assert list(flags[:len(robodyn)]) == robodyn
    assert {"-O3", "-march=native", "-DNDEBUG", "-std=c++17"} <= set(flags)
    # and what robodyn adds for its compiler's vector code (GCC: the loop alignment)
    added = [f for f in applied_flags(()) if f not in SCALAR_GCC_FLAGS]
    assert list(flags[len(robodyn):len(robodyn) + len(added)]) == added


def test_model_text_carries_the_pinocchio_model(peer):
    pin = pytest.importorskip("pinocchio")
    model = pin.buildSampleModelManipulator()
    model.armature[:] = np.arange(1, model.nv + 1) * 0.1
    lines = peer.model_text(model).splitlines()
    assert lines[0] == f"nq {model.nq}" and len(lines) == model.njoints + 1
    for j, line in enumerate(lines[2:], start=1):
        words = line.split()
        numbers = np.array(words[3:], float)
        place, inertia = model.jointPlacements[j], model.inertias[j]
        assert words[0] == "joint" and int(words[2]) == model.parents[j]
        np.testing.assert_array_equal(numbers[3:12], np.asarray(place.rotation).ravel())
        np.testing.assert_array_equal(numbers[12:15], place.translation)
        assert numbers[15] == inertia.mass and numbers[-1] == model.armature[j - 1]


def test_unsupported_joint_is_refused(peer):
    pin = pytest.importorskip("pinocchio")
    model = pin.buildSampleModelHumanoidRandom()  # free flyer: not a one-dof chain
    with pytest.raises(peer.NativeUnavailable, match="not supported"):
        peer.model_text(model)


if __name__ == "__main__":
    sys.exit(pytest.main([__file__, "-q"]))
