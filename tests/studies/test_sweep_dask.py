"""``sweep`` on a real Dask cluster (two worker processes on 127.0.0.1): exact agreement with a
serial loop, recorded failures, a worker killed mid-study, interruption, bad tasks and addresses."""

from __future__ import annotations

import importlib
import logging
import os
import signal

import numpy as np
import pytest

from robodyn.robot.errors import StudyError
from robodyn.studies import SweepInterrupted, expand_cases, run_serial, sweep
from robodyn.studies.models import RobotSource
from robodyn.studies.sizing import ActuatorSizing
from tests.studies.tasks import noisy_square, slow_square


@pytest.fixture(scope="module")
def client():
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                      dashboard_address=None, silence_logs=logging.ERROR) as cluster, \
            Client(cluster, set_as_default=False) as c:
        # import robodyn on the workers once, here, not inside the first test (seconds per process)
        c.run(importlib.import_module, "robodyn.studies.sizing")
        yield c


def _sizing_task() -> ActuatorSizing:
    # the AA300's slide lifts 0.3 m while the column turns 0.5 rad
    return ActuatorSizing(RobotSource.of("aa300"), trajectory="trapezoid", q_start=(0.0, 0.6, 1.0),
                          q_goal=(0.5, 0.9, 1.0), vmax=(1.0, 0.5, 1.5), amax=(2.0, 2.0, 4.0),
                          dt=5e-3, settle=0.2)


@pytest.mark.slow
def test_sizing_sweep_equals_a_serial_loop_exactly(client):
    task = _sizing_task()
    grid = {"payload": [0.0, 50.0], "bandwidth_hz": [3.0, 5.0], "gravity_compensation": [True, False]}
    table = sweep(task, grid, client=client, batch=3)
    cases = expand_cases(grid)
    assert len(table) == 8 and table["error"].isna().all()
    for i, case in enumerate(cases):  # the plain loop, in this process
        expected = task(case)
        row = table.loc[i]
        assert {k: row[k] for k in case} == case
        assert {k: row[k] for k in expected} == expected  # bit for bit
    # the slide's ideal peak force is the carried mass times (g + the move's acceleration):
    # the slide is dynamically decoupled from both rotations (docs/aa300.md)
    carried = 201.4534 + 118.9522 + 65.1572 + table["payload"].to_numpy()
    # synchronised trapezoid: the path parameter accelerates at min(amax_i / |dq_i|) = min(2/0.5, 2/0.3)
    slide_accel = min(2.0 / 0.5, 2.0 / 0.3) * 0.3  # 1.2 m/s^2 upwards
    np.testing.assert_allclose(table["peak_ideal_torque.upper_arm"], carried * (9.81 + slide_accel),
                               rtol=1e-9)


def test_results_do_not_depend_on_batch_size_or_workers(client):
    cases = {"x": [0, 1, 2, 4, 5, 6, 7], "k": [0, 1]}
    serial = run_serial(noisy_square, cases, seed=11)
    for batch in (1, 5, 14):
        assert sweep(noisy_square, cases, client=client, batch=batch, seed=11).equals(serial)


def test_failing_case_is_recorded_and_the_others_complete(client):
    table = sweep(noisy_square, {"x": [1, 2, 3, 4]}, client=client, batch=1)
    assert table.loc[2, "error"] == "ValueError: x = 3 is not allowed here"
    assert list(table["y"].drop(2)) == [1.0, 4.0, 16.0] and table["error"].drop(2).isna().all()
    with pytest.raises(ValueError, match="x = 3 is not allowed"):
        sweep(noisy_square, {"x": [1, 2, 3, 4]}, client=client, batch=1, on_error="raise")


def test_interrupted_sweep_keeps_the_finished_cases(client):
    seen = []

    def stop_after_two(rows):
        seen.append(rows)
        if len(seen) == 2:
            raise KeyboardInterrupt

    cases = {"x": list(range(4, 40))}
    with pytest.raises(SweepInterrupted) as info:
        sweep(slow_square, cases, client=client, batch=3, on_batch=stop_after_two)
    partial = info.value.table
    finished = sorted(i for rows in seen for i, _, _ in rows)
    assert list(partial.index) == finished and len(finished) == 6
    serial = run_serial(noisy_square, cases)
    cols = ["x", "seed", "y", "noise", "pair[0]", "pair[1]"]
    assert partial[cols].equals(serial.loc[finished, cols])


