"""``robodyn cache info`` and ``robodyn cache clear``: the compiled-model cache.

Kept apart from :mod:`robodyn.cli` (which registers it); like the rest of the command line, it
only parses, calls :mod:`robodyn.codegen.build` and prints.
"""

from __future__ import annotations

import argparse

__all__ = ["register"]

# robodyn.codegen.build (and cffi) is imported by the command itself, not to build the parser;
# tests/calibration/test_startup.py checks this against codegen.build.DEFAULT_CACHE_MAX_MB.
DEFAULT_CACHE_MAX_MB = 1024


def _mb(size: int) -> str:
    return f"{size / 2**20:.1f} MB"


def _cmd_cache(args: argparse.Namespace) -> int:
    from robodyn.codegen.build import cache_info, clear_cache

    info = cache_info()
    if args.action == "info":
        print(f"location  {info.path}" + ("" if info.path.is_dir() else " (not created yet)"))
        print(f"entries   {info.entries} compiled libraries ({info.files} files)")
        print(f"size      {_mb(info.size)} ({info.size} bytes) of {_mb(info.limit)} "
              "(limit: $ROBODYN_CACHE_MAX_MB, least recently used files removed beyond it)")
        return 0
    removed, freed = clear_cache()
    print(f"removed {removed} files ({freed} bytes) from {info.path}")
    return 0


def register(sub: argparse._SubParsersAction, fmt: type) -> None:
    """Register ``robodyn cache`` on the main parser's subcommands."""
    p = sub.add_parser(
        "cache", help="show or empty the compiled-model cache", formatter_class=fmt,
        description="The compiled-model cache holds the generated sources and compiled "
                    "libraries of rd.compile_model and the numbers of robot descriptions "
                    "'robodyn calibrate' has loaded (rd_robot_*.json, so that it starts without "
                    "SymPy), keyed by content: $ROBODYN_CACHE, else "
                    "$XDG_CACHE_HOME/robodyn, else ~/.cache/robodyn (mode 0700). Libraries are "
                    "checked against a size and SHA-256 manifest before loading and rebuilt "
                    "when they do not match. Beyond $ROBODYN_CACHE_MAX_MB megabytes (default "
                    f"{DEFAULT_CACHE_MAX_MB}) the least recently used files are removed. "
                    "'info' prints location, entries and size; 'clear' removes robodyn's files "
                    "(nothing else in the folder).",
        epilog="examples:\n  robodyn cache info\n  robodyn cache clear")
    p.add_argument("action", choices=("info", "clear"), help="what to do")
    p.set_defaults(func=_cmd_cache)
