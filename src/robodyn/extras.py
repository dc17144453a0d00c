"""Optional features and the pip extras that install them.

robodyn's core (descriptions, equations, code generation, compiled models, simulation,
recordings from CSV, calibration, identification (its semidefinite programs on cvxpy and
Clarabel included), reports) needs only the
packages in ``pyproject.toml``'s ``dependencies``. These features need an extra::

    study   rd.sweep and robodyn sweep on Dask, Parquet tables   dask[distributed], cloudpickle,
                                                                  pyarrow
    ros     ROS 2 bags (MCAP) in and out                           mcap, mcap-ros2-support

``pip install "robodyn[study,ros]"`` installs them all (``make`` installs ``robodyn[test]``,
which includes every extra). A feature whose extra is missing raises :class:`MissingExtraError`
naming the feature and the command that installs it.
"""

from __future__ import annotations

import importlib
from types import ModuleType

from robodyn.robot.errors import MissingExtraError

__all__ = ["EXTRAS", "MissingExtraError", "require"]

#: Extra of each optional top-level module.
EXTRAS: dict[str, str] = {
    "dask": "study", "distributed": "study", "cloudpickle": "study", "pyarrow": "study",
    "mcap": "ros", "mcap_ros2": "ros", "zstandard": "ros",
}


def require(module: str, feature: str) -> ModuleType:
    """Import ``module`` (an optional dependency) for ``feature``, or say which extra to install.

    Parameters
    ----------
    module : str
        A key of :data:`EXTRAS` (or a submodule of one, e.g. ``"mcap.reader"``).
    feature : str
        What needs it, as the user asked for it (``"rd.sweep"``, ``"method='consistent'"``).

    Returns
    -------
    module

    Raises
    ------
    MissingExtraError
        The module cannot be imported.
    """
    extra = EXTRAS[module.split(".")[0]]
    try:
        return importlib.import_module(module)
    except ImportError as exc:
        raise MissingExtraError(
            f"{feature} needs the '{extra}' extra ({module.split('.')[0]} is not installed: "
            f"{exc}); install it with: pip install 'robodyn[{extra}]'") from exc
