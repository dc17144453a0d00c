"""``python -m robodyn.cli``: the ``robodyn`` command."""

from robodyn.cli import run

run()
