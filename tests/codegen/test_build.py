"""The compiled-model cache: private directory, corrupt entries rebuilt, size limit, CLI."""

from __future__ import annotations

import os
import stat
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest

from robodyn.cli import main
from robodyn.codegen import build
from robodyn.codegen.build import cache_info, cache_limit, clear_cache, compile_library

DECL = "double rd_test_twice(double x);"


def source(k: int) -> str:
    """A tiny distinct C library (one cache entry each)."""
    return f"double rd_test_twice(double x) {{ return 2.0 * x + {k}.0; }}\n"


@pytest.fixture()
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    path = tmp_path / "cache" / "robodyn"
    monkeypatch.setenv("ROBODYN_CACHE", str(path))
    monkeypatch.delenv("ROBODYN_CACHE_MAX_MB", raising=False)
    return path


def run_fresh(k: int, cache: Path) -> subprocess.CompletedProcess:
    """Compile-or-load ``source(k)`` in a fresh process (nothing already dlopen'ed)."""
    code = ("from robodyn.codegen.build import compile_library\n"
            f"lib = compile_library({source(k)!r}, {DECL!r})\n"
            "print(lib.lib.rd_test_twice(1.5))\n")
    env = {**os.environ, "ROBODYN_CACHE": str(cache)}
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          env=env, check=False, timeout=120)


@pytest.mark.tool("cc")
def test_cache_directory_is_private(cache: Path) -> None:
    lib = compile_library(source(0), DECL)
    assert lib.lib.rd_test_twice(1.5) == 3.0
    assert stat.S_IMODE(cache.stat().st_mode) == 0o700
    assert lib.path.parent == cache


