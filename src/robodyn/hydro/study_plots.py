"""Figures, table files and the HTML section of the underwater effect series (matplotlib Agg).

:func:`write_study` writes everything ``robodyn underwater ROBOT -o DIR`` produces::

    effects.csv, effects.md          the table (one row per variant and joint)
    tracking_q.png, tracking_tau.png joint positions and PD torques of the tracked move, per variant
    free_q.png                       the free (torque-free) motion, per variant
    ideal_tau.png                    inverse dynamics along the plan, per variant
    underwater_section.html          an HTML fragment (table and figures) for a larger report
    underwater.html                  the same as a page
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from robodyn.hydro.study import EffectSeries  # noqa: E402
from robodyn.report.html import figure, html_table, page  # noqa: E402

__all__ = ["study_figures", "study_section", "write_study"]

#: Columns shown in the HTML table (all are in the CSV).
_SHOWN = ("variant", "joint", "peak_tau", "rms_tau", "ideal_peak_tau", "effect_peak_tau",
          "rms_error", "settling", "diff_vs_dry", "free_amplitude", "free_diff_vs_dry")


def _per_joint(series: EffectSeries, path: Path, title: str, ylabel: str, pick, *,
               reference: np.ndarray | None = None) -> Path:
    """One subplot per joint, one line per variant; ``pick(run) -> (t, (N, n) values)``."""
    names = series.table["joint"].unique()
    fig, axes = plt.subplots(len(names), 1, figsize=(8, 2.6 * len(names)), sharex=True,
                             squeeze=False)
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
    plt.close(fig)
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
    """An HTML fragment: settings, the table and the (embedded) figures."""
    table = series.table
    rows = [[f"{v:.4g}" if isinstance(v, float) else v for v in row]
            for row in table[list(_SHOWN)].itertuples(index=False)]
    current = ", ".join(f"{c:g}" for c in series.current)
    lift = "the description's" if series.lift is None else f"{series.lift:g}"
    intro = (
        f"<h2>Underwater effect series: {series.robot}</h2>"
        f"<p>Each variant adds one effect to the one before (dry, + buoyancy, + added mass, "
        f"+ drag, + lift, + current). Tracked: a {series.move_time:g} s quintic move held for "
        f"{series.hold_time:g} s under the same PD controller (kp = "
        f"{', '.join(f'{k:.4g}' for k in series.kp)}; kd = {', '.join(f'{k:.4g}' for k in series.kd)}), "
        f"which knows nothing of the water. Free: released at rest for {series.free_time:g} s. "
        f"RK4 at {series.dt:g} s. Current of the last variant ({current}) m/s in the base frame; "
        f"lift coefficient: {lift}. Torques N m (N), positions rad (m), times s; "
        f"effect_peak_tau is the torque this effect adds to the inverse dynamics of the plan.</p>")
    figs = "".join(figure(p, p.stem.replace("_", " ")) for p in figures)
    return intro + html_table(list(_SHOWN), rows) + figs


def write_study(series: EffectSeries, out: str | Path) -> tuple[Path, ...]:
    """Write the table (CSV, markdown), the figures and the HTML fragment and page into ``out``.

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
    fragment, html = out / "underwater_section.html", out / "underwater.html"
    fragment.write_text(section, encoding="utf-8")
    html.write_text(page(f"Underwater effect series: {series.robot}", section), encoding="utf-8")
    return (csv, md, *figures, fragment, html)
