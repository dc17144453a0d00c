"""``out=``: the regressor and the stacked identification matrix written into a caller's buffer.

Reference: the same call without ``out`` (a fresh array), and the kernels' own one-state results.
"""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd
from robodyn.identification.stacking import identification_matrix

pytestmark = pytest.mark.tool("gcc|cc")


@pytest.fixture(scope="module", params=["c", "numpy"])
def model(request):
    return rd.compile_model(rd.load("planar_2r"), request.param)


def _states(count, seed=0):
    rng = np.random.default_rng(seed)
    return rng.uniform(-2, 2, (3, count, 2))


@pytest.mark.parametrize("count", [1, 16, 17, 1000])
def test_out_buffer_equals_fresh_and_is_reused(model, count):
    q, qd, qdd = _states(count)
    fresh = identification_matrix(model, q, qd, qdd)
    buf = np.full((2 * count, 30), np.nan)  # every entry must be written, zeros included
    got = identification_matrix(model, q, qd, qdd, out=buf)
    assert np.shares_memory(got, buf)
    assert np.array_equal(got, fresh)
    # a second stacking into the same memory, other states
    q2, qd2, qdd2 = _states(count, seed=1)
    again = identification_matrix(model, q2, qd2, qdd2, out=buf)
    assert np.shares_memory(again, buf)
    assert np.array_equal(again, identification_matrix(model, q2, qd2, qdd2))
    # row k n + i is joint i of sample k, equal to the one-state regressor
    k = count - 1
    assert np.array_equal(buf[2 * k:2 * k + 2], model.regressor(q2[k], qd2[k], qdd2[k]))


def test_column_selection_into_out(model):
    q, qd, qdd = _states(40)
    cols = [0, 3, 9, 15, 29]
    buf = np.empty((80, len(cols)))
    got = identification_matrix(model, q, qd, qdd, cols, out=buf)
    assert got is buf
    assert np.array_equal(buf, identification_matrix(model, q, qd, qdd)[:, cols])


def test_bad_out_is_refused(model):
    q, qd, qdd = _states(5)
    with pytest.raises(ValueError, match=r"expected shape \(10, 30\), got \(10, 29\)"):
        identification_matrix(model, q, qd, qdd, out=np.empty((10, 29)))
    with pytest.raises(ValueError, match="C-contiguous float64"):
        model.regressor(q, qd, qdd, out=np.empty((5, 2, 30), dtype=np.float32))
    with pytest.raises(ValueError, match="C-contiguous float64"):
        model.regressor(q, qd, qdd, out=np.empty((5, 2, 60))[:, :, ::2])
    with pytest.raises(ValueError, match=r"\(5, 2, 30\) \(300 values\)"):
        model.regressor(q, qd, qdd, out=np.empty(299))
    shared = np.empty(300)
    with pytest.raises(ValueError, match="overlaps an input"):
        model.regressor(shared[:10].reshape(5, 2), qd, qdd, out=shared)


@pytest.mark.parametrize("count", [1, 17])
def test_every_batch_kernel_writes_into_out(model, count):
    """inverse_dynamics, forward_dynamics, state_derivative, mass_matrix, gravity and coriolis
    take ``out=`` as the regressor does: the same bits as a fresh result, in the caller's
    memory (the buffer starts as NaN: every entry is written)."""
    q, qd, qdd = _states(count)
    x = np.hstack([q, qd])
    calls = {"inverse_dynamics": (q, qd, qdd), "forward_dynamics": (q, qd, qdd),
             "state_derivative": (x, qdd), "mass_matrix": (q,), "gravity": (q,),
             "coriolis": (q, qd)}
    for name, args in calls.items():
        fresh = getattr(model, name)(*args)
        buf = np.full(fresh.size, np.nan)
        got = getattr(model, name)(*args, out=buf)
        assert np.shares_memory(got, buf), name
        assert got.shape == fresh.shape, name
        np.testing.assert_array_equal(got, fresh, err_msg=name)
    with pytest.raises(ValueError, match=r"inverse_dynamics\(out=...\)"):
        model.inverse_dynamics(q, qd, qdd, out=np.empty(q.size + 1))


def test_derivatives_write_into_out(model):
    """``out=`` of the two derivative kernels receives ``[d/dq | d/dqd (| d/dtau)]``: the returned
    blocks are views into it, equal to a fresh call's."""
    q, qd, qdd = _states(17)
    for name, width in (("inverse_dynamics_derivatives", 4), ("forward_dynamics_derivatives", 6)):
        fresh = getattr(model, name)(q, qd, qdd)
        buf = np.full((17, 2, width), np.nan)
        got = getattr(model, name)(q, qd, qdd, out=buf)
        for a, b in zip(got, fresh, strict=True):
            assert np.shares_memory(a, buf), name
            np.testing.assert_array_equal(a, b, err_msg=name)
        assert np.array_equal(np.concatenate(got, axis=-1), buf), name
