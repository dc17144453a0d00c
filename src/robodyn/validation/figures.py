"""Figures of a validation (matplotlib, no display needed): one PNG per view.

Every figure states the noise floor of the target in its title, so an error is always read
against what the measurement itself allows.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from robodyn.validation.validation import Validation

__all__ = ["error_histogram_figure", "friction_figure", "prediction_figure", "spectra_figure",
           "validation_figures"]


def _grid(n: int, width: float = 11.0, height: float = 1.9):
    """A figure of ``n`` panels, two columns from four on, with fixed margins in inches (a
    layout engine lays the figure out twice and took about 40 % of its time)."""
    from matplotlib.figure import Figure

    cols = 2 if n > 3 else 1
    rows = -(-n // cols)
    tall = max(2.6, height * rows)
    fig = Figure(figsize=(width, tall))
    # margins: tick labels and y label on the left, the suptitle on top, an x label below;
    # between rows a panel's x label and the next one's title
    fig.subplots_adjust(left=0.8 / width, right=1.0 - 0.15 / width, bottom=0.5 / tall,
                        top=1.0 - 0.5 / tall, wspace=0.22, hspace=0.6)
    axes = np.atleast_1d(fig.subplots(rows, cols, squeeze=False).ravel())
    for ax in axes[n:]:
        ax.set_visible(False)
    return fig, axes[:n]


def _noise_title(val: Validation) -> str:
    return (f"{val.robot} vs {val.source}: relative error {val.prediction.total_relative:.3f} "
            f"(filtered {val.prediction_filtered.total_relative:.3f}); noise floor "
            f"{val.noise.total_relative:.3f} ({val.noise.cutoff:g} Hz low-pass)")


def prediction_figure(val: Validation, path: Path) -> Path:
    """Measured (raw and filtered) and predicted target against time, one panel per joint.

    Parameters
    ----------
    val : Validation
    path : Path
        PNG to write.

    Returns
    -------
    Path
    """
    fig, axes = _grid(val.dof)
    s = slice(None, None, max(1, len(val.t) // 4000))  # at most ~4000 points per line
    t = val.t[s] - val.t[0]
    for k, ax in enumerate(axes):
        ax.plot(t, val.measured[s, k], color="0.7", lw=0.6, label="measured")
        ax.plot(t, val.filtered[s, k], color="k", lw=0.9, label="measured, filtered")
        ax.plot(t, val.predicted[s, k], color="C3", lw=1.0, label="predicted")
        ax.set_ylabel(f"{val.joint_names[k]} / {val.unit}", fontsize=8)
        ax.set_title(f"rel. {val.prediction.relative[k]:.3f}, noise floor "
                     f"{val.noise.relative[k]:.3f}", fontsize=8)
        ax.tick_params(labelsize=7)
    axes[0].legend(fontsize=7, ncols=3)
    axes[-1].set_xlabel("t / s")
    fig.suptitle(_noise_title(val), fontsize=9)
    return _save(fig, path)


def friction_figure(val: Validation, path: Path) -> Path:
    """Friction curves: the model's friction torque against velocity over the data cloud.

    The cloud is the measured joint torque minus the model's rigid-body and rotor torque at each
    sample: the friction the measurement implies.
    """
    fig, axes = _grid(val.dof, height=2.2)
    for k, ax in enumerate(axes):
        ax.plot(val.friction_velocity[:, k], val.friction_data[:, k], ".", ms=1.5, color="C0",
                alpha=0.35, label="measured - rigid body")
        ax.plot(val.friction_grid[:, k], val.friction_model[:, k], color="C3", lw=1.4,
                label="model friction")
        ax.set_xlabel(f"{val.joint_names[k]} velocity / (rad/s)", fontsize=8)
        ax.set_ylabel("torque / N m", fontsize=8)
        if not val.moving[k]:
            ax.set_title("held still: friction not exercised", fontsize=8)
        ax.tick_params(labelsize=7)
    axes[0].legend(fontsize=7)
    fig.suptitle(_noise_title(val), fontsize=9)
    return _save(fig, path)


def error_histogram_figure(val: Validation, path: Path) -> Path:
    """Histograms of ``predicted - measured`` per joint beside the noise ``measured - filtered``."""
    fig, axes = _grid(val.dof, height=2.0)
    for k, ax in enumerate(axes):
        e = val.predicted[:, k] - val.measured[:, k]
        noise = val.measured[:, k] - val.filtered[:, k]
        if not np.isfinite(e).any():  # a joint without a sensor: nothing to show
            ax.text(0.5, 0.5, "no measurement", ha="center", va="center", transform=ax.transAxes)
            ax.set_xlabel(f"{val.joint_names[k]} / {val.unit}", fontsize=8)
            continue
        lim = max(np.nanmax(np.abs(e)), np.nanmax(np.abs(noise)), 1e-12)
        bins = np.linspace(-lim, lim, 60)
        ax.hist(e, bins=bins, histtype="stepfilled", alpha=0.7, color="C3", label="prediction error")
        ax.hist(noise, bins=bins, histtype="step", color="k", lw=1.0, label="noise (raw - filtered)")
        ax.set_xlabel(f"{val.joint_names[k]} / {val.unit}", fontsize=8)
        ax.tick_params(labelsize=7)
    shown = [ax for ax in axes if ax.get_legend_handles_labels()[0]]
    if shown:
        shown[0].legend(fontsize=7)
    fig.suptitle(_noise_title(val), fontsize=9)
    return _save(fig, path)


def spectra_figure(val: Validation, path: Path) -> Path:
    """Welch spectra of the residual against those of the noise, one panel per joint."""
    from matplotlib.ticker import NullLocator

    fig, axes = _grid(val.dof, height=2.0)
    s = val.spectra
    f = s.frequency[1:]
    for k, ax in enumerate(axes):
        ax.semilogy(f, s.residual[1:, k] + 1e-300, color="C3", lw=1.0, label="residual")
        ax.semilogy(f, s.noise[1:, k] + 1e-300, color="k", lw=0.8, label="noise")
        ax.set_xscale("log")
        # decades only on the PSD axis: its minor ticks were a third of the figure's time
        ax.yaxis.set_minor_locator(NullLocator())
        ax.set_xlabel(f"{val.joint_names[k]}: frequency / Hz", fontsize=8)
        ax.set_ylabel(f"PSD / ({val.unit})²/Hz", fontsize=8)
        ax.tick_params(labelsize=7)
    axes[0].legend(fontsize=7)
    fig.suptitle(_noise_title(val), fontsize=9)
    return _save(fig, path)


def validation_figures(val: Validation, folder: Path, stem: str) -> dict[str, Path]:
    """All figures of ``val`` into ``folder`` as ``<stem>_<kind>.png``; {kind: path}."""
    folder = Path(folder)
    return {
        "prediction": prediction_figure(val, folder / f"{stem}_prediction.png"),
        "friction": friction_figure(val, folder / f"{stem}_friction.png"),
        "errors": error_histogram_figure(val, folder / f"{stem}_errors.png"),
        "spectra": spectra_figure(val, folder / f"{stem}_spectra.png"),
    }


def _save(fig, path: Path) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=100)
    return path
