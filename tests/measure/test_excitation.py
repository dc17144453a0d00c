"""Excitation design: rest-to-rest Fourier series, base columns, limits, optimality vs random designs."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from robodyn.measure.csv_io import read_csv
from robodyn.studies.excitation import (
    ExcitationLimits,
    FourierTrajectory,
    base_columns,
    condition_number,
    excitation,
    excitation_limits,
    random_fourier,
)
from robodyn.symbolic.regressor import parameter_names


@pytest.fixture(scope="module")
def puma_design(puma):
    """The issue's target case: PUMA 560, 6 joints, 5 harmonics, default limits and starts."""
    return excitation(puma, harmonics=5, seed=0)


def test_fourier_series_derivatives_and_rest(planar):
    """qd, qdd of the series are the time derivatives of q (central differences), and the motion is
    at rest at the offset at t = 0 and after each period."""
    lim = excitation_limits(planar.robot)
    traj = random_fourier(lim, 5, 0.2, np.random.default_rng(3))
    t = np.linspace(0.3, 4.7, 41)
    h = 1e-5
    q, qd, qdd = traj.evaluate(t)
    qp, qdp, _ = traj.evaluate(t + h)
    qm, qdm, _ = traj.evaluate(t - h)
    assert np.allclose((qp - qm) / (2 * h), qd, atol=1e-8)
    assert np.allclose((qdp - qdm) / (2 * h), qdd, atol=1e-8)
    ends = np.array([0.0, traj.period, 2 * traj.period])
    q_e, qd_e, qdd_e = traj.evaluate(ends)
    assert np.allclose(q_e, traj.offset, atol=1e-14)
    assert np.allclose(qd_e, 0.0, atol=1e-13) and np.allclose(qdd_e, 0.0, atol=1e-13)
    # not trivially at rest: it does move
    assert np.max(np.abs(q - traj.offset)) > 0.1


def test_base_columns_planar_2r_closed_form(planar):
    """Planar 2R in a vertical plane (Khalil & Dombre): base inertial parameters ZZ1R, MX1R, MY1,
    ZZ2, MX2, MY2, rotor inertia Ia2 (Ia1 merges into ZZ1R), and per joint Fv, Fc+, Fc- (the
    offset equals Fc+ - Fc- wherever qd != 0): 13 columns."""
    cols = base_columns(planar, 0)
    names = [parameter_names(2)[c] for c in cols]
    assert len(cols) == 13, names
    for name in ("MY1", "MX2", "MY2", "Ia2", "Fv1", "Fv2"):
        assert name in names
    # another seed may pick another two of Fc+, Fc-, Fo, but never a different number
    assert len(base_columns(planar, 7)) == 13


@pytest.mark.slow
def test_puma_design_meets_target_and_limits(puma, puma_design):
    ex = puma_design
    print(f"PUMA 560 excitation: cond = {ex.condition_number:.1f} (starts {np.round(ex.history, 1)}), "
          f"{len(ex.columns)} base columns")
    assert ex.condition_number < 100.0
    assert ex.q.shape == (ex.t.size, 6) and ex.qd.shape == ex.q.shape == ex.qdd.shape
    lim = ex.limits
    # every returned sample respects every limit
    assert np.all(ex.q <= lim.upper) and np.all(ex.q >= lim.lower)
    assert np.all(np.abs(ex.qd) <= lim.velocity) and np.all(np.abs(ex.qdd) <= lim.acceleration)
    # and so does the continuous motion, on a 10x finer grid of the series
    q, qd, qdd = ex.at(np.linspace(0.0, ex.duration, 10 * ex.t.size))
    assert lim.violation(q, qd, qdd) <= 0.0
    # default limits come from the PUMA's joint limits (5 % margin)
    lower = np.array([float(j.lower) for j in puma.robot.joints])
    assert np.all(lim.lower > lower)
    # rest to rest at the offset
    a, b, off = ex.coefficients
    for arr, ref in ((ex.q, off), (ex.qd, 0.0), (ex.qdd, 0.0)):
        assert np.allclose(arr[0], ref, atol=1e-15) and np.allclose(arr[-1], ref, atol=1e-15)
    # the reported condition number is that of the returned trajectory
    t = np.arange(ex.design_samples) * ex.series.period / ex.design_samples
    w = puma.regressor(*ex.at(t)).reshape(-1, 90)[:, list(ex.columns)]
    s = np.linalg.svd(w, compute_uv=False)
    assert s[0] / s[-1] == pytest.approx(ex.condition_number, rel=1e-6)


@pytest.mark.slow
def test_puma_design_beats_best_of_100_random(puma, puma_design):
    ex = puma_design
    rng = np.random.default_rng(2024)
    t = np.arange(ex.design_samples) * ex.series.period / ex.design_samples
    conds = []
    for _ in range(100):
        traj = random_fourier(ex.limits, 5, ex.series.base_frequency, rng)
        q, qd, qdd = traj.evaluate(t)
        assert ex.limits.violation(q, qd, qdd) <= 1e-9
        conds.append(condition_number(puma, q, qd, qdd, ex.columns))
    print(f"optimised {ex.condition_number:.1f} vs best of 100 random {min(conds):.1f} "
          f"(median {np.median(conds):.0f})")
    assert ex.condition_number < min(conds)


