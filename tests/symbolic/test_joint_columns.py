"""Where each joint's drive parameters sit among the regressor's 15 n columns."""

from __future__ import annotations

import pytest

from robodyn.symbolic.regressor import joint_columns, parameter_names


@pytest.mark.parametrize("j", [0, 1, 5])
def test_joint_columns_name_the_parameters(j):
    names = parameter_names(6)
    assert names[joint_columns(j)] == tuple(f"{p}{j + 1}" for p in ("Ia", "Fv", "Fcp", "Fcn", "Fo"))
    assert names[joint_columns(j, "Fcp", "Fcn")] == (f"Fcp{j + 1}", f"Fcn{j + 1}")
    assert names[joint_columns(j, "Fv")] == tuple(f"{p}{j + 1}" for p in ("Fv", "Fcp", "Fcn", "Fo"))
    with pytest.raises(ValueError):
        joint_columns(j, "XX")
