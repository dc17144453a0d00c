"""Report section of a parameter study: summary table, failed cases and figures (HTML fragment).

Figures: a heat map of a result over two parameters when the cases form a full grid in them
(a scatter coloured by the result otherwise), the result against the parameter when one varies,
and a histogram of the result over the cases (the Monte-Carlo view).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from robodyn.report.html import Markup, figure, html_table, render

__all__ = ["result_columns", "study_figures", "study_section"]

_NOT_RESULTS = ("error", "seed", "repeat")


def result_columns(table: pd.DataFrame, parameters: Sequence[str]) -> list[str]:
    """Numeric result columns of a study table (not parameters, seed or error)."""
    case_cols = set(parameters)
    return [c for c in table.columns if c not in case_cols and c not in _NOT_RESULTS
            and pd.api.types.is_numeric_dtype(table[c]) and not pd.api.types.is_bool_dtype(table[c])]


def _numeric(table: pd.DataFrame, name: str) -> bool:
    return name in table and pd.api.types.is_numeric_dtype(table[name])


def study_figures(table: pd.DataFrame, varying: Sequence[str], directory: str | Path,
                  plot: Mapping[str, str] | None = None) -> tuple[Path, ...]:
    """Save the study's figures as PNG files in ``directory``; their paths.

    Parameters
    ----------
    table : pandas.DataFrame
        From :func:`robodyn.sweep`.
    varying : sequence of str
        Parameters that take several values (the figure axes, first two by default).
    directory : str or Path
    plot : mapping, optional
        ``x``, ``y``, ``result`` column names overriding the defaults.
    """
    from matplotlib.figure import Figure

    plot = dict(plot or {})
    ok = table[table["error"].isna()] if "error" in table else table
    results = result_columns(table, [c for c in table.columns if c in varying or c in plot.values()])
    result = plot.get("result") or (results[0] if results else None)
    out = Path(directory)
    out.mkdir(parents=True, exist_ok=True)
    paths: list[Path] = []
    if result is None or result not in ok or ok.empty:
        return ()
    axes = [a for a in (plot.get("x"), plot.get("y")) if a] or [v for v in varying if _numeric(ok, v)][:2]
    if len(axes) >= 2 and all(_numeric(ok, a) for a in axes[:2]):
        x, y = axes[:2]
        fig = Figure(figsize=(6, 4.5))
        ax = fig.subplots()
        grid = ok.groupby([y, x])[result].mean().unstack(x)
        if len(ok) == grid.size and not grid.isna().to_numpy().any():
            # a full grid: heat map of the result (cell = one case)
            mesh = ax.imshow(grid.to_numpy(), origin="lower", aspect="auto", cmap="viridis")
            ax.set_xticks(range(grid.shape[1]), [f"{v:g}" for v in grid.columns])
            ax.set_yticks(range(grid.shape[0]), [f"{v:g}" for v in grid.index])
        else:
            mesh = ax.scatter(ok[x], ok[y], c=ok[result], cmap="viridis", s=30)
        fig.colorbar(mesh, ax=ax, label=result)
        ax.set_xlabel(x)
        ax.set_ylabel(y)
        ax.set_title(f"{result} over {x} and {y}")
        paths.append(out / "study_map.png")
        fig.tight_layout()
        fig.savefig(paths[-1], dpi=100)
    elif len(axes) == 1 and _numeric(ok, axes[0]):
        fig = Figure(figsize=(6, 4))
        ax = fig.subplots()
        ax.plot(ok[axes[0]], ok[result], "o")
        ax.set_xlabel(axes[0])
        ax.set_ylabel(result)
        paths.append(out / "study_curve.png")
        fig.tight_layout()
        fig.savefig(paths[-1], dpi=100)
    # the distribution of the result over the cases (Monte Carlo)
    fig = Figure(figsize=(6, 4))
    ax = fig.subplots()
    ax.hist(ok[result].to_numpy(dtype=float), bins=max(5, min(50, len(ok) // 4)))
    ax.set_xlabel(result)
    ax.set_ylabel("cases")
    ax.set_title(f"{result}: {len(ok)} cases")
    paths.append(out / "study_histogram.png")
    fig.tight_layout()
    fig.savefig(paths[-1], dpi=100)
    return tuple(paths)


def study_section(table: pd.DataFrame, *, title: str, varying: Sequence[str],
                  figures: Sequence[Path] = (), source: str = "") -> str:
    """The study's report section as an HTML fragment (values escaped; figures embedded).

    Parameters
    ----------
    table : pandas.DataFrame
        From :func:`robodyn.sweep`.
    title : str
    varying : sequence of str
        Parameters that vary.
    figures : sequence of Path
        From :func:`study_figures`.
    source : str
        The study file (shown).
    """
    failed = table[table["error"].notna()] if "error" in table else table.iloc[:0]
    rows = []
    ok = table.drop(index=failed.index)
    for col in result_columns(table, varying):
        v = ok[col].to_numpy(dtype=float)
        if v.size:
            rows.append([col, f"{np.min(v):.4g}", f"{np.median(v):.4g}", f"{np.max(v):.4g}"])
    results = Markup(html_table(["result", "min", "median", "max"], rows)) if rows else ""
    failures = ""
    if len(failed):
        shown = [[int(i), str(m)] for i, m in failed["error"].head(10).items()]
        failures = Markup(html_table(["case", "error"], shown))
    return render("study.html.j2", title=title, cases=len(table), source=source,
                  failed=len(failed), varying=list(varying), results=results, failures=failures,
                  figures=[Markup(figure(p, Path(p).stem.replace("_", " "))) for p in figures],
                  ).rstrip("\n")
