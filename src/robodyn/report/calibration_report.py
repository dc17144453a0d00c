"""HTML reports of kinematic calibration: one measured calibration, and the simulation study."""

from __future__ import annotations

import html
import math
from pathlib import Path

import numpy as np

from robodyn.calibration.result import Calibration, ErrorStats
from robodyn.report.html import Markup, figure, html_table, page, render
from robodyn.studies.calibration_study import StudyResult

__all__ = ["calibration_figure", "calibration_html", "study_section"]


def calibration_figure(cal: Calibration, path: Path, validation: np.ndarray | None = None) -> Path:
    """Distance errors before/after (histogram) and residual components per pose.

    Parameters
    ----------
    cal : Calibration
    path : Path
        PNG file to write.
    validation : numpy.ndarray, optional, shape (K, 3)
        Residuals on held-out poses after calibration, m (drawn in the histogram when given).

    Returns
    -------
    Path
    """
    from matplotlib.figure import Figure

    res = cal.residuals.reshape(-1, 3)  # (N, 3), or (N K, 3) for several targets per pose
    before = np.linalg.norm(cal.before_residuals.reshape(-1, 3), axis=1) * 1e3
    after = np.linalg.norm(res, axis=1) * 1e3
    # fixed margins: a layout engine would draw the figure twice (a third of the command's
    # time after the solve)
    fig = Figure(figsize=(10.0, 3.6))
    fig.subplots_adjust(left=0.07, right=0.99, bottom=0.14, top=0.92, wspace=0.25)
    ax0, ax1 = fig.subplots(1, 2)
    bins = np.linspace(0, max(before.max(), after.max()) * 1.02 + 1e-12, 40)
    ax0.hist(before, bins=bins, alpha=0.6, label="before")
    ax0.hist(after, bins=bins, alpha=0.8, label="after")
    if validation is not None and len(validation):
        ax0.hist(np.linalg.norm(validation, axis=1) * 1e3, bins=bins, histtype="step", lw=1.5,
                 color="k", label="held-out, after")
    ax0.set_xlabel("position error / mm")
    ax0.set_ylabel("poses")
    ax0.legend()
    ax0.set_title(f"{cal.model.name} model, {cal.pose_count} poses")
    k = np.arange(len(res))
    for j, lab in enumerate("xyz"):
        ax1.plot(k, res[:, j] * 1e3, ".", ms=3, label=f"d{lab}")
    ax1.axhspan(-2 * cal.sigma * 1e3, 2 * cal.sigma * 1e3, color="0.85", zorder=0,
                label="±2σ measurement")
    ax1.set_xlabel("pose")
    ax1.set_ylabel("residual after / mm")
    ax1.legend(fontsize=7, ncols=4)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    return path


def _stats_rows(rows: list[tuple[str, ErrorStats]]) -> list[list[object]]:
    return [[name, s.count, f"{s.mean * 1e3:.4f}", f"{s.rms * 1e3:.4f}", f"{s.max * 1e3:.4f}",
             f"{s.std * 1e3:.4f}"] for name, s in rows]


_STATS_HEADERS = ("poses", "count", "mean / mm", "RMS / mm", "max / mm", "std / mm")


def calibration_html(cal: Calibration, path: Path, *, source: str = "",
                     validation: tuple[str, np.ndarray] | None = None) -> Path:
    """Write a one-page HTML report of ``cal`` (with its figure beside it) to ``path``.

    Parameters
    ----------
    cal : Calibration
    path : Path
        The ``.html`` file; the figure is written next to it as ``<stem>.png``.
    source : str
        Where the measurements came from (shown in the report).
    validation : (str, numpy.ndarray), optional
        Name of a held-out data set and its residuals after calibration, shape (K, 3), m.

    Returns
    -------
    Path
    """
    held = validation[1] if validation else None
    fig = calibration_figure(cal, path.with_suffix(".png"), held)
    stats = [("calibration poses, before", cal.before), ("calibration poses, after", cal.after)]
    if validation:
        stats.append((f"held-out ({validation[0]}), after", ErrorStats.from_residuals(held)))
    params = []
    for p in cal.parameters:
        scale, unit = (1e3, "mm") if p.unit == "m" else (180 / math.pi, "deg")
        params.append([p.name, f"{p.initial * scale:.6f}", f"{p.value * scale:.6f}",
                       f"{p.std * scale:.3g}", unit])
    obs = ", ".join(f"{k} {v:.4g}" for k, v in cal.observability.as_dict().items())
    # templates/calibration.html.j2; the tables and the figure are trusted fragments
    body = render("calibration.html.j2", cal=cal, source=source or "", observability=obs,
                  stats_table=Markup(html_table(_STATS_HEADERS, _stats_rows(stats))),
                  figure=Markup(figure(fig, "errors before and after")),
                  parameter_table=Markup(html_table(("parameter", "initial", "estimate", "std",
                                                     "unit"), params)))
    path.write_text(page(f"robodyn calibration: {cal.robot.name}", body), encoding="utf-8")
    return path


def study_section(study: StudyResult, folder: str) -> str:
    """The demo report's section on the PUMA 560 calibration simulation study.

    Parameters
    ----------
    study : StudyResult
    folder : str
        The figures' folder relative to the report page.
    """
    rows = []
    for c in study.cases:
        noise_rms = c.sigma * math.sqrt(3)
        rows.append([c.model, c.initial, f"{c.sigma * 1e3:.3f}", c.n_poses,
                     f"{c.test_before.rms * 1e3:.4f}", f"{c.test_after.rms * 1e3:.4f}",
                     f"{c.test_after.max * 1e3:.4f}", f"{c.test_after_true.rms * 1e3:.4f}",
                     f"{c.test_after.rms / noise_rms:.3f}"])
    headers = ("model", "initial", "noise / mm", "poses", "before RMS / mm", "after RMS / mm",
               "after max / mm", "vs truth RMS / mm", "after / noise RMS")
    imgs = "".join(figure(p, p.stem) for p in study.figures)
    notes = "".join(f"<li>{html.escape(n)}</li>" for n in study.notes)
    n_test = len(study.test_q)
    return f"""<h2>Kinematic calibration of the PUMA 560 (simulation study, chapter 4)</h2>
<p>A "true" PUMA 560 with manufacturing errors (about 1 mm in lengths and offsets, 0.1 degree in
angles, joint zero offsets) measured by a tracker with 0.05 mm noise per coordinate (a laser
tracker) and 0.1 mm (the thesis' Optotrac); the instrument placement and the target on the last
link are unknown. Errors are on {n_test} held-out poses, against the noisy measurements and
against the noise-free truth; "after / noise RMS" near 1 means the model explains everything but
the noise.</p>
{html_table(headers, rows)}
<ul>{notes}</ul>
{imgs}
<p><code>robodyn calibrate ROBOT --data poses.csv --model s-model -o DIR</code> runs the same on
measured data.</p>"""
