"""A joint without target data (an all-NaN column: no sensor on that joint) in ``rd.identify``.

The plant is the PUMA 560 with each link's inertial parameters scaled (a physical set other than
the description's) and other viscous friction; its torque is the description's regressor times
those parameters. Joint 1's torque is missing from the recordings. The expectation is the plant
itself: the other joints' torques on another trajectory, and the description's own terms for
joint 1 where no data speak for them.
"""

from __future__ import annotations

import warnings
from types import SimpleNamespace

import numpy as np
import pytest

import robodyn as rd
from robodyn.identification.pipeline import nominal_standard
from robodyn.identification.prior import IdentificationWarning
from robodyn.robot.errors import IdentificationError
from robodyn.symbolic.regressor import PER_JOINT, joint_columns

from .helpers import fourier, load_quiet

SCALE = np.array([1.3, 0.8, 1.2, 0.9, 1.1, 1.25])  # each link's mass, first and second moments


@pytest.fixture(scope="module")
def arm():
    robot = load_quiet("puma560")
    nominal = nominal_standard(robot)
    true = nominal.copy()
    for j, c in enumerate(SCALE):
        true[j * PER_JOINT:j * PER_JOINT + 10] *= c  # a scaled rigid body stays physical
        true[j * PER_JOINT + 11] *= 1.5  # viscous friction Fv
    model = rd.compile_model(robot)
    return robot, model, (model, true), nominal


def _run(plant: tuple[rd.Model, np.ndarray], seed: int, seconds: float,
         missing: tuple[int, ...] = ()):
    """A run of the plant: the regressor of the description times the plant's parameters."""
    model, true = plant
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, seconds, 0.01)
    q, qd, qdd = fourier(t, model.dof, rng)
    tau = model.regressor(q, qd, qdd) @ true
    logged = tau.copy()
    logged[:, list(missing)] = np.nan
    rec = rd.Recording(t=t, q=q, qd=qd, qdd=qdd, tau=logged, joint_names=model.robot.joint_names,
                       source=f"sim{seed}")
    return rec, tau


def test_the_other_joints_are_identified_and_the_missing_one_keeps_the_description(arm):
    robot, model, plant, nominal = arm
    rec, _ = _run(plant, 1, 20.0, missing=(0,))
    with pytest.warns(IdentificationWarning, match=r"tau: no data for joint\(s\) q1 in any recording"):
        ident = rd.identify(robot, rec, method="ols", cutoff=None, regularization=None, model=model)
    assert ident.unobserved == ("q1",)
    assert np.isnan(ident.residual_std[0]) and np.isfinite(ident.residual_std[1:]).all()
    assert np.isnan(rec.tau[:, 0]).all()  # the caller's recording is left as it was
    # another trajectory: the plant's torques on joints 2-6 (what their rows determine)
    check, tau = _run(plant, 2, 5.0)
    pred = ident.predict(check)
    np.testing.assert_allclose(pred[:, 1:], tau[:, 1:], rtol=0, atol=1e-8 * np.abs(tau).max())
    # the description alone is far off there: the test can tell
    assert np.abs(model.inverse_dynamics(check.q, check.qd, check.qdd)[:, 1:] - tau[:, 1:]).max() \
        > 0.05 * np.abs(tau).max()
    # joint 1's own rotor inertia and friction: no data, the description's values
    np.testing.assert_allclose(ident.standard[joint_columns(0)], nominal[joint_columns(0)],
                               rtol=1e-9, atol=1e-12)
    # ... and with data on joint 1 the same call finds the plant's viscous friction there
    full, _ = _run(plant, 1, 20.0)
    seen = rd.identify(robot, full, method="ols", cutoff=None, regularization=None, model=model)
    fv = 11  # joint 1's Fv
    np.testing.assert_allclose(seen.standard[fv], 1.5 * nominal[fv], rtol=1e-6)


