"""rollout's options objects: every choice checked on construction, with the field named."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"steps": 0, "dt": 1e-3}, "steps must be a positive integer"),
    ({"steps": 2.5, "dt": 1e-3}, "steps must be a positive integer"),
    ({"steps": True, "dt": 1e-3}, "steps must be a positive integer"),
    ({"steps": 10, "dt": 0.0}, "dt must be a positive number"),
    ({"steps": 10, "dt": float("nan")}, "dt must be a positive number"),
    ({"steps": 10, "dt": 1e-3, "method": "RK45"}, "unknown fixed-step method 'RK45'"),
    ({"steps": 10, "dt": 1e-3, "control": "held"}, "unknown control 'held'"),
    ({"steps": 10, "dt": 1e-3, "method": "semi_implicit", "control": "continuous"},
     "control='continuous' needs method='rk4'"),
    ({"steps": 10, "dt": 1e-3, "threads": 0}, "threads must be a positive integer"),
])
def test_bad_options_are_refused_by_name(kwargs, message):
    with pytest.raises(ValueError, match=message):
        rd.RolloutOptions(**kwargs)


def test_bad_law_and_options_type_are_refused():
    with pytest.raises(ValueError, match="unknown controller mode 'pd'"):
        rd.FeedbackLaw("pd")
    model = rd.compile_model(rd.load("planar_2r"), backend="numpy")
    with pytest.raises(ValueError, match="options must be a RolloutOptions"):
        rd.rollout(model, np.zeros(4), {"steps": 10, "dt": 1e-3})  # type: ignore[arg-type]
    with pytest.raises(ValueError, match=r"rollout: gain must have shape \(2, 4\)"):
        rd.rollout(model, np.zeros(4), rd.RolloutOptions(10, 1e-3), rd.FeedbackLaw(gain=np.eye(2)))


def test_zero_law_is_the_passive_run_and_feedforward_moves_it():
    """No law is zero torque: a run from rest at a stable equilibrium stays there, and a constant
    feedforward on a planar arm in a vertical plane gives the same steps as the explicit law."""
    model = rd.compile_model(rd.load("planar_2r"), backend="numpy")
    x0 = np.array([0.3, -0.2, 0.0, 0.0])
    opts = rd.RolloutOptions(50, 1e-3)
    passive, tau = rd.rollout(model, x0, opts)
    assert np.all(tau == 0.0)
    zero, _ = rd.rollout(model, x0, opts, rd.FeedbackLaw(feedforward=np.zeros((50, 2))))
    np.testing.assert_array_equal(passive, zero)
    # holding torque g(q0) as feedforward keeps the arm at q0 (to RK4 rounding)
    g = model.gravity(x0[:2])
    held, tau_h = rd.rollout(model, x0, opts, rd.FeedbackLaw(feedforward=np.tile(g, (50, 1))))
    np.testing.assert_allclose(held[-1], x0, atol=1e-12)
    np.testing.assert_allclose(tau_h, np.tile(g, (50, 1)), rtol=0, atol=0)
