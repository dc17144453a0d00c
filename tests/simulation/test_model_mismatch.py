"""A controller's own model is the one it uses: plant/controller mismatch tracks worse, as predicted.

The planar 2R arm's inertial parameters all scale with the masses (uniform rods): a controller
model with ``m1, m2`` 20 % heavier has ``M' = a M``, ``h' = a h`` exactly (``a = 1.2``). Under the
computed-torque law ``tau = M' v + h'`` with ``v = qdd_ref + Kp e + Kd ed`` the plant obeys
``M qdd + h = a (M v + h)``, so the tracking error ``e = q_ref - q`` obeys, exactly,

    e'' + a Kd e' + a Kp e = d(t),   d = (1 - a) (qdd_ref + M^-1 h) = (1 - a) (qdd_ref - FD(q, qd, 0))

With Kp = 400, Kd = 40 the error loop ``s^2 + 48 s + 480`` is overdamped (two real poles), its
impulse response is positive with integral ``1 / (a Kp)``: ``|e_j| <= max |d_j| / (a Kp)``.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.interpolate import CubicSpline

import robodyn as rd
from robodyn.simulation import ComputedTorque, GravityCompensation, quintic, simulate

ALPHA = 1.2
KP, KD = 400.0, 40.0
Q0 = np.array([-1.0, 0.5])
Q1 = np.array([0.5, 1.3])


@pytest.fixture(scope="module")
def heavy():
    """The planar 2R arm's model with both masses (hence every inertial parameter) 20 % high."""
    return rd.compile_model(rd.load("planar_2r"), parameters={"m1": ALPHA, "m2": ALPHA})


def _forcing(plant, run, plan):
    # d = (1 - a) (qdd_ref - FD(q, qd, 0))
    qdd_r = plan.at(run.t)[2]
    return (1.0 - ALPHA) * (qdd_r - plant.forward_dynamics(run.q, run.qd, np.zeros_like(run.q)))


def test_the_wrong_model_tracks_worse_by_the_predicted_amount(planar, heavy):
    plan = quintic(Q0, Q1, 1.0, dt=1e-3)
    exact = simulate(planar, Q0, None, 1.5, 1e-3, "rk4", ComputedTorque(plan, KP, KD),
                     control="continuous")
    wrong = simulate(planar, Q0, None, 1.5, 1e-3, "rk4", ComputedTorque(plan, KP, KD, model=heavy),
                     control="continuous")
    err_exact = np.abs(exact.q - plan.at(exact.t)[0]).max()
    e = plan.at(wrong.t)[0] - wrong.q
    # the exact model tracks to RK4's error; the 20 % heavier one by mrad (before the fix both
    # runs used the plant's model and gave the same ~1e-12)
    assert err_exact < 1e-9
    assert np.abs(e).max() > 1e-4
    d = _forcing(planar, wrong, plan)
    # |e_j| <= max|d_j| / (a Kp): the overdamped loop's impulse response integrates to 1/(a Kp)
    bound = np.abs(d).max(axis=0) / (ALPHA * KP)
    assert np.all(np.abs(e).max(axis=0) <= bound * (1 + 1e-6)), (np.abs(e).max(axis=0), bound)
    # and e is the response of e'' + a Kd e' + a Kp e = d(t) to the forcing along the run
    # d is smooth but for a jump of its slope where the quintic ends (t = 1 s): one cubic spline
    # on each side
    k = 1000
    before, after = CubicSpline(wrong.t[: k + 1], d[: k + 1]), CubicSpline(wrong.t[k:], d[k:])

    def rhs(t, y):
        forcing = before(t) if t <= 1.0 else after(t)
        return np.concatenate([y[2:], forcing - ALPHA * KD * y[2:] - ALPHA * KP * y[:2]])

    sol = solve_ivp(rhs, (0.0, wrong.t[-1]), np.zeros(4), t_eval=wrong.t, method="DOP853",
                    rtol=1e-11, atol=1e-14)
    predicted = sol.y[:2].T
    # measured: 6.0e-9 of max |e| at 1 ms, 3.7e-10 at 0.5 ms (fourth order: the spline of d and
    # RK4); max |e| = 9.4e-3 rad
    assert np.abs(predicted - e).max() < 1e-7 * np.abs(e).max()


@pytest.mark.parametrize(("method", "control"), [("rk4", "sampled"), ("RK45", "sampled")])
def test_every_method_uses_the_controllers_model(planar, heavy, method, control):
    plan = quintic(Q0, Q1, 1.0, dt=1e-3)
    ref = simulate(planar, Q0, None, 1.0, 1e-3, "rk4", ComputedTorque(plan, KP, KD, model=heavy),
                   control="continuous")
    run = simulate(planar, Q0, None, 1.0, 1e-3, method, ComputedTorque(plan, KP, KD, model=heavy),
                   control=control)
    e_ref = np.abs(ref.q - plan.q).max()
    # the same mismatch error whatever the integrator (sampled at 1 ms adds about 1e-4 of it)
    assert abs(np.abs(run.q - plan.q).max() - e_ref) < 1e-2 * e_ref
    assert run.controller == "ComputedTorque"


def test_a_model_with_the_same_dynamics_keeps_the_compiled_loop(planar):
    same = rd.compile_model(rd.load("planar_2r"), backend="numpy")
    plan = quintic(Q0, Q1, 1.0, dt=1e-3)
    a = simulate(planar, Q0, None, 1.0, 1e-3, "rk4", ComputedTorque(plan, KP, KD))
    b = simulate(planar, Q0, None, 1.0, 1e-3, "rk4", ComputedTorque(plan, KP, KD, model=same))
    np.testing.assert_array_equal(a.q, b.q)


def test_gravity_compensation_with_a_wrong_model_settles_where_the_error_is_predicted(planar, heavy):
    q_ref = np.array([0.5, 0.3])
    run = simulate(planar, Q0, None, 10.0, 1e-3, "rk4",
                   GravityCompensation(200.0, 40.0, q_ref, model=heavy))
    q = run.q[-1]
    # at rest: Kp (q_ref - q) + a g(q) = g(q)
    assert np.abs(200.0 * (q_ref - q) - (1.0 - ALPHA) * planar.gravity(q)).max() < 1e-8
    assert np.abs(q - q_ref).max() > 1e-2


def test_a_controller_model_of_another_robot_is_refused(planar):
    other = rd.compile_model(rd.load("trolley_double_pendulum"))
    plan = quintic(Q0, Q1, 1.0, dt=1e-3)
    with pytest.raises(ValueError, match="controller's model .* 3 joints"):
        simulate(planar, Q0, None, 1.0, 1e-3, "rk4", ComputedTorque(plan, KP, KD, model=other))
