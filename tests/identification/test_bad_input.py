"""Bad input to rd.identify: each rejected with a message naming the recording, field and reason."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

import robodyn as rd
from robodyn.robot.errors import IdentificationError
from tests.identification.helpers import load_quiet, simulated


@pytest.fixture(scope="module")
def arm():
    robot = load_quiet("planar_2r")
    return robot, rd.compile_model(robot)


def test_joints_not_matching_the_robot(arm):
    robot, model = arm
    rec, _ = simulated(model, seconds=2.0)
    other = rd.Recording(t=rec.t, q=rec.q, qd=rec.qd, qdd=rec.qdd, tau=rec.tau,
                         joint_names=("shoulder", "q2"), source="lab.csv")
    with pytest.raises(IdentificationError, match=r"lab.csv: joint_names do not match robot "
                                                  r"'planar_2r': missing \['q1'\], unknown \['shoulder'\]"):
        rd.identify(robot, other, cutoff=None, model=model)
    swapped = SimpleNamespace(t=rec.t, q=rec.q, qd=rec.qd, qdd=rec.qdd, tau=rec.tau,
                              joint_names=("q2", "q1"), source="swap.csv")
    with pytest.raises(IdentificationError, match=r"swap.csv: joint_names .* order"):
        rd.identify(robot, swapped, cutoff=None, model=model)
    narrow = rd.Recording(t=rec.t, q=rec.q[:, :1], tau=rec.tau[:, :1], source="one.csv")
    with pytest.raises(IdentificationError, match=r"one.csv: q: expected shape \(N, 2\)"):
        rd.identify(robot, narrow, cutoff=None, model=model)


def test_too_few_samples(arm):
    robot, model = arm
    rec, _ = simulated(model, seconds=0.05, dt=0.01)  # 5 samples x 2 joints for 13 parameters
    with pytest.raises(IdentificationError, match=r"too few samples for the parameters: 5 samples x 2 "
                                                  r"joints = 10 equations .* 13 base parameters"):
        rd.identify(robot, rec, cutoff=None, model=model)


def test_nan_named_with_row_and_column(arm):
    robot, model = arm
    rec, _ = simulated(model, seconds=2.0)
    tau = rec.tau.copy()
    tau[17, 1] = np.nan
    bad = SimpleNamespace(t=rec.t, q=rec.q, qd=rec.qd, qdd=rec.qdd, tau=tau, joint_names=None,
                          source="run7.csv")
    with pytest.raises(IdentificationError, match=r"run7.csv: tau: value nan is not finite at row 17, "
                                                  r"column 1 \(q2\)"):
        rd.identify(robot, bad, cutoff=None, model=model)
    assert np.isnan(tau[17, 1]) and np.isfinite(rec.tau).all()  # inputs untouched


def test_missing_target_and_unknown_options(arm):
    robot, model = arm
    rec, _ = simulated(model, seconds=2.0)
    no_current = rd.Recording(t=rec.t, q=rec.q, qd=rec.qd, qdd=rec.qdd, tau=rec.tau, source="a.csv")
    with pytest.raises(IdentificationError, match=r"a.csv: current: the recording has no 'current'"):
        rd.identify(robot, no_current, target="current", cutoff=None, model=model)
    with pytest.raises(IdentificationError, match=r"method: expected one of"):
        rd.identify(robot, rec, method="magic", model=model)
    with pytest.raises(IdentificationError, match=r"cutoff: must lie in \(0, 50\) Hz"):
        rd.identify(robot, rec, cutoff=80.0, model=model)


def test_joint_that_never_moves_is_reported_unidentifiable(arm):
    robot, model = arm
    rng = np.random.default_rng(4)
    t = np.arange(0.0, 6.0, 0.01)
    w = 2 * np.pi * 0.3
    q = np.column_stack([np.sin(w * t) + 0.3 * np.sin(3 * w * t), np.full_like(t, 0.4)])
    qd = np.column_stack([w * np.cos(w * t) + 0.9 * w * np.cos(3 * w * t), np.zeros_like(t)])
    qdd = np.column_stack([-w * w * np.sin(w * t) - 2.7 * w * w * np.sin(3 * w * t), np.zeros_like(t)])
    tau = model.inverse_dynamics(q, qd, qdd) + 0.01 * rng.standard_normal((t.size, 2))
    rec = rd.Recording(t=t, q=q, qd=qd, qdd=qdd, tau=tau, source="held.csv")
    ident = rd.identify(robot, rec, method="ols", cutoff=None, regularization=None, model=model)
    table = ident.base_parameters
    names = list(table.names)
    for name in ("Ia2", "Fv2"):
        i = names.index(name)
        assert not table.identifiable[i], name
        assert np.isinf(table.std[i]) and np.isinf(table.relative_std[i])
        assert table.values[i] == table.nominal[i]  # left at the prior, flagged
    assert "(not excited)" in str(table)
    assert table.identifiable[names.index("Fv1")]


def test_infeasible_consistent_problem_is_reported(arm):
    robot, model = arm
    rec, _ = simulated(model, seconds=4.0, dt=0.02, noise=0.01)
    with pytest.raises(IdentificationError, match=r"semidefinite program is infeasible.*M1"):
        rd.identify(robot, rec, method="consistent", cutoff=None, regularization=None,
                    bounds={"M1": (-2.0, -1.0)}, model=model)
    with pytest.raises(IdentificationError, match=r"bounds: unknown standard parameter 'mass'"):
        rd.identify(robot, rec, method="consistent", cutoff=None, bounds={"mass": (0, 1)}, model=model)


def test_positions_in_degrees_named_as_such():
    # issue 23: a recording in degrees ran to an overflow warning and exit 1; positions a whole
    # turn beyond a joint's limits cannot be radians of that joint
    robot = load_quiet("puma560")  # limits from the description, e.g. q1 in [-2.79, 2.79] rad
    t = np.arange(500) * 0.01
    q_rad = 0.8 * np.sin(np.outer(t, np.arange(1, 7)))  # inside every limit
    rec = rd.Recording(t=t, q=np.degrees(q_rad), tau=np.zeros_like(q_rad), source="deg.csv")
    with pytest.raises(IdentificationError, match=r"deg.csv: q: joint q1 reaches 45.8\d* rad at row "
                                                  r"\d+, .* beyond its limits .* positions in degrees\?"):
        rd.identify(robot, rec)
    # a trajectory that only leaves the limits (a simulated one may) is not refused by this check
    ok = rd.Recording(t=t, q=q_rad * 4, tau=np.zeros_like(q_rad), source="wide.csv")
    from robodyn.identification.inputs import check_within_limits

    check_within_limits(robot, ok.q, "wide.csv")


def test_options_object_checks_once_and_runs_like_the_keywords(arm):
    # issue 21 item 6: the choices in one checked object; the keywords build the same object
    robot, model = arm
    rec, _ = simulated(model, seconds=4.0, noise=0.01)
    by_keywords = rd.identify(robot, rec, cutoff=None, regularization=None, method="ols", model=model)
    opts = rd.IdentifyOptions(cutoff=None, regularization=None, method="ols")
    by_options = rd.identify(robot, rec, options=opts, model=model)
    np.testing.assert_array_equal(by_options.standard, by_keywords.standard)
    assert by_options.options is opts and by_keywords.options.method == "ols"
    assert by_keywords.options.cutoff is None and by_keywords.options.spikes == "auto"
    for bad, message in [({"method": "lasso"}, r"method: expected one of \('ols', 'wls', 'consistent'\)"),
                         ({"spikes": "clip"}, r"spikes: expected one of \('auto', 'keep', 'drop'\)"),
                         ({"weights": "state-noise"}, r"state_noise: weights='state-noise' needs"),
                         ({"thermal": 1}, r"thermal: expected False, True or 'auto', got 1"),
                         ({"ripple": "yes"}, r"ripple: expected False, True or 'auto', got 'yes'")]:
        with pytest.raises(IdentificationError, match=message):
            rd.IdentifyOptions(**bad)
    with pytest.raises(IdentificationError, match=r"options: given together with the keyword\(s\) "
                                                  r"method, spikes"):
        rd.identify(robot, rec, options=opts, method="wls", spikes="drop", model=model)
    with pytest.raises(IdentificationError, match="options: expected IdentifyOptions, got dict"):
        rd.identify(robot, rec, options={"method": "ols"}, model=model)
