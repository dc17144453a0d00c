"""HTML of identification and validation: parameter tables, validation sections, Kinova Gen3 demo.

Each function returns an HTML fragment (and writes its figures next to it), so the reports and
the demo page can place them wherever they like.
"""

from __future__ import annotations

import html
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from robodyn.identification.coulomb_width import HOLD_SECONDS, HOLD_SPEED
from robodyn.report.html import Markup, figure, html_table, page, render, render_macro
from robodyn.validation.validation import Validation

__all__ = ["KINOVA_CONTROLLER_GAINS", "combined_relative", "identification_html",
           "kinova_section", "parameter_table", "validation_html", "validation_section"]

#: The Kinova controller's torque per ampere (``TorqueCur = k Cur``, see the data README), N m/A.
KINOVA_CONTROLLER_GAINS = np.array([9.13, 9.13, 9.13, 9.13, 5.852, 5.852, 5.852])
#: The README's baseline on the last 30 % of the whole-arm runs: raw and filtered current.
KINOVA_BASELINE = (0.32, 0.22)


def combined_relative(vals: Sequence[Validation], filtered: bool = False,
                      joints: Sequence[int] | None = None) -> float:
    """``||E|| / ||Y||`` over several validations together (Frobenius norms, joints with data).

    Parameters
    ----------
    vals : sequence of Validation
    filtered : bool
        Against the filtered target instead of the raw one.
    joints : sequence of int, optional
        Only these joints (default: all).
    """
    num = den = 0.0
    for v in vals:
        y = v.filtered if filtered else v.measured
        cols = list(range(v.dof)) if joints is None else list(joints)
        e, yy = (v.predicted - y)[:, cols], y[:, cols]
        has = ~np.all(np.isnan(yy), axis=0)
        num += float(np.sum(e[:, has] ** 2))
        den += float(np.sum(yy[:, has] ** 2))
    return float(np.sqrt(num / den)) if den > 0 else float("nan")


def validation_section(val: Validation, out: Path, folder: str, stem: str, heading: str,
                       kinds: Sequence[str] = ("prediction", "friction", "errors", "spectra"),
                       level: int = 3) -> str:
    """One validation as HTML: per-joint table, noise floor, figures (written to ``out/folder``).

    Parameters
    ----------
    val : Validation
    out : Path
        The report's folder.
    folder : str
        Sub-folder of ``out`` for the figures (relative links).
    stem : str
        File name stem of the figures.
    heading : str
    kinds : sequence of {"prediction", "friction", "errors", "spectra"}
        Figures to draw.
    level : int
        HTML heading level.
    """
    from robodyn.validation import figures

    draw = {"prediction": figures.prediction_figure, "friction": figures.friction_figure,
            "errors": figures.error_histogram_figure, "spectra": figures.spectra_figure}
    imgs = []
    for kind in kinds:
        path = draw[kind](val, out / folder / f"{stem}_{kind}.png")
        imgs.append(figure(path, kind))
    sim = ""
    if val.simulation is not None:
        s = val.simulation
        sim = (f" Simulation: {len(s.starts)} windows of {s.window:g} s from the measured state, "
               f"driven by the measured torque (RK4 at {s.dt * 1e3:.3g} ms); drift = median "
               f"|q<sub>sim</sub> &minus; q<sub>meas</sub>| at the end of a window, beside the "
               f"drift of a constant-velocity guess" + (f"; {s.failed} windows failed" if s.failed
                                                        else "") + ".")
    table = html_table(val.table_headers(), val.table_rows())
    return _macro("validation_section", val=val, heading=heading, level=level,
                  samples=len(val.t), span=val.t[-1] - val.t[0], simulation=Markup(sim),
                  table=Markup(table), figures=Markup("".join(imgs)))


def _macro(name: str, **arguments: object) -> str:
    """The fragment ``name`` of ``templates/identification.html.j2``."""
    return render_macro("identification.html.j2", name, **arguments)


def parameter_table(ident: Any) -> str:
    """The identified base parameters with standard deviations, as an HTML table."""
    bp = ident.base_parameters
    rows = []
    for i, name in enumerate(bp.names):
        rows.append([name, f"{bp.values[i]:.6g}", f"{bp.std[i]:.3g}",
                     f"{bp.relative_std[i]:.3g}", f"{bp.nominal[i]:.6g}",
                     "yes" if bp.identifiable[i] else "NO", str(bp.relations[i])])
    headers = ("parameter", "estimate", "std", "rel. std / %", "description", "excited",
               "combination of standard parameters")
    return html_table(headers, rows)