@pytest.mark.tool("cc")
@pytest.mark.parametrize("damage", ["truncate", "flip", "no manifest"])
def test_corrupt_entry_is_detected_and_rebuilt(cache: Path, damage: str) -> None:
    first = run_fresh(1, cache)
    assert first.returncode == 0, first.stderr
    assert first.stdout.strip() == "4.0"
    (so,) = cache.glob("rd_*.so")
    good = so.read_bytes()
    if damage == "truncate":  # an interrupted copy or a full disk: dlopen said "file too short"
        so.write_bytes(good[: len(good) // 3])
    elif damage == "flip":  # same size, different content: only the hash tells
        so.write_bytes(good[:-100] + bytes(b ^ 0xFF for b in good[-100:]))
    else:
        so.with_name(so.name + ".sha256").unlink()
    again = run_fresh(1, cache)
    assert again.returncode == 0, again.stderr
    assert again.stdout.strip() == "4.0"
    assert so.read_bytes() == good  # the same compiler and flags give the same library
    assert so.with_name(so.name + ".sha256").read_text().split() == [
        str(len(good)), __import__("hashlib").sha256(good).hexdigest()]


@pytest.mark.tool("cc")
def test_least_recently_used_entries_are_evicted_beyond_the_limit(
        cache: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    a, b = compile_library(source(10), DECL).path, compile_library(source(11), DECL).path
    entry = sum(p.stat().st_size for p in cache.glob("rd_*"))  # two entries
    # room for about two entries: the third evicts the least recently used one
    monkeypatch.setenv("ROBODYN_CACHE_MAX_MB", repr(entry * 1.2 / 2**20))
    old = time.time() - 100
    os.utime(a, (old, old))
    os.utime(b, (old - 50, old - 50))
    assert compile_library(source(10), DECL).lib.rd_test_twice(0.0) == 10.0  # uses a: now newest
    c = compile_library(source(12), DECL).path
    assert a.exists() and c.exists()
    assert not b.exists() and not b.with_name(b.name + ".sha256").exists()
    assert cache_info().size <= cache_limit()


@pytest.mark.tool("cc")
def test_an_entry_larger_than_the_limit_is_still_kept(cache, monkeypatch) -> None:
    monkeypatch.setenv("ROBODYN_CACHE_MAX_MB", "0")
    compile_library(source(20), DECL)
    lib = compile_library(source(21), DECL)
    assert [p.name for p in sorted(cache.glob("rd_*.so"))] == [lib.path.name]


@pytest.mark.parametrize("text", ["-1", "lots", "nan", "inf"])
def test_bad_limit_is_a_clear_error(monkeypatch, text) -> None:
    monkeypatch.setenv("ROBODYN_CACHE_MAX_MB", text)
    with pytest.raises(ValueError, match=rf"ROBODYN_CACHE_MAX_MB={text!r}: expected a "
                                         "non-negative number of megabytes"):
        cache_limit()


@pytest.mark.tool("cc")
def test_cli_cache_info_and_clear_leave_other_files_alone(cache: Path, capsys) -> None:
    compile_library(source(30), DECL)
    compile_library(source(31), DECL)
    cache.joinpath("notes.txt").write_text("mine")  # a user's file in a shared $ROBODYN_CACHE
    # user files whose names look like robodyn's (issue 23: 'cache clear' deleted them)
    for name in ("rd_thesis_draft.docx", "rd_measurements.csv", "rd_model_notes.py"):
        cache.joinpath(name).write_text("mine")
    (cache / ".build-notes").mkdir()
    (cache / ".build-notes" / "keep.txt").write_text("mine")
    # what an interrupted compilation leaves: tempfile's own folder name
    tempfile.mkdtemp(dir=cache, prefix=".build-")
    size = sum(p.stat().st_size for p in cache.glob("rd_*") if p.read_bytes() != b"mine")
    assert main(["cache", "info"]) == 0
    out = capsys.readouterr().out
    assert f"location  {cache}\n" in out
    assert "entries   2 compiled libraries (6 files)" in out  # each: library, manifest, index
    assert f"size      {size / 2**20:.1f} MB ({size} bytes) of 1024.0 MB" in out
    assert build.DEFAULT_CACHE_MAX_MB == 1024
    assert main(["cache", "clear"]) == 0
    assert f"removed 6 files ({size} bytes) from {cache}" in capsys.readouterr().out
    assert sorted(p.name for p in cache.iterdir()) == [".build-notes", "notes.txt", "rd_measurements.csv",
                                                       "rd_model_notes.py", "rd_thesis_draft.docx"]
    assert (cache / ".build-notes" / "keep.txt").read_text() == "mine"
    assert clear_cache() == (0, 0)


def test_cli_cache_info_before_the_cache_exists(cache: Path, capsys) -> None:
    assert main(["cache", "info"]) == 0
    assert f"location  {cache} (not created yet)" in capsys.readouterr().out
    assert not cache.exists()  # info creates nothing


def test_default_cache_folder_left_open_is_closed_but_a_chosen_one_is_not(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("ROBODYN_CACHE", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    old = tmp_path / "robodyn"
    old.mkdir(mode=0o755)
    os.chmod(old, 0o755)  # as an older robodyn created it
    assert build.cache_dir() == old
    assert stat.S_IMODE(old.stat().st_mode) == 0o700
    chosen = tmp_path / "shared"
    chosen.mkdir()
    os.chmod(chosen, 0o755)
    monkeypatch.setenv("ROBODYN_CACHE", str(chosen))
    assert build.cache_dir() == chosen
    assert stat.S_IMODE(chosen.stat().st_mode) == 0o755  # the user's folder: left as it is


@pytest.mark.tool("cc")
@pytest.mark.parametrize("backend", ["c", "numpy"])
def test_corrupted_cached_sources_are_generated_again(cache: Path, backend) -> None:
    # issue 23: a truncated cached .c/.py made every later run fail instead of being rebuilt
    import numpy as np

    import robodyn as rd

    robot = rd.load("planar_2r")
    first = rd.compile_model(robot, backend=backend)
    q = np.array([0.3, -0.4])
    expected = first.inverse_dynamics(q, q, q)
    suffix = ".c" if backend == "c" else ".py"
    (src,) = [p for p in cache.glob(f"rd_model_*{suffix}")]
    src.write_text(src.read_text()[: len(src.read_text()) // 3])  # truncated mid-function
    if backend == "numpy":
        sys.modules.pop(f"robodyn_generated_{src.stem.removeprefix('rd_model_')}", None)
    again = rd.compile_model(robot, backend=backend)
    np.testing.assert_array_equal(again.inverse_dynamics(q, q, q), expected)
    assert len(src.read_text()) > 3 * 100  # written whole again


@pytest.mark.tool("cc")
def test_cached_library_loads_without_a_compiler(cache: Path, monkeypatch) -> None:
    # issue 24: a worker with the compiled model in its cache but no toolchain failed every case
    # because the compiler was looked up before the cache
    import numpy as np

    import robodyn as rd

    lib = compile_library(source(40), DECL)
    robot = rd.load("planar_2r")
    q = np.array([0.2, 0.7])
    expected = rd.compile_model(robot).inverse_dynamics(q, q, q)
    from robodyn.numeric.model import openmp_flags

    monkeypatch.setenv("PATH", str(cache / "no-tools"))
    monkeypatch.setenv("CC", "")
    openmp_flags.cache_clear()  # as in a fresh worker process: no compiler to probe OpenMP with
    try:
        with pytest.raises(build.CompilerNotFoundError):
            build.find_compiler()
        again = compile_library(source(40), DECL)
        assert again.path == lib.path and again.lib.rd_test_twice(4.0) == lib.lib.rd_test_twice(4.0)
        np.testing.assert_array_equal(rd.compile_model(robot).inverse_dynamics(q, q, q), expected)
        with pytest.raises(build.CompilerNotFoundError):
            compile_library(source(41), DECL)  # never built: a compiler is still needed
    finally:
        monkeypatch.undo()
        openmp_flags.cache_clear()


@pytest.mark.parametrize("content", ["x = 1\n", "", "import numpy\nDOF = 2\n"])
def test_cached_module_that_imports_but_is_not_the_generated_one_is_generated_again(
        cache: Path, content: str) -> None:
    # probe 23: a cached rd_model_*.py overwritten with valid Python (or emptied) imported fine
    # and every later run failed with "has no attribute 'state_derivative'"
    import numpy as np

    import robodyn as rd

    robot = rd.load("planar_2r")
    q = np.array([0.3, -0.4])
    expected = rd.compile_model(robot, backend="numpy").inverse_dynamics(q, q, q)
    (src,) = cache.glob("rd_model_*.py")
    good = src.read_bytes()
    assert good.splitlines()[-1].startswith(b"# robodyn-sha256: ")
    src.write_text(content)
    sys.modules.pop(f"robodyn_generated_{src.stem.removeprefix('rd_model_')}", None)
    again = rd.compile_model(robot, backend="numpy")
    np.testing.assert_array_equal(again.inverse_dynamics(q, q, q), expected)
    assert src.read_bytes() == good  # generated again, whole


@pytest.mark.tool("cc")
@pytest.mark.parametrize("entry", ["../../etc/passwd", "/etc/passwd", "sub/rd_0123456789abcdef01234567.so",
                                   "rd_0123456789abcdef01234567.c", "\udcff"])
def test_index_naming_anything_but_an_own_library_is_ignored(
        cache: Path, monkeypatch: pytest.MonkeyPatch, entry: str) -> None:
    # probe 23: a path in the .src index stopped every run with "ValueError: Invalid name"
    lib = compile_library(source(50), DECL)
    (index,) = cache.glob("rd_*.src")
    index.write_bytes(entry.encode("utf-8", "surrogateescape") + b"\n")
    assert build._indexed(index) is None
    again = compile_library(source(50), DECL)  # with a compiler: the index is rewritten
    assert again.path == lib.path and again.lib.rd_test_twice(1.0) == 2.0 + 50
    assert index.read_text() == lib.path.name + "\n"
    index.write_bytes(entry.encode("utf-8", "surrogateescape") + b"\n")
    monkeypatch.setenv("PATH", str(cache / "no-tools"))
    monkeypatch.setenv("CC", "")
    with pytest.raises(build.CompilerNotFoundError):  # without one: as for a source never built
        compile_library(source(50), DECL)
