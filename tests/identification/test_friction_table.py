"""``friction_table(..., like=ident)``: every law is identified with the processing of ``like``.

The laws are compared like for like when only the law differs: the velocity source, cut-off,
Coulomb dead band and Tikhonov weight are ``like``'s, passed to each ``rd.identify`` call beside
the law (checked by recording the calls), and an option that ``like`` sets cannot be given as
well.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

import robodyn as rd
from robodyn.identification import friction_comparison
from robodyn.robot.errors import IdentificationError


def _recording(seed: int) -> rd.Recording:
    t = 0.01 * np.arange(200)
    rng = np.random.default_rng(seed)
    q = np.column_stack([np.sin(t), np.cos(2 * t)])
    return rd.Recording(t=t, q=q, tau=q + 0.1 * rng.standard_normal(q.shape), joint_names=("a", "b"))


def _like() -> SimpleNamespace:
    return SimpleNamespace(preprocess=SimpleNamespace(velocity="measured", cutoff=4.5, dead_band=0.002),
                           regularization=0.03)


def test_each_law_is_identified_with_the_processing_of_like(monkeypatch) -> None:
    calls = []

    def fake_identify(robot, train, **kwargs):
        calls.append(kwargs)
        return SimpleNamespace(target="tau", predict=lambda rec: np.asarray(rec.tau) * 0.9)

    monkeypatch.setattr(friction_comparison, "identify", fake_identify)
    robot = SimpleNamespace(joint_names=("a", "b"))
    table = friction_comparison.friction_table(robot, [_recording(1)], [_recording(2)],
                                               models=("none", "stribeck"), like=_like(),
                                               target="tau", method="wls")
    assert [c["friction"] for c in calls] == ["none", "stribeck"]
    for c in calls:
        assert (c["velocity"], c["cutoff"], c["dead_band"], c["regularization"]) == (
            "measured", 4.5, 0.002, 0.03)
        assert (c["target"], c["method"]) == ("tau", "wls")
    # the prediction is 0.9 y: relative error 0.1 on every row
    assert np.allclose(table["relative_error"], 0.1)


@pytest.mark.parametrize("option", ["cutoff", "velocity", "dead_band", "regularization"])
def test_like_and_an_option_it_sets_are_refused(option) -> None:
    robot = SimpleNamespace(joint_names=("a", "b"))
    with pytest.raises(IdentificationError, match=option):
        friction_comparison.friction_table(robot, [_recording(1)], [_recording(2)],
                                           models=("none",), like=_like(), **{option: 1.0})
