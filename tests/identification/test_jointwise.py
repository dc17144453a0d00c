"""Per-joint identification: closed form of the 2R arm, a joint that never moves, Kinova jointwise runs."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd
from robodyn.identification.jointwise import identify_joint
from robodyn.measure.filtering import lowpass
from robodyn.robot.errors import IdentificationError
from tests.identification.helpers import load_quiet
from tests.identification.kinova import JOINTWISE_FILES, read, relative_error, split


def _one_joint_moving(model, q2=0.7, seconds=8.0, dt=0.01):
    t = np.arange(0.0, seconds, dt)
    w = 2 * np.pi * 0.25
    q = np.column_stack([1.2 * np.sin(w * t) + 0.4 * np.sin(3 * w * t), np.full_like(t, q2)])
    qd = np.column_stack([1.2 * w * np.cos(w * t) + 1.2 * w * np.cos(3 * w * t), np.zeros_like(t)])
    qdd = np.column_stack([-1.2 * w * w * np.sin(w * t) - 3.6 * w * w * np.sin(3 * w * t), np.zeros_like(t)])
    return rd.Recording(t=t, q=q, qd=qd, qdd=qdd, tau=model.inverse_dynamics(q, qd, qdd), source="one.csv")


def test_2r_closed_form_inertia_and_gravity():
    """Spong's 2R arm (m = l = 1, lc = 1/2, I = 1/12, g = 9.81) with joint 2 held at q2."""
    robot = load_quiet("planar_2r")
    model = rd.compile_model(robot)
    q2 = 0.7
    rec = _one_joint_moving(model, q2)
    fit = identify_joint(robot, rec, target="tau", cutoff=None)
    assert fit.joint == 0 and fit.joint_name == "q1"
    values = dict(zip(fit.names, fit.values, strict=True))
    # M11 = m1 lc1^2 + m2 (l1^2 + lc2^2 + 2 l1 lc2 cos q2) + I1 + I2
    j = 0.25 + (1 + 0.25 + np.cos(q2)) + 2 / 12
    # g1 = (m1 lc1 + m2 l1) g cos q1 + m2 lc2 g cos(q1 + q2) = Gc cos q1 + Gs sin q1
    gc = 1.5 * 9.81 + 0.5 * 9.81 * np.cos(q2)
    gs = -0.5 * 9.81 * np.sin(q2)
    np.testing.assert_allclose([values["J"], values["Gc"], values["Gs"]], [j, gc, gs], rtol=1e-9)
    np.testing.assert_allclose(fit.predict(rec), rec.tau[:, 0], atol=1e-9)


def test_a_held_joint_without_a_sensor_does_not_stop_the_moving_one():
    # the held joint 2's torque missing (an all-NaN column): joint 1 is identified as with it
    # (the same values); the moving joint's own torque missing: it has no data, said so
    robot = load_quiet("planar_2r")
    model = rd.compile_model(robot)
    rec = _one_joint_moving(model)

    def without(j: int) -> rd.Recording:
        tau = rec.tau.copy()
        tau[:, j] = np.nan
        return rd.Recording(t=rec.t, q=rec.q, qd=rec.qd, qdd=rec.qdd, tau=tau, source="one.csv")

    full = identify_joint(robot, rec, target="tau", cutoff=None)
    fit = identify_joint(robot, without(1), target="tau", cutoff=None)
    np.testing.assert_array_equal(fit.values, full.values)
    with pytest.raises(IdentificationError, match=r"one.csv: tau: joint 'q1' has no data"):
        identify_joint(robot, without(0), target="tau", cutoff=None)


def test_joint_that_never_moves_is_unidentifiable():
    robot = load_quiet("planar_2r")
    model = rd.compile_model(robot)
    rec = _one_joint_moving(model)
    with pytest.raises(IdentificationError, match=r"one.csv: q: joint 'q2' never moves .* unidentifiable"):
        identify_joint(robot, rec, joint="q2", target="tau", cutoff=None)


@pytest.mark.data(*JOINTWISE_FILES)
def test_kinova_jointwise_fit_and_held_out():
    """Each jointwise run, its moving joint: fit on the whole run (in-sample), and fit on the
    first 70 % to predict the last 30 % (an extrapolation: the joints move one way, so the last
    30 % lies outside the fitted position range)."""
    robot = load_quiet("kinova_gen3")
    for k, path in enumerate(JOINTWISE_FILES):
        rec = read(path)
        whole = identify_joint(robot, rec)
        assert whole.joint == k and whole.relative_std[0] < 20  # effective inertia within 20 %
        train, test = split(rec)
        fit = identify_joint(robot, train)
        figures = []
        for f, r in ((whole, rec), (fit, test)):
            y = r.current[:, k]
            y_f = lowpass(r.t, r.current, f.preprocess.cutoff)[:, k]
            pred = f.predict(r)
            figures.append((relative_error(pred - y, y), relative_error(pred - y_f, y_f),
                            relative_error(y - y_f, y)))
        (raw_in, filt_in, floor_in), (raw, filt, floor) = figures
        print(f"{path.name}: J {whole.values[0]:.4g} A s^2/rad ({whole.relative_std[0]:.2g} %); "
              f"in-sample raw {raw_in:.3f} filtered {filt_in:.3f} floor {floor_in:.3f}; "
              f"held-out raw {raw:.3f} filtered {filt:.3f} floor {floor:.3f}")
        assert filt_in < 0.07, path.name
        # held out: the raw error is the noise floor plus at most 0.07, or below the baseline
        assert raw < max(0.32, floor + 0.07), path.name
