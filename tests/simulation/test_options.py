"""SimulateOptions: the choices of rd.simulate in one checked object (issue 21 item 6)."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd
from robodyn.robot.errors import InputError
from robodyn.simulation.controllers import PD


@pytest.fixture(scope="module")
def model():
    return rd.compile_model(rd.load("planar_2r"))


def test_options_run_like_the_keywords_and_are_kept(model):
    q0 = np.array([0.3, -0.2])
    pd = PD(kp=np.diag([50.0, 30.0]), kd=np.diag([5.0, 3.0]), q_ref=np.zeros(2))
    by_keywords = rd.simulate(model, q0, None, 0.5, 1e-3, "rk4", pd, decimate=5, tau_limit=20.0)
    opts = rd.SimulateOptions(decimate=5, tau_limit=20.0)
    by_options = rd.simulate(model, q0, None, 0.5, 1e-3, controller=pd, options=opts)
    np.testing.assert_array_equal(by_options.x, by_keywords.x)
    assert by_options.options is opts and by_keywords.options.decimate == 5


@pytest.mark.parametrize(("bad", "message"), [
    ({"method": "euler"}, r"unknown method 'euler'; choose one of rk4, semi_implicit, RK45"),
    ({"control": "held"}, r"unknown control 'held'"),
    ({"method": "semi_implicit", "control": "continuous"}, r"control='continuous' needs method='rk4'"),
    ({"substeps": 0}, r"substeps must be a positive integer, got 0"),
    ({"substeps": 2, "method": "RK45"}, r"substeps needs a fixed-step method"),
    ({"rtol": -1.0}, r"rtol must be a positive number, got -1.0"),
    ({"max_samples": 0}, r"max_samples must be a positive integer or None, got 0"),
])
def test_bad_options_are_refused_when_made(bad, message):
    with pytest.raises(InputError, match=message):
        rd.SimulateOptions(**bad)


def test_options_and_keywords_together_are_refused(model):
    with pytest.raises(InputError, match=r"options: given together with the keyword\(s\) method, decimate"):
        rd.simulate(model, np.zeros(2), None, 0.1, 1e-3, "RK45", decimate=2,
                    options=rd.SimulateOptions())
