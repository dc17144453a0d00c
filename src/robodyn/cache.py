"""robodyn's cache folder: compiled models, their sources and the numbers of loaded descriptions.

Kept apart from :mod:`robodyn.codegen.build` (which compiles into it and manages its size) so
that a command that only reads the cache, such as ``robodyn calibrate`` on a robot whose numbers
are cached (:mod:`robodyn.robot.numbers_cache`), imports neither cffi nor the code generators.
"""

from __future__ import annotations

import os
from pathlib import Path

__all__ = ["cache_dir"]


def cache_dir(*, create: bool = True) -> Path:
    """The compiled-model cache directory.

    Parameters
    ----------
    create : bool
        Create it (mode 0700: other users can neither read nor plant libraries) when missing;
        the default folder (not ``$ROBODYN_CACHE``) is also made 0700 when it is open to others.

    Returns
    -------
    Path
    """
    root = os.environ.get("ROBODYN_CACHE")
    if root:
        path = Path(root)
    else:
        base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
        path = Path(base) / "robodyn"
    if create and not path.is_dir():
        path.mkdir(mode=0o700, parents=True, exist_ok=True)
        os.chmod(path, 0o700)  # mkdir's mode is filtered by the umask
    elif create and not root:
        # the default folder is robodyn's own: one an older version left open is closed
        st = path.stat()
        if st.st_mode & 0o077 and st.st_uid == os.getuid():
            os.chmod(path, 0o700)
    return path
