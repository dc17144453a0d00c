"""Sweeps on clusters that grow after submission, and compiled models shipped to workers that
have neither a compiler nor the models in their caches (issue 24). Loopback only."""

from __future__ import annotations

import logging
import os
import subprocess
import sys
import threading
import time
import uuid
from pathlib import Path

import pytest

from robodyn.codegen.build import _cpu_id
from robodyn.studies import run_serial, sweep
from robodyn.studies.models import ModelSpec, RobotSource
from robodyn.studies.shipping import ModelBundle, bundle_models, models_to_ship
from robodyn.studies.sizing import ActuatorSizing
from robodyn.studies.sweeps import MIN_BATCHES, default_batch
from tests.studies.tasks import GatedSquare, has_compiler, noisy_square

ROOT = Path(__file__).resolve().parents[2]


def _planar_sizing() -> ActuatorSizing:
    return ActuatorSizing(RobotSource.of("planar_2r"), trajectory="trapezoid", q_start=(0.0, 0.0),
                          q_goal=(0.5, -0.3), vmax=(1.0, 1.0), amax=(2.0, 2.0), dt=5e-3, settle=0.1)


def test_default_batching_does_not_depend_on_workers_at_submission():
    # the old default, ceil(n / (4 * max(1, threads))), made 4 batches on an empty cluster
    assert default_batch(10_000, 0) == default_batch(10_000, 2) == 40  # 250 tasks
    assert default_batch(40, 0) == 1
    assert default_batch(10_000, 1000) == 3  # 4 tasks per thread on a big cluster
    assert MIN_BATCHES >= 64


def _scheduler_tasks(dask_scheduler=None) -> int:
    return len(dask_scheduler.tasks)


@pytest.mark.parametrize("grow", ["scale", "adapt"])
def test_workers_that_join_after_submission_get_batches(grow):
    # issue 24: with no worker at submission the sweep made 4 batches, so at most 4 workers
    # ever worked. Every batch here waits for a gate that opens once 6 workers have joined, so
    # each of them holds one before any finishes.
    from distributed import Client, Event, LocalCluster

    cases = {"x": list(range(40))}
    gate = f"robodyn-test-gate-{uuid.uuid4().hex}"
    found: dict = {}
    with LocalCluster(n_workers=0, threads_per_worker=1, processes=False, protocol="tcp://",
                      host="127.0.0.1", dashboard_address=None, silence_logs=logging.ERROR) as cluster, \
            Client(cluster, set_as_default=False) as client:
        run = threading.Thread(target=lambda: found.update(
            table=sweep(GatedSquare(gate), cases, client=client, seed=5)))
        run.start()
        try:
            deadline = time.monotonic() + 30
            while client.run_on_scheduler(_scheduler_tasks) < 40 and time.monotonic() < deadline:
                time.sleep(0.05)
            assert client.nthreads() == {}  # submitted to a cluster without workers
            if grow == "scale":
                cluster.scale(6)
            else:  # 40 queued tasks of unknown duration (0.5 s each) ask for 20 workers
                cluster.adapt(minimum=0, maximum=6, interval="100ms", target_duration="1s")
            client.wait_for_workers(6, timeout=60)
        finally:
            Event(gate, client=client).set()
            run.join(timeout=120)
    table = found["table"]
    assert table.drop(columns="worker").equals(run_serial(noisy_square, cases, seed=5))
    assert table["worker"].dropna().nunique() == 6


@pytest.mark.slow
@pytest.mark.tool("gcc|cc")  # here, to build the models shipped
def test_workers_without_compiler_or_cache_get_the_compiled_models(tmp_path):
    # issue 24: compiled models were never shipped, so every worker needed the toolchain.
    # Two `dask worker` processes, each with its own empty cache and no compiler on PATH or in $CC,
    # that join the cluster after the sweep was submitted (the plugin reaches late joiners too).
    from distributed import Client, LocalCluster

    task = _planar_sizing()
    grid = {"payload": [0.0, 0.5], "bandwidth_hz": [1.0, 2.0, 3.0]}
    empty = tmp_path / "bin"
    empty.mkdir()
    caches = [tmp_path / f"cache{k}" for k in range(2)]
    found: dict = {}
    with LocalCluster(n_workers=0, processes=False, protocol="tcp://", host="127.0.0.1",
                      dashboard_address=None, silence_logs=logging.ERROR) as cluster, \
            Client(cluster, set_as_default=False) as client:
        run = threading.Thread(target=lambda: found.update(
            table=sweep(task, grid, client=client, seed=None, batch=1)))
        run.start()
        deadline = time.monotonic() + 60
        while client.run_on_scheduler(_scheduler_tasks) < 6 and time.monotonic() < deadline:
            time.sleep(0.05)
        assert client.nthreads() == {}  # submitted before any worker exists
        workers = [subprocess.Popen(
            [sys.executable, "-m", "distributed.cli.dask_worker", cluster.scheduler_address,
             "--nthreads", "1", "--no-nanny", "--no-dashboard", "--name", f"bare-{k}"],
            cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
            env={**os.environ, "ROBODYN_CACHE": str(cache), "PATH": str(empty),
                 "CC": str(tmp_path / "no-such-cc")}) for k, cache in enumerate(caches)]
        try:
            client.wait_for_workers(2, timeout=60)
            assert list(client.run(has_compiler).values()) == [False, False]
            run.join(timeout=240)
        finally:
            for proc in workers:
                proc.terminate()
            for proc in workers:
                proc.wait(timeout=30)
    table = found["table"]
    assert table["error"].isna().all() and len(table) == 6  # without the models: "no C compiler"
    assert table.equals(run_serial(task, grid, seed=None))  # bit for bit
    used = [c for c in caches if c.is_dir()]
    assert used and all(len(list(c.glob("rd_*.so"))) == 2 for c in used)  # one per payload


