"""The nonlinear friction fit on a joint that turns one way only, and on one that reverses.

On one-way data ``sign(qd)`` is constant: the Coulomb level and the offset enter only as their
sum, and a free fit drifted to large opposite values (Coulomb 63 N m against an offset of
-63 N m on the Kinova's torque-sensor run), which a reversing motion then shows at twice their
size. The offset now stays the start's (the linear step's) there; the expectations are the
truth's sums, and on reversing data the truth itself.
"""

from __future__ import annotations

import numpy as np
import pytest

from robodyn.identification.friction import V_EPS, _fit_law, _law, _start

TRUE = {"stribeck": np.array([0.8, 1.3, 0.07, 0.4, -0.1]),
        "polynomial": np.array([0.8, 0.4, -0.3, 0.2, -0.1])}


@pytest.mark.parametrize("law", sorted(TRUE))
def test_one_way_motion_keeps_the_offset_and_fits_the_sum(law):
    x = TRUE[law]
    v = np.linspace(0.1, 1.0, 400)  # turning forward only (far beyond V_EPS: sign 1 to 1e-8)
    assert v.min() >= 10 * V_EPS
    load = np.zeros_like(v)
    r = _law(law, x, v, load)
    # a start from a linear step whose split of Coulomb and offset is off by 0.5
    x0, bounds = _start(law, np.array([0.3, 1.3, 1.3, 0.4]))
    fit = _fit_law(law, x0, bounds, v, load, r)
    assert fit[-1] == x0[-1]  # the offset held
    np.testing.assert_allclose(_law(law, fit, v, load), r, atol=1e-6)
    # Coulomb + offset is what one-way data see: the truth's sum
    np.testing.assert_allclose(fit[0] + fit[-1], x[0] + x[-1], atol=1e-5)


@pytest.mark.parametrize("law", sorted(TRUE))
def test_reversing_motion_fits_the_offset(law):
    x = TRUE[law]
    v = np.concatenate([np.linspace(-1.0, -0.02, 200), np.linspace(0.02, 1.0, 200)])
    load = np.zeros_like(v)
    x0, bounds = _start(law, np.array([0.3, 1.3, 1.3, 0.4]))
    fit = _fit_law(law, x0, bounds, v, load, _law(law, x, v, load))
    np.testing.assert_allclose(fit, x, rtol=1e-5, atol=1e-6)
