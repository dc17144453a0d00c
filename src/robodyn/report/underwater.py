"""Figures, table files and the HTML section of the underwater effect series (matplotlib
figures without pyplot: the user's backend is left alone).

:func:`write_study` writes everything ``robodyn underwater ROBOT -o DIR`` produces::

    effects.csv, effects.md          the table (one row per variant and joint)
    tracking_q.png, tracking_tau.png joint positions and PD torques of the tracked move, per variant
    free_q.png                       the free (torque-free) motion, per variant
    ideal_tau.png                    inverse dynamics along the plan, per variant
    sensitivity.csv, sensitivity.png added torque and free decay against C_d and current speed
                                     (when a Sensitivity is given,
                                     :mod:`robodyn.studies.underwater_sensitivity`)
    model_error.csv, model_error.png computed-torque tracking error when the controller's model
                                     omits each effect (a ModelErrorStudy,
                                     :mod:`robodyn.studies.underwater_model_error`)
    underwater_section.html          an HTML fragment (tables and figures) for a larger report
    underwater.html                  the same as a page
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from robodyn.report.html import Markup, figure, html_table, page, render_macro
from robodyn.studies.underwater import EffectSeries
from robodyn.studies.underwater_model_error import ModelErrorStudy
from robodyn.studies.underwater_sensitivity import Sensitivity

__all__ = ["model_error_figure", "model_error_section", "sensitivity_figure",
           "sensitivity_section", "study_figures", "study_section", "write_study"]

#: Columns shown in the HTML table (all are in the CSV).
_SHOWN = ("variant", "joint", "peak_tau", "rms_tau", "ideal_peak_tau", "effect_peak_tau",
          "rms_error", "settling", "diff_vs_dry", "free_amplitude", "free_diff_vs_dry")


def _per_joint(series: EffectSeries, path: Path, title: str, ylabel: str, pick, *,
               reference: np.ndarray | None = None) -> Path:
    """One subplot per joint, one line per variant; ``pick(run) -> (t, (N, n) values)``."""
    names = series.table["joint"].unique()
    fig = Figure(figsize=(8, 2.6 * len(names)))
    axes = fig.subplots(len(names), 1, sharex=True, squeeze=False)
    for run in series.runs:
        t, y = pick(run)
        for i, ax in enumerate(axes[:, 0]):
            ax.plot(t, y[:, i], label=run.label, lw=1.2)
    for i, ax in enumerate(axes[:, 0]):
        if reference is not None:
            ax.plot(series.runs[0].tracked.t, reference[:, i], "k--", lw=1, label="reference")
        ax.set_ylabel(f"{names[i]} {ylabel}")
        ax.grid(alpha=0.3)
    axes[0, 0].set_title(title)
    axes[0, 0].legend(fontsize=8, ncol=2)
    axes[-1, 0].set_xlabel("time, s")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    return path


def study_figures(series: EffectSeries, out: str | Path) -> tuple[Path, ...]:
    """Write the four figures of the series into ``out`` (created); returns their paths."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    ref = series.reference.at(series.runs[0].tracked.t)[0]
    name = series.robot
    return (
        _per_joint(series, out / "tracking_q.png", f"{name}: PD-tracked move, each effect added",
                   "q", lambda r: (r.tracked.t, r.tracked.q), reference=ref),
        _per_joint(series, out / "tracking_tau.png", f"{name}: PD torque of the tracked move",
                   "tau", lambda r: (r.tracked.t, r.tracked.tau)),
        _per_joint(series, out / "free_q.png", f"{name}: free motion from rest (no torque)", "q",
                   lambda r: (r.free.t, r.free.q)),
        _per_joint(series, out / "ideal_tau.png",
                   f"{name}: inverse dynamics along the plan (exact tracking)", "tau",
                   lambda r: (r.tracked.t, r.ideal_tau)),
    )


def study_section(series: EffectSeries, figures: tuple[Path, ...] = ()) -> str:
    """An HTML fragment: settings, the table and the (embedded) figures
    (``templates/underwater.html.j2``)."""
    rows = [[f"{v:.4g}" if isinstance(v, float) else v for v in row]
            for row in series.table[list(_SHOWN)].itertuples(index=False)]
    return render_macro("underwater.html.j2", "series_section", s=series,
                        table=Markup(html_table(list(_SHOWN), rows)), notes=series.notes,
                        figures=_figures(figures))


def _figures(paths: tuple[Path, ...]) -> Markup:
    """The embedded figures of ``paths``, each captioned by its file name."""
    return Markup("".join(figure(p, p.stem.replace("_", " ")) for p in paths))


def _rows(table, digits: int = 4) -> list[list]:
    return [[f"{v:.{digits}g}" if isinstance(v, float) else v for v in row]
            for row in table.itertuples(index=False)]


