"""Optional dependencies: which pip extra installs each, and one import that says so when missing.

Here, in the description layer, so that the URDF reader (the ``urdf`` extra) can ask for its
parser as the Dask sweeps and the MCAP readers ask for theirs; :mod:`robodyn.extras` is the public
page of the same table.
"""

from __future__ import annotations

import importlib
from types import ModuleType

from robodyn.robot.errors import MissingExtraError

__all__ = ["EXTRAS", "require"]

#: Extra of each optional top-level module.
EXTRAS: dict[str, str] = {
    "dask": "study", "distributed": "study", "cloudpickle": "study", "pyarrow": "study",
    "mcap": "ros", "mcap_ros2": "ros", "zstandard": "ros",
    "yourdfpy": "urdf",
    "jinja2": "report", "markupsafe": "report",
}


def require(module: str, feature: str) -> ModuleType:
    """Import ``module`` (an optional dependency) for ``feature``, or say which extra to install.

    Parameters
    ----------
    module : str
        A key of :data:`EXTRAS` (or a submodule of one, e.g. ``"mcap.reader"``).
    feature : str
        What needs it, as the user asked for it (``"rd.sweep"``, ``"rd.load('arm.urdf')"``).

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