def test_a_joint_missing_in_one_recording_is_fitted_from_the_others(arm):
    # the default call (consistent, regularised, choices by held-out blocks): joint 3 has data in
    # the second run only; the rows it has are used, and joint 3 is not reported unobserved
    robot, model, plant, nominal_p = arm
    first, _ = _run(plant, 3, 12.0, missing=(2,))
    second, _ = _run(plant, 4, 12.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error", IdentificationWarning)
        ident = rd.identify(robot, [first, second], model=model)
    assert ident.unobserved == ()
    check, tau = _run(plant, 5, 5.0)
    err = np.linalg.norm(ident.predict(check) - tau, axis=0) / np.linalg.norm(tau, axis=0)
    nominal = model.inverse_dynamics(check.q, check.qd, check.qdd)
    err0 = np.linalg.norm(nominal - tau, axis=0) / np.linalg.norm(tau, axis=0)
    # every joint, joint 3 included, predicted well within the description's own error
    assert np.all(err < 0.1 * err0), (err, err0)
    # joint 3's viscous friction from the run that has its torque: the plant's (1.5 times the
    # description's, which it keeps where no run has data: the first test)
    fv = 2 * PER_JOINT + 11
    np.testing.assert_allclose(ident.standard[fv], 1.5 * nominal_p[fv], rtol=1e-3)


def test_partly_missing_and_all_missing_targets_are_refused(arm):
    robot, model, plant, _ = arm
    rec, tau = _run(plant, 6, 3.0, missing=(0,))
    part = rec.tau.copy()
    part[40, 2] = np.nan  # one bad value in a joint that has data: a corrupt row, not a sensor
    # (a Recording refuses it itself; any object with the fields reaches rd.identify's check)
    bad = SimpleNamespace(t=rec.t, q=rec.q, qd=rec.qd, qdd=rec.qdd, tau=part,
                          joint_names=robot.joint_names, source="part.csv")
    with pytest.raises(IdentificationError, match=r"part.csv: tau: value nan is not finite at row 40, "
                                                  r"column 2 \(q3\)"):
        rd.identify(robot, bad, model=model, cutoff=None)
    # without the bad value the same object is accepted, joint 1 left out
    good = SimpleNamespace(**{**vars(bad), "tau": rec.tau})
    with pytest.warns(IdentificationWarning, match="no data for joint"):
        assert rd.identify(robot, good, model=model, cutoff=None, method="ols").unobserved == ("q1",)
    assert np.isnan(good.tau[:, 0]).all()
    none = rd.Recording(t=rec.t, q=rec.q, qd=rec.qd, qdd=rec.qdd, tau=np.full_like(tau, np.nan),
                        joint_names=robot.joint_names, source="none.csv")
    with pytest.raises(IdentificationError, match=r"none.csv: tau: no joint has a finite value"):
        rd.identify(robot, none, model=model, cutoff=None)


def test_drive_gains_from_a_payload_run_with_a_joint_without_current(arm):
    # target current through drive gains 2-9 % off the description's, a run with a known payload:
    # the gains of the joints with current come back (noise-free), joint 1 keeps the
    # description's gain, reported not estimated (std inf); before, the gain fit diverged
    robot, model, (_, true), _ = arm
    from robodyn.identification.payload import payload_standard
    from robodyn.identification.prior import description_gains

    pay = rd.Payload(mass=1.5, com=[0.0, 0.0, 0.05], inertia=np.diag([0.004, 0.006, 0.008]))
    desc = description_gains(robot)
    gains = desc * np.array([1.02, 0.95, 1.07, 0.91, 1.04, 0.97])
    loaded = true.copy()
    loaded[5 * PER_JOINT:5 * PER_JOINT + 10] += payload_standard(robot, pay)
    runs = []
    for k, p in enumerate((true, loaded)):
        rng = np.random.default_rng(10 + k)
        t = np.arange(0.0, 12.0, 0.01)
        q, qd, qdd = fourier(t, robot.dof, rng)
        current = (model.regressor(q, qd, qdd) @ p) / gains
        current[:, 0] = np.nan
        runs.append(rd.Recording(t=t, q=q, qd=qd, qdd=qdd, current=current,
                                 joint_names=robot.joint_names, source=f"run{k}"))
    with pytest.warns(IdentificationWarning, match="no data for joint"):
        ident = rd.identify(robot, runs, target="current", model=model, payloads=[None, pay],
                            method="ols", cutoff=None, regularization=None)
    assert ident.gains_source == "payload"
    np.testing.assert_allclose(ident.gains[1:], gains[1:], rtol=1e-6)
    assert ident.gains[0] == desc[0] and np.isinf(ident.gains_std[0])


def test_a_gain_that_cannot_be_absorbed_is_the_mean_of_the_joints_with_data(arm):
    # gains absorbed, joint 1 without current and joint 6's current unrelated to its torque: joint
    # 6 gets the geometric mean of joints 2-5's absorbed gains (joint 1's stand-in 1 left out)
    robot, model, (_, true), nominal = arm
    rng = np.random.default_rng(12)
    t = np.arange(0.0, 12.0, 0.01)
    q, qd, qdd = fourier(t, robot.dof, rng)
    gains = np.array([20.0, 30.0, 15.0, 6.0, 5.0, 4.0])
    current = (model.regressor(q, qd, qdd) @ true) / gains
    current[:, 0] = np.nan
    # joint 6: a current against the description's rigid-body torque, under an unrelated
    # oscillation three times larger (correlation above -0.5: not a reversed sensor)
    rigid = nominal.copy()
    for j in range(robot.dof):
        rigid[joint_columns(j)] = 0.0
    against = -(model.regressor(q, qd, qdd) @ rigid)[:, 5] / gains[5]
    current[:, 5] = against + 3 * against.std() * np.sin(2 * np.pi * 3.7 * t)
    rec = rd.Recording(t=t, q=q, qd=qd, qdd=qdd, current=current, joint_names=robot.joint_names,
                       source="run")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", IdentificationWarning)
        ident = rd.identify(robot, rec, target="current", model=model, gains="absorbed",
                            method="ols", cutoff=None, regularization=None)
    assert "q6: mean of the others" in ident.gains_source, (ident.gains_source, ident.gains)
    k = np.abs(ident.gains)
    assert k[0] == 1.0
    np.testing.assert_allclose(k[5], np.exp(np.mean(np.log(k[1:5]))), rtol=1e-12)
