"""Figures of the calibration simulation study (matplotlib, no display needed)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from robodyn.studies.calibration_study import StudyCase

__all__ = ["save_figures"]


def _figure(width: float, height: float):
    from matplotlib.figure import Figure

    return Figure(figsize=(width, height), layout="constrained")


def save_figures(cases: Sequence[StudyCase], q_test: np.ndarray, test_points: np.ndarray,
                 out_dir: Path) -> tuple[Path, ...]:
    """Write the study's PNG figures into ``out_dir``; returns their paths.

    * ``calibration_histograms.png``: held-out error histograms before and after, per model;
    * ``calibration_workspace.png``: held-out errors over the workspace, before and after;
    * ``calibration_parameters.png``: identified joint parameters minus their true values, with
      95 % confidence intervals;
    * ``calibration_rms.png``: held-out RMS error per model and noise level.
    """
    out_dir.mkdir(parents=True, exist_ok=True)
    paths = []
    sigma0 = min(c.sigma for c in cases)
    first = [c for c in cases if c.sigma == sigma0]

    fig = _figure(3.2 * len(first), 3.0)
    axes = fig.subplots(1, len(first), sharey=True, squeeze=False)[0]
    top = max(c.test_errors_before.max() for c in first) * 1e3
    bins = np.linspace(0, top, 40)
    for ax, c in zip(axes, first, strict=True):
        ax.hist(c.test_errors_before * 1e3, bins=bins, alpha=0.6, label="before")
        ax.hist(c.test_errors_after * 1e3, bins=bins, alpha=0.8, label="after")
        ax.set_title(f"{c.model}, {c.initial} start", fontsize=9)
        ax.set_xlabel("held-out position error / mm")
    axes[0].set_ylabel("poses")
    axes[0].legend()
    paths.append(out_dir / "calibration_histograms.png")
    fig.savefig(paths[-1], dpi=110)

    best = min(first, key=lambda c: c.test_after.rms)
    fig = _figure(9.0, 3.6)
    axes = fig.subplots(1, 2)
    for ax, errs, title in ((axes[0], best.test_errors_before, "before calibration"),
                            (axes[1], best.test_errors_after, f"after ({best.model})")):
        sc = ax.scatter(test_points[:, 0], test_points[:, 1], c=errs * 1e3, s=14, cmap="viridis")
        ax.set_aspect("equal")
        ax.set_title(title)
        ax.set_xlabel("x (tracker) / m")
        ax.set_ylabel("y (tracker) / m")
        fig.colorbar(sc, ax=ax, label="error / mm")
    paths.append(out_dir / "calibration_workspace.png")
    fig.savefig(paths[-1], dpi=110)

    withtrue = [c for c in first if c.true_params is not None and c.model != "poe"
                and c.initial == "nominal"]
    if withtrue:
        c = next((x for x in withtrue if x.model == "hayati"), withtrue[0])
        cal = c.calibration
        rows = [(p, c.true_params[cal.model.index(p.name)]) for p in cal.parameters
                if not p.name.startswith(("base", "tool"))]
        fig = _figure(9.0, 5.0)
        axes = fig.subplots(2, 1)
        for ax, unit, scale, label in ((axes[0], "m", 1e3, "mm"), (axes[1], "rad", 180e3 / math.pi, "mdeg")):
            sel = [(p, t) for p, t in rows if p.unit == unit]
            x = np.arange(len(sel))
            ax.errorbar(x, [(p.value - t) * scale for p, t in sel],
                        yerr=[1.96 * p.std * scale for p, _ in sel], fmt="o", capsize=3)
            ax.axhline(0, color="k", lw=0.8)
            ax.set_xticks(x, [p.name for p, _ in sel], rotation=60, fontsize=7)
            ax.set_ylabel(f"estimate - true / {label}")
        axes[0].set_title(f"{c.model}: identified joint parameters, 95 % confidence intervals "
                          f"(noise {c.sigma * 1e3:.3g} mm, {c.n_poses} poses)")
        paths.append(out_dir / "calibration_parameters.png")
        fig.savefig(paths[-1], dpi=110)

    fig = _figure(6.5, 3.4)
    ax = fig.subplots()
    runs = list(dict.fromkeys((c.model, c.initial) for c in cases))
    sigmas = sorted({c.sigma for c in cases})
    width = 0.8 / len(sigmas)
    for k, s in enumerate(sigmas):
        vals = [next(c.test_after.rms for c in cases if (c.model, c.initial) == r and c.sigma == s) * 1e3
                for r in runs]
        ax.bar(np.arange(len(runs)) + k * width, vals, width, label=f"noise {s * 1e3:.3g} mm")
        ax.axhline(s * math.sqrt(3) * 1e3, ls="--", lw=0.8, color=f"C{k}")
    ax.set_xticks(np.arange(len(runs)) + width * (len(sigmas) - 1) / 2,
                  [f"{m}\n{i}" for m, i in runs], fontsize=8)
    ax.set_yscale("log")
    ax.set_ylabel("held-out RMS error / mm")
    ax.set_title("after calibration (dashed: noise RMS)")
    ax.legend()
    paths.append(out_dir / "calibration_rms.png")
    fig.savefig(paths[-1], dpi=110)
    return tuple(paths)