def identification_html(ident: Any, validations: Sequence[tuple[str, Validation]], out: Path,
                        sources: Sequence[str], name: str = "report.html") -> Path:
    """Write the HTML report of an identification and its validations into ``out``.

    Parameters
    ----------
    ident : Identification
    validations : sequence of (str, Validation)
        Heading and result, e.g. the training runs and the held-out ``--validate`` runs.
    out : Path
    sources : sequence of str
        The identification data files.
    name : str
        File name of the page.
    """
    sections = "\n".join(validation_section(v, out, "figures", f"val{i}_{_slug(v.source)}", head)
                         for i, (head, v) in enumerate(validations))
    body = _macro("identification_body", ident=ident, sources=list(sources),
                  cutoff=_cutoff(ident), gains=", ".join(f"{g:.4g}" for g in ident.gains),
                  choices=Markup(_choices_html(ident)), parameters=Markup(parameter_table(ident)),
                  sections=Markup(sections))
    path = out / name
    path.write_text(page(f"robodyn identification: {ident.robot.name}", body), encoding="utf-8")
    return path


def validation_html(val: Validation, out: Path, name: str = "validation.html") -> Path:
    """Write a one-page HTML report of one validation (figures in ``out/figures``)."""
    body = (f"<h1>Validation of {html.escape(val.robot)}</h1>\n"
            + validation_section(val, out, "figures", _slug(val.source), "Measured against model",
                                 level=2))
    path = out / name
    path.write_text(page(f"robodyn validation: {val.robot}", body), encoding="utf-8")
    return path


def _choices_html(ident: Any) -> str:
    """The preprocessing chosen from the data and every candidate's held-out score
    (``templates/choices.html.j2``)."""
    ch = getattr(ident, "choices", None)
    if ch is None:
        return ""
    chosen = None if ch.chosen is None else ch.chosen.key
    table = ""
    if len(ch.candidates) > 1:
        table = html_table(["candidate", "held-out blocks, relative", "best weight", ""],
                           [(c.label, f"{c.score:.4f}", f"{c.lam:g}", "chosen" if c.key == chosen else "")
                            for c in ch.candidates])
    width = np.atleast_1d(getattr(ident, "coulomb_width", 0.0))
    widths = ", ".join(f"{w:.2g}" for w in width) if np.any(width) else ""
    return render("choices.html.j2", ch=ch, cutoff=_cutoff(ident), table=Markup(table),
                  widths=widths, hold_speed=f"{HOLD_SPEED:g}", hold_seconds=f"{HOLD_SECONDS:g}",
                  scores=lambda pairs: ", ".join(f"{k} {v:.4f}" for k, v in pairs))


def _cutoff(ident: Any) -> str:
    c = getattr(getattr(ident, "preprocess", None), "cutoff", None)
    return "none" if c is None else f"{c:.3g} Hz"


def _slug(text: str) -> str:
    stem = Path(text).name.split(".")[0] or "recording"
    return "".join(c if c.isalnum() or c in "-_" else "_" for c in stem)


# ----------------------------------------------------------------------------------------------
# Kinova Gen3 demo section
# ----------------------------------------------------------------------------------------------