def test_csv_round_trip(tmp_path, planar):
    ex = excitation(planar, harmonics=3, base_frequency=0.5, duration=4.0, starts=1, max_iterations=10,
                    dt=0.01)
    path = ex.to_csv(tmp_path / "traj.csv")
    df = pd.read_csv(path)
    assert list(df.columns) == ["t", "q[q1]", "q[q2]", "qd[q1]", "qd[q2]", "qdd[q1]", "qdd[q2]"]
    assert len(df) == ex.t.size == 401
    assert np.array_equal(df["t"].to_numpy(), ex.t)
    assert np.array_equal(df[["q[q1]", "q[q2]"]].to_numpy(), ex.q)
    assert np.array_equal(df[["qdd[q1]", "qdd[q2]"]].to_numpy(), ex.qdd)
    # the recording layout: it reads back as a recording with the same numbers
    rec = read_csv(path)
    assert rec.joint_names == ("q1", "q2") and np.array_equal(rec.qd, ex.qd)


def test_joint_trajectory_matches_series(planar):
    ex = excitation(planar, harmonics=4, base_frequency=0.5, starts=1, max_iterations=10)
    jt = ex.trajectory()
    t = np.array([0.0, 0.123, 0.777, 1.5, 1.999])
    for got, want in zip(jt.at(t), ex.at(t), strict=True):
        assert np.allclose(got, want, atol=1e-9)


def test_logdet_criterion_improves_on_its_start(planar):
    lim = excitation_limits(planar.robot)
    rng = np.random.default_rng(0)
    cols = base_columns(planar, rng)
    start = random_fourier(lim, 4, 0.5, rng, samples=80)
    t = np.arange(80) * 2.0 / 80
    w = planar.regressor(*start.evaluate(t)).reshape(-1, 30)[:, list(cols)]
    logdet0 = np.linalg.slogdet(w.T @ w / 80)[1]
    ex = excitation(planar, harmonics=4, base_frequency=0.5, criterion="logdet", starts=1, seed=0,
                    max_iterations=30)
    assert ex.logdet > logdet0 + 1.0
    assert ex.limits.violation(ex.q, ex.qd, ex.qdd) <= 0


def test_explicit_limits_respected(planar):
    lim = excitation_limits(planar.robot, lower=[-0.5, 0.2], upper=[0.5, 1.0], velocity=[0.3, 0.4],
                            acceleration=0.5)
    ex = excitation(planar, harmonics=3, base_frequency=0.25, limits=lim, starts=2, max_iterations=15)
    assert ex.limits is lim
    assert np.all(ex.q >= [-0.5, 0.2]) and np.all(ex.q <= [0.5, 1.0])
    assert np.all(np.abs(ex.qd) <= [0.3, 0.4]) and np.all(np.abs(ex.qdd) <= 0.5)
    # the design uses the room it has: some limit is (nearly) reached
    assert lim.violation(ex.q, ex.qd, ex.qdd) > -0.05


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"harmonics": 2}, "harmonics must be an integer >= 3"),
    ({"base_frequency": 0.0}, "base_frequency must be a number of Hz in"),
    ({"base_frequency": 0.5, "duration": 3.0}, "whole number of periods"),
    ({"criterion": "trace"}, "unknown criterion 'trace'"),
    ({"starts": 0}, "starts must be >= 1"),
])
def test_bad_arguments(planar, kwargs, message):
    with pytest.raises(ValueError, match=message):
        excitation(planar, **kwargs)


def test_bad_limits(planar):
    with pytest.raises(ValueError, match="limits are for 3 joints, the robot has 2"):
        excitation(planar, limits=ExcitationLimits(*(np.ones(3) * s for s in (-1, 1, 1, 1))))
    with pytest.raises(ValueError, match="joint 'q2': upper limit -1 is not above lower limit 1"):
        excitation_limits(planar.robot, lower=[0, 1], upper=[1, -1])
    with pytest.raises(ValueError, match="velocity must be positive"):
        excitation_limits(planar.robot, velocity=[1.0, -2.0])


def test_inputs_not_modified(planar):
    lim = excitation_limits(planar.robot)
    before = [a.copy() for a in (lim.lower, lim.upper, lim.velocity, lim.acceleration)]
    excitation(planar, harmonics=3, base_frequency=0.5, limits=lim, starts=1, max_iterations=5)
    for a, b in zip(before, (lim.lower, lim.upper, lim.velocity, lim.acceleration), strict=True):
        assert np.array_equal(a, b)
    assert isinstance(random_fourier(lim, 3, 0.5, np.random.default_rng(0)), FourierTrajectory)
