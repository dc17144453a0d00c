"""Identification Monte Carlo and underwater effects as study tasks: serial runs checked against
the truth and against physics, one small Dask sweep equal to the serial table."""

from __future__ import annotations

import importlib
import logging

import numpy as np
import pytest

from robodyn.robot.errors import StudyError
from robodyn.studies import IdentificationMonteCarlo, UnderwaterEffects, run_serial, sweep


@pytest.mark.slow
def test_identification_error_grows_with_noise_and_vanishes_without():
    task = IdentificationMonteCarlo()
    cases = [{"torque_noise": s, "seed": k} for s in (0.0, 0.05, 0.5) for k in (1, 2)]
    table = run_serial(task, cases, seed=None)
    assert table["error"].isna().all()
    err = table.groupby("torque_noise")["inertial_error"].mean()
    # noise-free: only the lab's discretisation (1 kHz logger, velocities from positions) is left
    assert err[0.0] < 1e-3
    assert table.loc[table["torque_noise"] == 0.0, "heldout_rel"].max() < 2e-3
    # ten times the noise, about ten times the parameter error (least squares: linear in sigma)
    assert err[0.0] < err[0.05] < err[0.5]
    assert 3.0 < err[0.5] / err[0.05] < 30.0
    assert np.all(table["condition"] > 1.0) and np.all(np.isfinite(table["condition"]))
    # seeded: the same case gives the same numbers
    assert task({"torque_noise": 0.05, "seed": 1}) == task({"torque_noise": 0.05, "seed": 1})


def test_identification_task_refuses_bad_cases():
    task = IdentificationMonteCarlo()
    with pytest.raises(StudyError, match="unknown parameter 'noise' for identification Monte Carlo"):
        task({"noise": 0.1, "seed": 1})
    with pytest.raises(StudyError, match="needs a 'seed'"):
        task({"torque_noise": 0.1})
    with pytest.raises(StudyError, match="excitation: expected one of optimal, jointwise"):
        task({"excitation": "chirp", "seed": 1})


def test_higher_drag_damps_the_free_swing_and_costs_torque():
    task = UnderwaterEffects()
    table = run_serial(task, [{"Cd": 0.5}, {"Cd": 4.0}], seed=None)
    assert table["error"].isna().all()
    low, high = table.loc[0], table.loc[1]
    for joint in ("q1", "q2"):
        assert high[f"free_amplitude.{joint}"] < low[f"free_amplitude.{joint}"]
        assert high[f"rms_tau.{joint}"] > low[f"rms_tau.{joint}"]
        assert high[f"peak_tau.{joint}"] >= high[f"rms_tau.{joint}"] > 0
    with pytest.raises(StudyError, match="unknown parameter 'drag' for the underwater effects"):
        task({"drag": 1.0})
    with pytest.raises(StudyError, match="effect: expected one of"):
        UnderwaterEffects(effect="sonar")


@pytest.mark.slow
def test_dask_sweep_equals_the_serial_table():
    from distributed import Client, LocalCluster

    task = IdentificationMonteCarlo()
    grid = {"torque_noise": [0.0, 0.2]}
    serial = run_serial(task, grid, seed=7)
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                      dashboard_address=None, silence_logs=logging.ERROR) as cluster, \
            Client(cluster, set_as_default=False) as client:
        client.run(importlib.import_module, "robodyn.studies.identification_mc")
        table = sweep(task, grid, client=client, batch=1, seed=7)
    assert len(table) == 2
    assert table.equals(serial)