def test_non_picklable_task_is_named():
    import threading

    class Holder:
        def __init__(self):
            self.lock = threading.Lock()

        def __call__(self, case):
            return {}

    with pytest.raises(StudyError, match=r"task 'test_non_picklable_task_is_named.<locals>.Holder' cannot "
                                         r"be sent to Dask workers: it does not pickle"):
        sweep(Holder(), [{"x": 1}], scheduler="tcp://127.0.0.1:9")


def test_unreachable_scheduler_is_a_clear_error_after_the_timeout():
    message = r"cannot reach the Dask scheduler at 'tcp://127.0.0.1:9' within 1 s"
    with pytest.raises(StudyError, match=message):
        sweep(noisy_square, [{"x": 1}], scheduler="tcp://127.0.0.1:9", timeout=1.0)


def test_killing_a_worker_mid_study_still_completes(client):
    pids = client.run(os.getpid)
    victim = sorted(pids.values())[0]
    killed = []

    def kill_once(rows):
        if not killed:
            os.kill(victim, signal.SIGKILL)
            killed.append(victim)

    cases = {"x": [0, 1, 2, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16]}
    table = sweep(slow_square, cases, client=client, batch=2, seed=3, on_batch=kill_once)
    assert killed == [victim]
    with pytest.raises(ProcessLookupError):
        os.kill(victim, 0)  # really gone
    assert list(table.index) == list(range(16)) and table["error"].isna().all()
    serial = run_serial(noisy_square, cases, seed=3)
    assert table.drop(columns="pid").equals(serial)


@pytest.mark.slow
@pytest.mark.parametrize("threads, batch", [(1, 4), (2, 1)])
def test_case_that_kills_its_worker_is_recorded_and_the_sweep_goes_on(threads, batch):
    # issue 24: a case crashing its worker every time aborted the whole sweep (KilledWorker) and
    # returned no table. The cases of a task whose worker died on every try run again one at a
    # time, alone; only the crashing one fails. With 2 threads (or a second task queued on the
    # worker) other cases die beside it, some on every try: they must not be recorded as failed.
    import dask
    from distributed import Client, LocalCluster

    from tests.studies.tasks import crashing_square

    # a cluster whose nanny cannot restart the worker (seen once under load) fails the tasks
    # after a minute instead of leaving the sweep waiting for ever
    with dask.config.set({"distributed.scheduler.allowed-failures": 1,
                          "distributed.scheduler.no-workers-timeout": "60s"}), \
            LocalCluster(n_workers=1, threads_per_worker=threads, processes=True, host="127.0.0.1",
                         dashboard_address=None, silence_logs=logging.CRITICAL) as cluster, \
            Client(cluster, set_as_default=False) as one:
        frame = sweep(crashing_square, {"x": list(range(10))}, client=one, batch=batch, seed=None)
    assert list(frame.index) == list(range(10))
    assert frame["error"].notna().tolist() == [x == 5 for x in range(10)]
    assert "the worker running this case died 2 times" in frame.loc[5, "error"]
    ok = frame.drop(index=5)
    assert (ok["y"] == ok.index.to_numpy(float) ** 2).all()


@pytest.mark.slow
def test_own_cluster_leaves_nothing_in_the_temporary_folder(tmp_path, monkeypatch):
    # issue 23: the cluster a sweep starts kept Dask's dask-scratch-space (lock files) in the
    # system's temporary folder after it closed
    import tempfile

    monkeypatch.setenv("TMPDIR", str(tmp_path))
    monkeypatch.setattr(tempfile, "tempdir", None)
    table = sweep(noisy_square, {"x": [1, 2]}, workers=1, seed=0)
    assert list(table["y"]) == [1.0, 4.0]
    assert sorted(p.name for p in tmp_path.iterdir()) == []


def test_a_cluster_without_workers_stops_the_sweep_with_a_clear_error():
    # issue 23: a sweep on a cluster that has lost every worker waited for ever
    import dask
    from distributed import Client, LocalCluster

    with dask.config.set({"distributed.scheduler.no-workers-timeout": "1s"}), \
            LocalCluster(n_workers=0, processes=True, host="127.0.0.1", dashboard_address=None,
                         silence_logs=logging.CRITICAL) as cluster, \
            Client(cluster, set_as_default=False) as empty:
        with pytest.raises(StudyError, match="the cluster had no worker for its tasks"):
            sweep(noisy_square, {"x": [1, 2]}, client=empty, seed=0)


def test_the_sweeps_own_cluster_has_a_no_worker_timeout():
    from robodyn.studies.sweeps import NO_WORKER_TIMEOUT, local_cluster

    with local_cluster(1) as cluster:
        assert cluster.scheduler.no_workers_timeout == NO_WORKER_TIMEOUT