def kinova_section(out: Path, data_dir: Path | None = None, method: str = "consistent",
                   friction_models: Sequence[str] = ("none", "linear", "stribeck", "load",
                                                     "polynomial")) -> tuple[str, bool]:
    """The demo's Kinova Gen3 section: identify on whole-arm runs, validate on held-out data.

    Identification on the first 70 % of each whole-arm run (``identification_data``), validation
    on the last 30 % of each and on every jointwise run (``jointwise_motion``; errors of the
    moving joint), beside the manufacturer's URDF model with the controller's current-to-torque
    gains, and a per-joint table against the URDF's parameters.

    Parameters
    ----------
    out : Path
        The demo's folder; figures go to ``out/kinova``.
    data_dir : Path, optional
        The recordings (default: ``../shared/data/kinova-gen3`` beside the repository root).
    method : {"ols", "wls", "consistent"}
        The estimator (default: rd.identify's, the physically consistent one).
    friction_models : sequence of str
        Friction models whose held-out error is tabulated (each identified anew with the main
        fit's velocity source, cut-off, dead band and Tikhonov weight; empty: no table).

    Returns
    -------
    (str, bool)
        The HTML section, and whether it ran (True also when the data are absent: it says so).
    """
    from robodyn.identification.pipeline import identify
    from robodyn.numeric.model import compile_model
    from robodyn.robot.load import load
    from robodyn.text import progress

    data_dir = Path(data_dir) if data_dir is not None else _default_data_dir()
    runs = sorted((data_dir / "identification_data").glob("*.csv.gz"))
    jointwise = sorted((data_dir / "jointwise_motion").glob("joint_*_trapez.csv.gz"))
    if not runs:
        return _macro("kinova_missing", data_dir=str(data_dir)), True
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the URDF's plausibility notes are shown by 'robodyn show'
        robot = load("kinova_gen3")
        model = compile_model(robot)
        train, test = _split_runs(runs, robot)
        with progress(f"Kinova Gen3: identify ({method}, current) on the first 70 % of "
                      f"{len(runs)} whole-arm runs"):
            ident = identify(robot, train, target="current", method=method)
        friction_html = ""
        if friction_models:
            from robodyn.identification.friction_comparison import friction_table

            # the main fit's processing for every law, so that the law alone differs (and
            # each fit skips the processing's cross-validation: half the time)
            with progress(f"Kinova Gen3: held-out error of {len(friction_models)} friction models"):
                ft = friction_table(robot, train, test, models=friction_models, target="current",
                                    method=method, model=model, like=ident)
            friction_html = _friction_html(ft, robot.joint_names)
        folder = out / "kinova"
        held_id, held_urdf, jw_id, jw_urdf, parts = _validations(out, robot, model, ident, test,
                                                                 jointwise)
        folder.mkdir(parents=True, exist_ok=True)
    raw, filt = combined_relative(held_id), combined_relative(held_id, filtered=True)
    raw_u, filt_u = combined_relative(held_urdf), combined_relative(held_urdf, filtered=True)
    noise = float(np.sqrt(sum(np.nansum((v.measured - v.filtered) ** 2) for v in held_id)
                          / sum(np.nansum(v.measured**2) for v in held_id)))
    base_raw, base_filt = KINOVA_BASELINE
    summary = [["identified (" + method + ")", f"{raw:.3f}", f"{filt:.3f}", f"{noise:.3f}",
                _verdict(raw, filt)],
               ["manufacturer URDF", f"{raw_u:.3f}", f"{filt_u:.3f}", f"{noise:.3f}",
                _verdict(raw_u, filt_u)]]
    scale = _gravity_scale(compile_model(ident.robot), model, np.vstack([r.q for r in test]))
    joint_rows = [_joint_row(j, robot, ident, held_id, held_urdf, jw_id.get(j), jw_urdf.get(j),
                             scale[j]) for j in range(robot.dof)]
    line = (f"Kinova Gen3 held-out relative current error: identified ({method}) {raw:.4f} "
            f"(filtered {filt:.4f}), manufacturer {raw_u:.4f} (filtered {filt_u:.4f}); noise floor "
            f"{noise:.4f}; README baseline {base_raw} ({base_filt} filtered)")
    (folder / "summary.txt").write_text(line + "\n", encoding="utf-8")
    print(line)
    summary_table = html_table(("model", "relative error (raw)", "against filtered", "noise floor",
                                f"vs README baseline {base_raw} / {base_filt}"), summary)
    section = _macro("kinova_section", data_dir=str(data_dir), method=method,
                     runs=[p.name for p in runs], ident=ident, cutoff=held_id[0].noise.cutoff,
                     summary=Markup(summary_table),
                     joints=Markup(html_table(_JOINT_HEADERS, joint_rows)),
                     friction=Markup(friction_html), parameters=Markup(parameter_table(ident)),
                     parts=Markup("".join(parts)))
    return section, True


def _split_runs(runs: Sequence[Path], robot: Any) -> tuple[list[Any], list[Any]]:
    """Each whole-arm run read and cut at 70 % of its duration: (first parts, last parts)."""
    from robodyn.measure.read import read_recording

    train, test = [], []
    for path in runs:
        rec = read_recording(path, spec="kinova_gen3", robot=robot)
        cut = rec.t[0] + 0.7 * (rec.t[-1] - rec.t[0])
        train.append(rec.slice(rec.t[0], cut))
        test.append(rec.slice(cut, rec.t[-1]))
    return train, test


def _validations(out: Path, robot: Any, model: Any, ident: Any, test: Sequence[Any],
                 jointwise: Sequence[Path]) -> tuple[list[Validation], list[Validation],
                                                     dict[int, Validation], dict[int, Validation],
                                                     list[str]]:
    """Identified and manufacturer models validated on the held-out parts and jointwise runs.

    Returns (held-out identified, held-out URDF, jointwise identified by joint index, jointwise
    URDF by joint index, HTML parts with the identified model's figures).
    """
    from robodyn.measure.read import read_recording
    from robodyn.text import progress
    from robodyn.validation.validation import validate

    gains = KINOVA_CONTROLLER_GAINS
    held_id, held_urdf, parts = [], [], []
    jw_id: dict[int, Validation] = {}
    jw_urdf: dict[int, Validation] = {}
    with progress("Kinova Gen3: validating on the held-out 30 % and the jointwise runs"):
        for rec in test:
            v_id = validate(ident.robot, rec, "current", ident=ident)
            held_id.append(v_id)
            held_urdf.append(validate(robot, rec, "current", model=model, gains=gains))
            parts.append(validation_section(v_id, out, "kinova", f"heldout_{_slug(rec.source)}",
                                            f"Held-out last 30 % of {rec.source}, identified "
                                            "model", kinds=("prediction", "friction"), level=4))
        for path in jointwise:
            rec = read_recording(path, spec="kinova_gen3", robot=robot)
            j = int(path.name.split("_")[1]) - 1
            jw_id[j] = validate(ident.robot, rec, "current", ident=ident)
            jw_urdf[j] = validate(robot, rec, "current", model=model, gains=gains)
            parts.append(validation_section(jw_id[j], out, "kinova", f"jointwise_{j + 1}",
                                            f"{rec.source}: joint {j + 1} moves, identified "
                                            "model", kinds=("prediction",), level=4))
    return held_id, held_urdf, jw_id, jw_urdf, parts