def sensitivity_figure(sens: Sensitivity, path: Path) -> Path:
    """Added peak torque against each swept value, and the free runs of each case."""
    table = sens.table
    joints = table["joint"].unique()
    fig = Figure(figsize=(10, 6.5))
    axes = fig.subplots(2, 2, squeeze=False)
    for row, (name, unit) in enumerate((("C_d", ""), ("current", ", m/s"))):
        part = table[table["parameter"] == name]
        ax = axes[row, 0]
        for joint in joints:
            sel = part[part["joint"] == joint]
            ax.plot(sel["value"], sel["added_peak_tau"], "o-", label=f"{joint} peak")
            ax.plot(sel["value"], sel["added_rms_tau"], "s--", label=f"{joint} RMS")
        ax.set_xlabel(f"{name}{unit}")
        ax.set_ylabel("torque the fluid adds, N m")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
        ax = axes[row, 1]
        for (kind, value), run in sens.free.items():
            if kind == name:
                ax.plot(run.t, run.q[:, 0], label=f"{name} = {value:g}", lw=1.2)
        ax.set_xlabel("time, s")
        ax.set_ylabel(f"free motion {joints[0]}, rad")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    axes[0, 0].set_title(f"{sens.robot}: sensitivity to C_d (still water)")
    axes[1, 0].set_title(f"{sens.robot}: sensitivity to the current speed")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    return path


def sensitivity_section(sens: Sensitivity, figures: tuple[Path, ...] = ()) -> str:
    """An HTML fragment: what was swept, the table and the figure."""
    table = Markup(html_table(list(sens.table.columns), _rows(sens.table)))
    return render_macro("underwater.html.j2", "sensitivity_section", direction=sens.direction,
                        table=table, figures=_figures(figures))


def model_error_figure(study: ModelErrorStudy, path: Path) -> Path:
    """Tracking error q_ref - q per joint, one line per omitted effect (symmetric log scale)."""
    names = study.table["joint"].unique()
    fig = Figure(figsize=(8, 2.8 * len(names)))
    axes = fig.subplots(len(names), 1, sharex=True, squeeze=False)
    for effect, run in study.runs.items():
        err = study.reference.at(run.t)[0] - run.q
        for i, ax in enumerate(axes[:, 0]):
            ax.plot(run.t, err[:, i], label=f"omits {effect}", lw=1.2)
    for i, ax in enumerate(axes[:, 0]):
        ax.set_yscale("symlog", linthresh=1e-4)
        ax.set_ylabel(f"{names[i]} error, rad")
        ax.grid(alpha=0.3)
    axes[0, 0].set_title(f"{study.robot}: computed torque on the full plant, model omitting one "
                         "effect")
    axes[0, 0].legend(fontsize=8, ncol=2)
    axes[-1, 0].set_xlabel("time, s")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    return path


def model_error_section(study: ModelErrorStudy, figures: tuple[Path, ...] = ()) -> str:
    """An HTML fragment: the controller-design question, its table and figure."""
    table = Markup(html_table(list(study.table.columns), _rows(study.table)))
    return render_macro("underwater.html.j2", "model_error_section", st=study, table=table,
                        figures=_figures(figures))


def write_study(series: EffectSeries, out: str | Path, sensitivity: Sensitivity | None = None,
                model_error: ModelErrorStudy | None = None) -> tuple[Path, ...]:
    """Write the table (CSV, markdown), the figures and the HTML fragment and page into ``out``.

    ``sensitivity`` and ``model_error``, when given, add their CSV, figure and section.

    Returns
    -------
    tuple of Path
        Every file written.
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    csv, md = out / "effects.csv", out / "effects.md"
    series.table.to_csv(csv, index=False)
    md.write_text(series.markdown(), encoding="utf-8")
    figures = study_figures(series, out)
    section = study_section(series, figures)
    extra: list[Path] = []
    if sensitivity is not None:
        files = (out / "sensitivity.csv", sensitivity_figure(sensitivity, out / "sensitivity.png"))
        sensitivity.table.to_csv(files[0], index=False)
        section += sensitivity_section(sensitivity, files[1:])
        extra += files
    if model_error is not None:
        files = (out / "model_error.csv", model_error_figure(model_error, out / "model_error.png"))
        model_error.table.to_csv(files[0], index=False)
        section += model_error_section(model_error, files[1:])
        extra += files
    fragment, html = out / "underwater_section.html", out / "underwater.html"
    fragment.write_text(section, encoding="utf-8")
    html.write_text(page(f"Underwater effect series: {series.robot}", section), encoding="utf-8")
    return (csv, md, *figures, *extra, fragment, html)
