"""``threads=`` on the Model batch methods: the same result bits for any thread count.

Threads take whole blocks of states (OpenMP in the generated C); a state's arithmetic does not
depend on which thread or block position computes it, so the results must be identical bit for
bit, not merely close.
"""

from __future__ import annotations

import numpy as np
import pytest

import robodyn as rd
from robodyn.codegen.kernels import kernel_signature
from robodyn.numeric.model import openmp_flags

KERNELS = ["inverse_dynamics", "mass_matrix", "gravity", "coriolis", "forward_dynamics",
           "state_derivative", "forward_kinematics", "jacobian", "regressor"]


@pytest.fixture(scope="module")
def puma():
    return rd.compile_model(rd.load("puma560"))


def _inputs(model, name, count, seed=0):
    rng = np.random.default_rng(seed)
    return [rng.uniform(-3, 3, (count, w)) for _, w in kernel_signature(name, model.dof)[0]]


@pytest.mark.tool("gcc|cc")
def test_models_are_compiled_with_openmp_when_the_compiler_has_it():
    # gcc here has -fopenmp: threads must really be threads, not a silent single-thread build
    assert "-fopenmp" in openmp_flags()


@pytest.mark.tool("gcc|cc")
@pytest.mark.parametrize("name", KERNELS)
def test_same_bits_for_one_two_and_three_threads(puma, name):
    for count in (17, 1000, 4099):
        args = _inputs(puma, name, count, seed=count)
        one = getattr(puma, name)(*args, threads=1)
        for threads in (2, 3):
            np.testing.assert_array_equal(getattr(puma, name)(*args, threads=threads), one)


def test_thread_count_is_checked():
    model = rd.compile_model(rd.load("planar_2r"), backend="numpy")
    q = np.zeros((3, 2))
    for bad in (0, -1, 1.5, "2", True):
        with pytest.raises(ValueError, match="threads must be a positive integer"):
            model.gravity(q, threads=bad)
    # the NumPy backend takes the argument and computes on one thread: same values
    np.testing.assert_array_equal(model.gravity(q, threads=2), model.gravity(q))
