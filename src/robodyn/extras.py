"""Optional features and the pip extras that install them.

robodyn's core (descriptions in YAML and the built-in robots, equations, code generation,
compiled models, simulation, recordings from CSV, calibration, identification (its semidefinite
programs on cvxpy and Clarabel included), reports, URDF and MJCF export) needs only the packages
in ``pyproject.toml``'s ``dependencies``. These features need an extra::

    study   rd.sweep and robodyn sweep on Dask, Parquet tables   dask[distributed], cloudpickle,
                                                                  pyarrow
    ros     ROS 2 bags (MCAP) in and out                           mcap, mcap-ros2-support
    urdf    reading URDF files (rd.load('arm.urdf'))              yourdfpy (and trimesh)

``pip install "robodyn[study,ros,urdf]"`` installs them all (``make`` installs ``robodyn[test]``,
which includes every extra). A feature whose extra is missing raises :class:`MissingExtraError`
naming the feature and the command that installs it. The table and :func:`require` live in
:mod:`robodyn.robot.optional` (the lowest layer, where the URDF reader needs them).
"""

from __future__ import annotations

from robodyn.robot.errors import MissingExtraError
from robodyn.robot.optional import EXTRAS, require

__all__ = ["EXTRAS", "MissingExtraError", "require"]