@pytest.mark.tool("gcc|cc")
def test_bundle_writes_what_a_cache_lacks_and_nothing_else(tmp_path):
    task = _planar_sizing()
    bundle = models_to_ship(task, [{"payload": 0.0}, {"payload": 0.0, "zeta": 0.8}], None)
    assert bundle is not None
    names = sorted(name for name, _ in bundle.files)
    suffixes = sorted(n.split(".", 1)[1] for n in names)
    assert suffixes == ["c", "cdef", "so", "so.sha256", "src"]  # one model, all its files
    assert sorted(bundle.install(tmp_path)) == names
    assert bundle.install(tmp_path) == []  # already there
    (tmp_path / names[0]).write_bytes(b"truncated")
    assert bundle.install(tmp_path) == [names[0]]
    # another kind of processor: only the generated sources (-march=native libraries would not run)
    elsewhere = ModelBundle("model name : another cpu", bundle.files)
    (tmp_path / "other").mkdir()
    assert sorted(elsewhere.install(tmp_path / "other")) == [n for n in names if n.endswith((".c", ".cdef"))]
    assert bundle.cpu == _cpu_id()


@pytest.mark.tool("gcc|cc")
def test_bundle_limits_and_refusals():
    task = _planar_sizing()
    many = [{"payload": 0.1 * k} for k in range(20)]
    assert models_to_ship(task, many, None) is None  # over SHIP_LIMIT: workers build their own
    assert models_to_ship(task, many[:1], False) is None
    assert models_to_ship(noisy_square, many, True) is None  # lists no models
    with pytest.raises(ValueError, match="not a robodyn cache file name"):
        ModelBundle("cpu", (("../../.bashrc", b""),))
    assert bundle_models([]).files == ()
    assert ModelSpec(RobotSource.of("planar_2r")).model().backend == "c"


_UNDERWATER_WORKER = """
import json, pickle, sys
from robodyn.studies.shipping import install_once
from robodyn.studies.underwater_task import UnderwaterEffects
from tests.studies.tasks import has_compiler

assert not has_compiler()
install_once(pickle.loads(open(sys.argv[1], "rb").read()))
task = UnderwaterEffects(move_time=0.2, hold_time=0.1, free_time=0.2, dt=5e-3)
print(json.dumps([task(c) for c in json.loads(sys.argv[2])]))
"""


@pytest.mark.slow
@pytest.mark.tool("gcc|cc")
def test_underwater_task_ships_the_models_it_uses(tmp_path):
    # issue 24: UnderwaterEffects listed no models, so its workers needed a compiler. A process
    # with an empty cache and no compiler runs its cases from the shipped bundle alone.
    import json
    import pickle

    from robodyn.studies.underwater_task import UnderwaterEffects

    task = UnderwaterEffects(move_time=0.2, hold_time=0.1, free_time=0.2, dt=5e-3)
    cases = [{"Cd": 1.0}, {"Cd": 1.4, "vc": 0.3}, {"Cd": 1.0, "seed": 3}, {"nonsense": 1.0}]
    specs = task.compiled_models(cases)
    assert [s.effect for s in specs] == ["dry", "current"] * 2  # the refused case lists nothing
    bundle = models_to_ship(task, cases, None)
    assert bundle is not None and len([n for n, _ in bundle.files if n.endswith(".so")]) == 4
    (tmp_path / "bundle.pkl").write_bytes(pickle.dumps(bundle))
    empty = tmp_path / "bin"
    empty.mkdir()
    run = subprocess.run(
        [sys.executable, "-c", _UNDERWATER_WORKER, str(tmp_path / "bundle.pkl"), json.dumps(cases[:3])],
        cwd=ROOT, capture_output=True, text=True, timeout=300,
        env={**os.environ, "ROBODYN_CACHE": str(tmp_path / "cache"), "PATH": str(empty),
             "CC": str(tmp_path / "no-such-cc")})
    assert run.returncode == 0, run.stderr[-2000:]
    assert json.loads(run.stdout) == [task(c) for c in cases[:3]]  # bit for bit (JSON floats: repr)