def _verdict(raw: float, filtered: float) -> str:
    """Whether the raw and filtered errors are below the data README's baseline."""
    base_raw, base_filt = KINOVA_BASELINE
    return (f"raw {'below' if raw < base_raw else 'NOT below'}, filtered "
            f"{'below' if filtered < base_filt else 'NOT below'}")


_JOINT_HEADERS = ("joint", "held-out: identified", "held-out: URDF", "jointwise: identified",
                  "jointwise: URDF", "jointwise noise floor", "gain / (N m/A)",
                  "controller gain", "viscous / (N m s)", "Coulomb +/- / N m",
                  "rotor inertia / (kg m²)", "gravity current / URDF's")


def _gravity_scale(identified: Any, urdf: Any, q: np.ndarray) -> np.ndarray:
    """Least-squares scale of the identified gravity load on the URDF's per joint, (n,).

    ``s_j = sum g_id,j g_urdf,j / sum g_urdf,j^2`` over the states ``q`` (N, n); NaN where the
    URDF's load is negligible (below 1e-3 of the largest joint's RMS).
    """
    g_id, g_u = identified.gravity(q), urdf.gravity(q)
    # s_j = <g_id,j, g_u,j> / <g_u,j, g_u,j>
    den = np.sum(g_u**2, axis=0)
    ok = np.sqrt(den) > 1e-3 * np.sqrt(den.max())
    return np.where(ok, np.sum(g_id * g_u, axis=0) / np.where(ok, den, 1.0), np.nan)


def _joint_row(j: int, robot: Any, ident: Any, held_id: Sequence[Validation],
               held_urdf: Sequence[Validation], jw_id: Validation | None,
               jw_urdf: Validation | None, gravity_scale: float) -> list[object]:
    fr = ident.robot.joints[j].friction
    drive = ident.robot.joints[j].drive

    def num(x: object) -> float:
        return float(x.subs(ident.robot.defaults()) if hasattr(x, "subs") else x)

    def jw(v: Validation | None, attr: str) -> str:
        if v is None:
            return "-"
        return f"{v.noise.relative[j]:.3f}" if attr == "noise" else f"{v.prediction.relative[j]:.3f}"

    return [robot.joint_names[j], f"{combined_relative(held_id, joints=[j]):.3f}",
            f"{combined_relative(held_urdf, joints=[j]):.3f}", jw(jw_id, "id"), jw(jw_urdf, "id"),
            jw(jw_id, "noise"), f"{ident.gains[j]:.4g}", f"{KINOVA_CONTROLLER_GAINS[j]:.4g}",
            f"{num(fr.viscous):.4g}",
            f"{num(fr.coulomb_positive):.3g} / {num(fr.coulomb_negative):.3g}",
            f"{num(drive.gear_ratio) ** 2 * num(drive.rotor_inertia):.4g}",
            # in current: (g_id / k_id) / (g_urdf / k_controller)
            "-" if np.isnan(gravity_scale) else
            f"{gravity_scale * KINOVA_CONTROLLER_GAINS[j] / ident.gains[j]:.3f}"]


def _friction_html(ft: Any, names: Sequence[str]) -> str:
    """The friction-model table (``robodyn.identification.friction_comparison.friction_table``) as HTML."""
    rows = [[r["model"], f"{r['relative_error']:.3f}", f"{r['relative_error_filtered']:.3f}",
             f"{r['noise_floor']:.3f}", *(f"{r[f'relative_error_{n}']:.3f}" for n in names)]
            for _, r in ft.iterrows()]
    headers = ("friction model", "held-out rel. error", "against filtered", "noise floor",
               *names)
    return _macro("friction_section", table=Markup(html_table(headers, rows)))


def _default_data_dir() -> Path:
    """``../shared/data/kinova-gen3`` beside the repository root (this file is in src/robodyn/)."""
    return Path(__file__).resolve().parents[3].parent / "shared" / "data" / "kinova-gen3"
