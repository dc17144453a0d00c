"""Bad input: each a clear error or a reported unidentifiable parameter, never a silent answer."""

from __future__ import annotations

import numpy as np
import pytest

from robodyn.calibration import calibrate, compensate
from robodyn.studies.calibration_study import perturbed_robot, robot_positions
from tests.calibration.helpers import TARGET, TRACKER, poses, robot


def _data(n=40, seed=0):
    r = robot("puma560")
    true = perturbed_robot(r, seed, base=TRACKER, target=TARGET)
    q = poses("puma560", n, seed + 1)
    return r, true, q, robot_positions(true, q)


def test_too_few_poses_for_the_parameter_count():
    r, _, q, y = _data(9)  # 27 equations for 27 identifiable parameters
    with pytest.raises(ValueError, match=r"too few poses: 9 poses give 27 equations for 27 identifiable"):
        calibrate(r, q, y, "hayati")
    calibrate(r, q[:9], y[:9], "dh")  # DH identifies 26: 27 equations are (barely) enough


def test_nan_in_readings_or_points():
    r, _, q, y = _data()
    q = q.copy()
    q[7, 2] = np.nan
    with pytest.raises(ValueError, match=r"q has NaN .* row 7, column 2"):
        calibrate(r, q, y)
    y = y.copy()
    y[3, 0] = np.inf
    with pytest.raises(ValueError, match=r"points has NaN .* row 3"):
        calibrate(r, np.nan_to_num(q), y)


def test_mismatched_lengths_and_shapes():
    r, _, q, y = _data()
    with pytest.raises(ValueError, match="mismatched lengths: q has 40 poses but points has 39"):
        calibrate(r, q, y[:-1])
    with pytest.raises(ValueError, match=r"q must have shape \(N, 6\)"):
        calibrate(r, q[:, :5], y)
    with pytest.raises(ValueError, match=r"points must have shape \(N, 3\)"):
        calibrate(r, q, y[:, :2])
    with pytest.raises(ValueError, match="sigma must be positive"):
        calibrate(r, q, y, sigma=0.0)
    with pytest.raises(ValueError, match="orientations"):
        calibrate(r, q, y, orientations=np.ones((40, 3, 3)))


def test_unknown_options():
    r, _, q, y = _data()
    with pytest.raises(ValueError, match="unknown error model 'mdh'"):
        calibrate(r, q, y, "mdh")
    with pytest.raises(ValueError, match="unknown loss"):
        calibrate(r, q, y, loss="l1")
    with pytest.raises(ValueError, match="initial must be"):
        calibrate(r, q, y, initial="guess")
    with pytest.raises(ValueError, match="needs circle_data"):
        calibrate(r, q, y, initial="circle-point")


def test_rank_deficient_pose_set_is_reported():
    r, true, q, _ = _data(60)
    q = q.copy()
    q[:, 3] = 0.4  # joint 4 never moves
    y = robot_positions(true, q)
    cal = calibrate(r, q, y, "hayati")
    data = [u for u in cal.unidentifiable if u.kind == "pose set"]
    assert data and all("q4 take a single value" in u.reason for u in data)
    assert cal.after.max < 1e-9  # the poses it has are fitted ...
    held = {p.name for p in cal.parameters}
    assert not {u.name for u in data} & held  # ... and the unidentifiable ones are not estimated


def test_identical_poses_are_too_few():
    r, _, q, y = _data(40)
    q = np.tile(q[0], (40, 1))
    y = np.tile(y[0], (40, 1))
    cal = calibrate(r, q, y, "hayati")
    # one distinct pose identifies at most 3 combinations; the rest is reported
    assert len(cal.parameters) <= 3
    assert len(cal.unidentifiable) == cal.model.n_params - len(cal.parameters)
    assert sum(u.kind == "pose set" for u in cal.unidentifiable) >= 10


def test_unreachable_compensation_target():
    r, _, q, y = _data(40)
    cal = calibrate(r, q, y, "hayati")
    with pytest.raises(ValueError, match="not reached"):
        compensate(cal, y[:2] + np.array([5.0, 0, 0]), q[:2])
    with pytest.raises(ValueError, match="frame must be"):
        compensate(cal, y[:2], q[:2], frame="world")


def test_options_object_runs_like_the_keywords_and_checks_when_made():
    # issue 21 item 6: the choices of rd.calibrate in one checked object
    import robodyn as rd
    from robodyn.robot.errors import InputError

    r = robot("puma560")
    true = perturbed_robot(r, 3, base=TRACKER, target=(0.0, 0.0, 0.0))
    q = poses("puma560", 40, 1)
    y = robot_positions(true, q)
    by_keywords = rd.calibrate(r, q, y, "hayati", loss="huber")
    opts = rd.CalibrateOptions(model="hayati", loss="huber")
    by_options = rd.calibrate(r, q, y, options=opts)
    np.testing.assert_array_equal(by_options.params, by_keywords.params)
    assert by_options.options is opts and by_keywords.options.loss == "huber"
    for bad, message in [({"model": "mdh"}, "unknown error model 'mdh'"),
                         ({"nongeometric": "compliance"}, "expected a sequence of terms"),
                         ({"payload": (1.0, (0, 0, 0))}, "payload needs the 'compliance' term"),
                         ({"sigma_rot": 0.0}, "sigma_rot must be a positive number")]:
        with pytest.raises(InputError, match=message):
            rd.CalibrateOptions(**bad)
    with pytest.raises(InputError, match=r"options: given together with the keyword\(s\) loss"):
        rd.calibrate(r, q, y, loss="cauchy", options=opts)


def test_too_many_parameters_for_the_poses_is_warned_about():
    # issue 25 item 2: fewer than 3 equations per identifiable parameter draws a warning (and
    # more poses silence it); fewer equations than parameters stay refused
    r = robot("puma560")
    true = perturbed_robot(r, 3, base=TRACKER, target=(0.0, 0.0, 0.0))
    q = poses("puma560", 40, 1)
    y = robot_positions(true, q)
    with pytest.warns(RuntimeWarning, match=r"40 poses give 120 equations for \d+ identifiable "
                                             r"parameters of the s-model model \(fewer than 3 per"):
        calibrate(r, q, y, nongeometric=("compliance", "harmonics"))
    import warnings

    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        calibrate(r, q, y)  # the geometry alone: about 30 parameters for 120 equations
    assert not [w for w in seen if "equations for" in str(w.message)]
