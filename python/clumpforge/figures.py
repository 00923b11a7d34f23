"""Figures of clumpforge results, drawn with matplotlib, as PNG and SVG.

The command line writes each result's data (``report.json``, ``tracks.json``,
``calibration.json``, ``study.json``, ``population.json``) and then calls this module to draw them; it can also
be run by hand on such a folder::

    python3 -m clumpforge.figures diagnosis|calibration|study|population DIR

Every figure is written to a temporary name and renamed, so a folder never holds half a
figure. ``draw(kind, directory)`` returns the files written.
"""

import argparse
import json
import math
import os
import pathlib
import sys

import matplotlib
import matplotlib.ticker

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

RECORDED, BASELINE, IMPROVED, LAB = "0.15", "#d62728", "#2ca02c", "#1f77b4"
RESPONSES = {"drop": "rebound height", "tilt": "slip angle", "roll": "roll distance"}


def _save(fig, directory, stem):
    written = []
    for suffix in ("png", "svg"):
        final = pathlib.Path(directory) / f"{stem}.{suffix}"
        temporary = final.with_name(f"{final.stem}.tmp.{suffix}")
        fig.savefig(temporary, dpi=150)
        os.replace(temporary, final)
        written.append(str(final))
    plt.close(fig)
    return written


def _t95(n):
    """Two-sided 95 % Student t quantile for n - 1 degrees of freedom (n >= 2)."""
    table = {1: 12.706, 2: 4.303, 3: 3.182, 4: 2.776, 5: 2.571, 6: 2.447, 7: 2.365, 8: 2.306, 9: 2.262,
             10: 2.228, 12: 2.179, 15: 2.131, 20: 2.086, 30: 2.042, 60: 2.000}
    dof = max(1, n - 1)
    key = max(k for k in table if k <= dof)
    return table[key] if dof <= 60 else 1.96


def _mean_ci(values):
    v = np.asarray(values, dtype=float)
    if v.size < 2:
        return float(v.mean()) if v.size else math.nan, 0.0
    return float(v.mean()), _t95(v.size) * float(v.std(ddof=1)) / math.sqrt(v.size)


# ---------------------------------------------------------------- diagnosis


def _values(values):
    """A JSON list as a float array; null (a frame the camera lost) becomes NaN."""
    return np.array([math.nan if v is None else v for v in values], dtype=float)


def _residual(t_rec, y_rec, t_model, y_model):
    """Recorded minus model at the recorded frames inside the model's time span [mm]."""
    t_rec, y_rec = _values(t_rec), _values(y_rec)
    t_model, y_model = _values(t_model), _values(y_model)
    if t_model.size < 2:
        return np.array([]), np.array([])
    inside = (t_rec >= t_model[0]) & (t_rec <= t_model[-1]) & np.isfinite(y_rec)
    return t_rec[inside], 1e3 * (y_rec[inside] - np.interp(t_rec[inside], t_model, y_model))


def diagnosis_track(track, report, directory):
    """One recording's first trial: z and x against time with both models, and below each the
    residuals (recorded - model) on a millimetre scale, with the camera noise as a band. The
    residual axis is scaled to the part of the track before the release horizon, where a
    frame-by-frame comparison means something; beyond it (shaded) the replay depends on the
    unknown release orientation and the diagnosis compares distributions instead."""
    name = track["recording"]
    noise_mm = 1e3 * report.get("noise_m", {}).get(name, 0.0)
    verdict = report.get("verdict", "?")
    fig, axes = plt.subplots(2, 2, figsize=(11, 6.2), sharex="col", layout="constrained",
                             gridspec_kw={"height_ratios": [3, 2]})
    t = _values(track["t"])
    horizon = track.get("horizon")
    has_horizon = horizon is not None and math.isfinite(horizon) and t.size and horizon < np.nanmax(t)
    for col, axis in enumerate(("z", "x")):
        top, bottom = axes[0][col], axes[1][col]
        top.plot(t, 1e3 * _values(track[axis]), "o", ms=2.0, mfc="none", mew=0.6, color=RECORDED,
                 label="recorded", zorder=2)
        window = []
        for key, colour, label in (("baseline", BASELINE, "baseline model"), ("improved", IMPROVED, "improved model")):
            tm = _values(track[f"{key}_t"])
            if tm.size:
                top.plot(tm, 1e3 * _values(track[f"{key}_{axis}"]), "-", lw=1.2, color=colour, label=label, zorder=3)
                tr, r = _residual(t, track[axis], tm, track[f"{key}_{axis}"])
                bottom.plot(tr, r, "-", lw=1.0, color=colour, label=f"recorded - {key}")
                window.append(r[tr <= horizon] if has_horizon else r)
        if noise_mm > 0:
            bottom.axhspan(-noise_mm, noise_mm, color="0.85", zorder=0, label=f"camera noise ±{noise_mm:.2f} mm")
        bottom.axhline(0.0, color="0.4", lw=0.6)
        inside = np.concatenate(window) if window else np.array([])
        inside = inside[np.isfinite(inside)]
        duration = float(np.nanmax(t) - np.nanmin(t)) if t.size else 0.0
        short_window = has_horizon and horizon - float(np.nanmin(t)) < 0.25 * duration
        span = 0.05
        if inside.size and not short_window:
            span = max(float(np.max(np.abs(inside))), 2.0 * noise_mm, 0.05) * 1.25
            bottom.set_ylim(-span, span)
        elif short_window:
            # Almost the whole track lies beyond the horizon: show all of it, millimetres
            # linear around the noise and logarithmic beyond.
            bottom.set_yscale("symlog", linthresh=max(2.0 * noise_mm, 0.1))
            span = bottom.get_ylim()[1]
        if has_horizon:
            for ax in (top, bottom):
                right = ax.get_xlim()[1]
                ax.axvspan(horizon, right, color="0.93", zorder=0)
                ax.set_xlim(right=right)
                ax.axvline(horizon, color="0.5", ls=":", lw=1.0)
            bottom.annotate("beyond the release horizon:\ncompared as distributions", (horizon, span),
                            xytext=(4, -4), textcoords="offset points", va="top", fontsize=7, color="0.35")
        top.set_ylabel(f"{'height z' if axis == 'z' else 'horizontal x'} [mm]")
        bottom.set_ylabel("residual [mm]")
        bottom.set_xlabel("time since release [s]")
        top.grid(alpha=0.3)
        bottom.grid(alpha=0.3)
    axes[0][0].legend(loc="lower left", fontsize=8, frameon=True, framealpha=0.9)
    axes[1][0].legend(loc="lower left", fontsize=7, frameon=True, framealpha=0.9, ncol=3)
    title = f"{name}: first trial, baseline and improved model (verdict: {verdict})"
    if has_horizon:
        title += f"; release horizon {horizon:.3f} s"
    fig.suptitle(title)
    return _save(fig, directory, f"track-{name}")


def diagnosis_phases(report, directory):
    """chi^2 per value of every (recording, phase), baseline and improved, on a log scale
    with the noise level at 1; phases are named."""
    phases = report.get("phases", [])
    if not phases:
        return []
    labels = [f"{p['recording']}: {p['phase']}" for p in phases]
    before = np.array([max(p["chi2_per_value"], 1e-3) for p in phases])
    after = np.array([max(p.get("improved_chi2_per_value", p["chi2_per_value"]), 1e-3) for p in phases])
    x = np.arange(len(phases))
    fig, ax = plt.subplots(figsize=(max(7.0, 0.55 * len(phases) + 2), 4.6), layout="constrained")
    ax.bar(x - 0.2, before, 0.4, color=BASELINE, label="baseline")
    ax.bar(x + 0.2, after, 0.4, color=IMPROVED, label="improved")
    for k, p in enumerate(phases):
        if p.get("significant"):
            ax.annotate("*", (x[k] - 0.2, before[k]), ha="center", va="bottom", fontsize=11, color=BASELINE)
    ax.axhline(1.0, color="0.3", ls="--", lw=1.0, label="noise level (chi²/value = 1)")
    ax.set_yscale("log")
    ax.set_xticks(x, labels, rotation=35, ha="right", fontsize=8)
    ax.set_ylabel("chi² per value")
    ax.set_title(f"Misfit by phase (* beyond the noise); verdict: {report.get('verdict', '?')}")
    ax.legend(loc="best", fontsize=8, frameon=False)
    ax.grid(axis="y", alpha=0.3, which="both")
    return _save(fig, directory, "residuals-by-phase")


def diagnosis(directory):
    directory = pathlib.Path(directory)
    report = json.loads((directory / "report.json").read_text())
    written = diagnosis_phases(report, directory)
    tracks_file = directory / "tracks.json"
    if tracks_file.exists():
        for track in json.loads(tracks_file.read_text()):
            written += diagnosis_track(track, report, directory)
    return written


# ---------------------------------------------------------------- calibration


def _fit_value(fit, x):
    return (fit["a"] * x + fit["b"]) * x + fit["c"]


def _invert(fit, target, low, high):
    """Solutions of fit(x) = target in [low, high]."""
    a, b, c = fit["a"], fit["b"], fit["c"] - target
    if abs(a) < 1e-300:
        roots = [-c / b] if b else []
    else:
        d = b * b - 4 * a * c
        roots = [] if d < 0 else [(-b - math.sqrt(d)) / (2 * a), (-b + math.sqrt(d)) / (2 * a)]
    return sorted(r for r in roots if low - 1e-12 <= r <= high + 1e-12)


def calibration_step(step, directory):
    """One sweep: level means with 95 % intervals, the quadratic fit, the lab's mean with its
    95 % band, and the calibrated value with the interval the band gives through the fit."""
    units = step.get("units", "")
    levels = step["levels"]
    xs = np.array([lv["value"] for lv in levels])
    fig, (ax, hist) = plt.subplots(1, 2, figsize=(11, 4.3), layout="constrained",
                                   gridspec_kw={"width_ratios": [3, 2]})
    for lv in levels:
        r = lv["responses"]
        ax.plot(np.full(len(r), lv["value"]), r, "o", ms=2.5, color="0.75", zorder=1)
    cis = [_mean_ci(lv["responses"]) for lv in levels]
    ax.errorbar(xs, [m for m, _ in cis], yerr=[c for _, c in cis], fmt="s", ms=4, color=LAB, capsize=3,
                label="level mean, 95 % interval", zorder=3)
    grid = np.linspace(xs.min(), xs.max(), 200)
    ax.plot(grid, _fit_value(step["fit"], grid), "-", color=BASELINE,
            label=f"quadratic fit (R² {step['fit'].get('r_squared', math.nan):.3f})")
    lab_mean, lab_ci = _mean_ci(step.get("measured", [])) if step.get("measured") else (step["measured_mean"], 0.0)
    ax.axhline(step["measured_mean"], color="0.2", lw=1.0, label="lab mean")
    if lab_ci > 0:
        ax.axhspan(step["measured_mean"] - lab_ci, step["measured_mean"] + lab_ci, color="0.88", zorder=0,
                   label="lab mean, 95 % interval")
    low, high = xs.min(), xs.max()
    edges = _invert(step["fit"], step["measured_mean"] - lab_ci, low, high) + \
        _invert(step["fit"], step["measured_mean"] + lab_ci, low, high)
    calibrated = step["calibrated"]
    on_fit = float(_fit_value(step["fit"], calibrated))
    if step.get("roots"):
        if edges and lab_ci > 0:
            near = sorted(edges, key=lambda e: abs(e - calibrated))[:2]
            lo, hi = min(near + [calibrated]), max(near + [calibrated])
            ax.errorbar([calibrated], [on_fit], xerr=[[calibrated - lo], [hi - calibrated]], fmt="D", ms=7,
                        color=IMPROVED, capsize=4, zorder=4, label=f"calibrated {calibrated:.3g} [{lo:.3g}, {hi:.3g}]")
        else:
            ax.plot([calibrated], [on_fit], "D", ms=7, color=IMPROVED, zorder=4, label=f"calibrated {calibrated:.3g}")
    else:
        # No root in the swept range: the tool took the nearer end; the point sits on the fit,
        # away from the lab's line, and the figure says so.
        ax.plot([calibrated], [on_fit], "D", ms=7, mfc="white", color=IMPROVED, zorder=4,
                label=f"calibrated {calibrated:.3g}: no root in range, nearer end")
    verified = step.get("verification_responses", [])
    if verified:
        v_mean, v_ci = _mean_ci(verified)
        ax.errorbar([calibrated], [v_mean], yerr=[v_ci], fmt="x", ms=7, color="0.1", capsize=3, zorder=5,
                    label=f"verification runs, mean {v_mean:.3g}")
    if step.get("study_value") is not None:
        ax.axvline(step["study_value"], color="0.5", ls=":", label=f"the study's value {step['study_value']:.3g}")
    ax.set_xlabel(step["parameter"].replace("_", " "))
    response = RESPONSES.get(step["test"], f"{step['test']} response")
    ax.set_ylabel(f"{response} [{units}]")
    ax.set_title(f"{step['parameter'].replace('_', ' ')} on {step['surface']}: {step['test']} test")
    ax.legend(loc="best", fontsize=7, frameon=False)
    ax.grid(alpha=0.3)
    simulated, measured = step.get("verification_responses", []), step.get("measured", [])
    both = list(simulated) + list(measured)
    if both:
        bins = np.histogram_bin_edges(both, bins=min(12, max(4, len(both) // 3)))
        hist.hist(measured, bins=bins, alpha=0.45, color=BASELINE, label=f"lab ({len(measured)} trials)")
        hist.hist(simulated, bins=bins, histtype="step", lw=2.0, color=LAB,
                  label=f"simulated at {calibrated:.3g} ({len(simulated)} trials)")
        hist.set_xlabel(f"{response} [{units}]")
        hist.set_ylabel("trials")
        hist.set_title("trial outcomes at the calibrated value")
        hist.legend(fontsize=7, frameon=False)
    return _save(fig, directory, f"sweep-{step['parameter']}-{step['surface']}")


def calibration_joint(report, directory):
    """Joint fit: each surface's coefficients with their bootstrap intervals, and each test's
    residual in standard errors."""
    surfaces = report.get("surfaces", [])
    if not surfaces:
        return []
    fig, axes = plt.subplots(1, 4, figsize=(13, 3.8), layout="constrained")
    names = [s["surface"] for s in surfaces]
    for ax, key in zip(axes[:3], ("restitution", "static_friction", "rolling_friction")):
        values = [s[key]["value"] for s in surfaces]
        lows = [s[key]["value"] - s[key].get("low", s[key].get("low95")) for s in surfaces]
        highs = [s[key].get("high", s[key].get("high95")) - s[key]["value"] for s in surfaces]
        ax.errorbar(range(len(names)), values, yerr=[lows, highs], fmt="D", color=IMPROVED, capsize=4)
        ax.set_xticks(range(len(names)), names)
        ax.set_title(f"{key.replace('_', ' ')} (95 % bootstrap)")
        ax.grid(alpha=0.3)
    ax = axes[3]
    tests = []
    for s in surfaces:
        tests += [r.get("test", "?") for r in s.get("residuals", []) if r.get("test", "?") not in tests]
    for k, s in enumerate(surfaces):
        offset = 0.12 * (k - (len(surfaces) - 1) / 2)
        for r in s.get("residuals", []):
            ax.plot(tests.index(r.get("test", "?")) + offset, r.get("z", 0.0), "o", color=f"C{k}",
                    label=s["surface"] if r is s["residuals"][0] else None)
    ax.axhspan(-2, 2, color="0.9", zorder=0, label="within 2 standard errors")
    ax.axhline(0, color="0.4", lw=0.6)
    ax.set_title("residual [standard errors]")
    ax.set_xticks(range(len(tests)), tests)
    ax.set_xlim(-0.5, len(tests) - 0.5)
    ax.legend(fontsize=7, frameon=False, loc="best")
    ax.grid(alpha=0.3, axis="y")
    return _save(fig, directory, "joint-estimates")


def calibration(directory):
    directory = pathlib.Path(directory)
    report = json.loads((directory / "calibration.json").read_text())
    if report.get("method") == "joint":
        return calibration_joint(report, directory)
    steps = [step for step in report.get("steps", []) if step.get("levels")]
    written = []
    for step in steps:
        written += calibration_step(step, directory)
    return written + calibration_overview(steps, directory)


def calibration_overview(steps, directory):
    """Each step's simulated mean at the calibrated values relative to the lab's mean, in
    per cent, with the simulation's 95 % interval, over the lab mean's own 95 % interval: unit-free,
    so drops, tilts and rolls share one axis."""
    if not steps:
        return []
    fig, ax = plt.subplots(figsize=(7.5, 0.55 * len(steps) + 1.9), layout="constrained")
    for k, step in enumerate(steps):
        measured = step.get("measured", [])
        lab, lab_ci = _mean_ci(measured) if measured else (step["measured_mean"], 0.0)
        verified = step.get("verification_responses", [])
        sim, sim_ci = _mean_ci(verified) if verified else (step["verification_mean"], 0.0)
        ax.barh(k, 200.0 * lab_ci / lab, left=-100.0 * lab_ci / lab, height=0.6, color="0.88",
                label="lab mean, 95 % interval" if k == 0 else None)
        ax.errorbar([100.0 * (sim - lab) / lab], [k], xerr=[100.0 * sim_ci / lab], fmt="o", color=LAB, capsize=3,
                    label="simulated mean, 95 % interval" if k == 0 else None)
    ax.axvline(0.0, color="0.3", lw=0.8)
    labels = [f"{s['test']} on {s['surface']} ({s['parameter'].replace('_', ' ')} {s['calibrated']:.3g})"
              for s in steps]
    ax.set_yticks(range(len(steps)), labels, fontsize=8)
    ax.invert_yaxis()
    ax.set_xlabel("simulated mean at the calibrated values - lab mean [% of the lab mean]")
    ax.set_title("Verification runs against the lab")
    ax.legend(frameon=False, fontsize=7, loc="lower center", bbox_to_anchor=(0.5, 1.06), ncol=2)
    ax.grid(alpha=0.3, axis="x")
    return _save(fig, directory, "measured-vs-calibrated")


# ---------------------------------------------------------------- resolution study


def _plain_log(axis):
    """A log axis labelled at 1, 2 and 5 x 10^k in plain numbers."""
    axis.set_major_locator(matplotlib.ticker.LogLocator(subs=(1.0, 2.0, 5.0)))
    axis.set_major_formatter(matplotlib.ticker.FuncFormatter(lambda v, _: f"{v:g}"))
    axis.set_minor_formatter(matplotlib.ticker.NullFormatter())


def _against_spheres(ax, label, log_y=True):
    """A panel of a quantity against sphere count: log x with plain labels, log y unless told."""
    ax.set_xscale("log")
    _plain_log(ax.xaxis)
    if log_y:
        ax.set_yscale("log")
    ax.set_xlabel("spheres")
    ax.set_ylabel(label)
    ax.grid(alpha=0.3, which="both")


def study(directory):
    """Geometry error against sphere count, lattice and adaptive: mass, worst principal
    moment (mass-matched), surface RMS distance, and the fill's time."""
    directory = pathlib.Path(directory)
    report = json.loads((directory / "study.json").read_text())
    rows = report["rows"]
    panels = (("mass_error", "|mass error| at the body's density [%]", 100.0),
              ("worst_moment_error_mass_matched", "worst moment error, mass-matched [%]", 100.0),
              ("surface_rms_m", "surface RMS distance [mm]", 1e3),
              ("fill_seconds", "fill + error report [s]", 1.0))
    fig, axes = plt.subplots(2, 2, figsize=(10, 7), layout="constrained")
    for ax, (key, label, scale) in zip(axes.ravel(), panels):
        for method, marker, colour in (("lattice", "s", LAB), ("adaptive", "o", IMPROVED)):
            chosen = [r for r in rows if r["method"] == method and key in r]
            if not chosen:
                continue
            n = [r["spheres"] for r in chosen]
            y = [max(abs(r[key]) * scale, 1e-6) for r in chosen]
            ax.plot(n, y, marker + "-", color=colour, label=method)
            if method == "lattice":
                for r, xi, yi in zip(chosen, n, y):
                    ax.annotate(r["name"].replace("lattice-", ""), (xi, yi), fontsize=7, xytext=(4, 3),
                                textcoords="offset points")
        _against_spheres(ax, label)
        ax.legend(fontsize=8, frameon=False)
    fig.suptitle(f"Resolution study of {pathlib.Path(report.get('input', '')).name}: lattice against adaptive fill")
    written = _save(fig, directory, "study")
    if "dem" in report:
        written += study_dem(report, directory)
    return written


def _study_outcome_panel(ax, samples, dem, label, tolerance, unit):
    """One test on one surface: each clump's mean outcome with its 95 % CI against sphere count;
    the reference's interval and the tolerance around it as bands; hollow markers where the
    clump differs from the reference."""
    reference = next(s for s in samples if s["clump"] == dem["reference"])
    low, high = reference["mean"] - reference["ci95"], reference["mean"] + reference["ci95"]
    ax.axhspan(reference["mean"] - tolerance, reference["mean"] + tolerance, color="#ffbf00", alpha=0.15, lw=0,
               label=f"reference $\\pm$ tolerance ({tolerance:g} {unit})")
    ax.axhspan(low, high, color="0.5", alpha=0.25, lw=0, label=f"{dem['reference']} (reference), 95 % CI")
    for method, marker, colour in (("lattice", "s", LAB), ("adaptive", "o", IMPROVED)):
        chosen = sorted((s for s in samples if s["method"] == method), key=lambda s: s["spheres"])
        if not chosen:
            continue
        n = [s["spheres"] for s in chosen]
        ax.plot(n, [s["mean"] for s in chosen], "-", color=colour, lw=0.8, alpha=0.6)
        for s in chosen:
            differs = s.get("comparison", {}).get("distinguishable", False)
            ax.errorbar(s["spheres"], s["mean"], yerr=s["ci95"], fmt=marker, color=colour, capsize=2, ms=5,
                        mfc="white" if differs else colour)
        ax.plot([], [], marker, color=colour, label=f"{method} (hollow: differs)")
    if dem["coarsest"] != dem["reference"]:
        best = next(s for s in samples if s["clump"] == dem["coarsest"])
        ax.annotate(f"coarsest alike:\n{best['clump']}", (best["spheres"], best["mean"]), fontsize=7,
                    xytext=(8, -22), textcoords="offset points", arrowprops={"arrowstyle": "->", "lw": 0.6})
    _against_spheres(ax, label, log_y=False)
    ax.ticklabel_format(axis="y", useOffset=False, style="plain")


def study_dem(report, directory):
    """The study's DEM side: every test's outcome against sphere count, and the DEM's cost."""
    dem = report["dem"]
    keys = sorted({(s["surface"], s["test"]) for s in dem["samples"]}, key=lambda k: (k[0], list(RESPONSES).index(k[1])
                                                                                      if k[1] in RESPONSES else 9))
    columns = 2 if len(keys) + 1 == 4 else min(3, len(keys) + 1)
    rows = math.ceil((len(keys) + 1) / columns)
    fig, axes = plt.subplots(rows, columns, figsize=(4.2 * columns, 3.6 * rows), layout="constrained", squeeze=False)
    panels = list(axes.ravel())
    for ax, (surface, test) in zip(panels, keys):
        samples = [s for s in dem["samples"] if s["surface"] == surface and s["test"] == test]
        label, _ = OUTCOME_UNITS.get(test, (test, 1.0))
        tolerance = dem.get("tolerance_deg", 0.2) if test == "tilt" else dem.get("tolerance_mm", 0.5)
        _study_outcome_panel(ax, samples, dem, label, tolerance, "deg" if test == "tilt" else "mm")
        ax.set_title(f"{test} on {surface}", fontsize=9)
    panels[0].legend(fontsize=7, frameon=False)
    cost = panels[len(keys)]
    for (surface, test), colour in zip(keys, ("#17becf", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#bcbd22")):
        for method, marker, style in (("lattice", "s", "--"), ("adaptive", "o", "-")):
            pts = sorted((s["spheres"], s["seconds_per_trial"]) for s in dem["samples"]
                         if s["surface"] == surface and s["test"] == test and s["method"] == method)
            if pts:
                cost.plot(*zip(*pts), marker + style, ms=4, lw=0.8, color=colour,
                          label=f"{test} on {surface}" if method == "adaptive" else None)
    cost.plot([], [], "s--", color="0.4", ms=4, lw=0.8, label="lattice")
    cost.plot([], [], "o-", color="0.4", ms=4, lw=0.8, label="adaptive")
    _against_spheres(cost, "DEM wall time per trial [s]")
    _plain_log(cost.yaxis)
    cost.legend(fontsize=7, frameon=False)
    cost.set_title("cost", fontsize=9)
    for ax in panels[len(keys) + 1:]:
        ax.set_visible(False)
    verdict = (f"{dem['coarsest']} is the coarsest clump alike to {dem['reference']}"
               if dem["coarsest"] != dem["reference"] else f"no coarser clump is alike to {dem['reference']}")
    fig.suptitle(f"DEM outcomes against sphere count ({dem['trials']} release orientations per point, 95 % CI)\n"
                 f"{verdict}", fontsize=10)
    return _save(fig, directory, "study-dem")


# ---------------------------------------------------------------- population (batch)

SHAPE_PANELS = (("volume_m3", "volume [cm$^3$]", 1e6), ("mass_kg", "mass [g]", 1e3),
                ("length_m", "length L [mm]", 1e3), ("sphericity", "sphericity", 1.0),
                ("elongation", "elongation W/L", 1.0), ("flatness", "flatness T/W", 1.0))
OUTCOME_UNITS = {"drop": ("rebound height [mm]", 1e3), "roll": ("roll distance [mm]", 1e3),
                 "tilt": ("slip angle [deg]", 1.0)}


def _histogram(ax, values, label):
    v = np.asarray(values, dtype=float)
    ax.hist(v, bins=max(5, min(30, int(round(math.sqrt(v.size)) * 2))), color=LAB, alpha=0.75, edgecolor="white")
    mean, ci = _mean_ci(v)
    ax.axvline(mean, color="black", lw=1)
    ax.axvspan(mean - ci, mean + ci, color="black", alpha=0.12, lw=0)
    ax.set_xlabel(label)
    ax.set_ylabel("scans")
    ax.yaxis.set_major_locator(matplotlib.ticker.MaxNLocator(integer=True))
    spread = f", sd {v.std(ddof=1):.3g}" if v.size > 1 else ""
    ax.set_title(f"mean {mean:.3g} (95 % CI $\\pm${ci:.2g}){spread}", fontsize=8)
    ax.grid(alpha=0.3, axis="y")


def population_shapes(report, directory):
    """The population's shape distributions: one histogram per measure, mean and its 95 % CI."""
    scans = report["scans"]
    fig, axes = plt.subplots(2, 3, figsize=(11, 6.5), layout="constrained")
    for ax, (key, label, scale) in zip(axes.ravel(), SHAPE_PANELS):
        _histogram(ax, [s[key] * scale for s in scans], label)
    failed = len(report.get("failed", []))
    fig.suptitle(f"Population of {len(scans)} scans" + (f" ({failed} failed, left out)" if failed else ""))
    return _save(fig, directory, "population-shapes")


def population_outcomes(report, directory):
    """DEM outcomes across the population: per validated clump, test and surface, the scans'
    mean outcomes as points with their 95 % CI (trials), and the population's spread."""
    series = {}
    for s in report["scans"]:
        for c in s["clumps"]:
            for o in c["outcomes"]:
                series.setdefault((o["test"], o["surface"]), {}).setdefault(c["name"], []).append(o["values"])
    if not series:
        return []
    tests = sorted({t for t, _ in series})
    surfaces = sorted({s for _, s in series})
    fig, axes = plt.subplots(len(surfaces), len(tests), figsize=(3.6 * len(tests) + 0.8, 3.4 * len(surfaces) + 0.6),
                             layout="constrained", squeeze=False)
    for (row, surface), (col, test) in ((r, c) for r in enumerate(surfaces) for c in enumerate(tests)):
        ax, key = axes[row][col], (test, surface)
        if key not in series:
            ax.set_visible(False)
            continue
        label, scale = OUTCOME_UNITS.get(key[0], (key[0], 1.0))
        for k, (clump, trials) in enumerate(sorted(series[key].items())):
            means = [_mean_ci(np.asarray(t) * scale) for t in trials]
            x = k + np.linspace(-0.25, 0.25, len(means)) if len(means) > 1 else np.array([k])
            ax.errorbar(x, [m for m, _ in means], yerr=[ci for _, ci in means], fmt="o", ms=3, lw=0.8,
                        color=(IMPROVED, LAB, BASELINE)[k % 3], capsize=2)
            ax.boxplot([m for m, _ in means], positions=[k], widths=0.7, showfliers=False,
                       medianprops={"color": "black"}, boxprops={"alpha": 0.4}, whiskerprops={"alpha": 0.4})
        ax.set_xticks(range(len(series[key])), sorted(series[key]), rotation=20, fontsize=8)
        ax.set_ylabel(label)
        ax.ticklabel_format(axis="y", useOffset=False, style="plain")
        ax.set_title(f"{key[0]} on {key[1]}", fontsize=9)
        ax.grid(alpha=0.3, axis="y")
    fig.suptitle("DEM outcomes across the population: each point a scan's mean with its 95 % CI over trials")
    return _save(fig, directory, "population-outcomes")


def population_errors(report, directory):
    """Fill error against sphere count: one point per scan and clump, lattice and adaptive."""
    panels = (("mass_error", "|mass error| [%]", 100.0),
              ("worst_moment_error_mass_matched", "worst moment error, mass-matched [%]", 100.0),
              ("surface_rms_m", "surface RMS distance [mm]", 1e3))
    fig, axes = plt.subplots(1, 3, figsize=(12, 4), layout="constrained")
    for ax, (key, label, scale) in zip(axes, panels):
        for method, marker, colour in (("lattice", "s", LAB), ("adaptive", "o", IMPROVED)):
            pts = [(c["spheres"], max(abs(c[key]) * scale, 1e-6)) for s in report["scans"] for c in s["clumps"]
                   if c["method"] == method and key in c]
            if pts:
                ax.scatter(*zip(*pts), marker=marker, s=14, color=colour, alpha=0.7, label=method)
        _against_spheres(ax, label)
        ax.legend(fontsize=8, frameon=False)
    fig.suptitle("Fill error against sphere count, every scan of the population")
    return _save(fig, directory, "population-errors")


def population(directory):
    """The figures of a batch's folder (population.json)."""
    directory = pathlib.Path(directory)
    report = json.loads((directory / "population.json").read_text())
    if not report["scans"]:
        raise ValueError("population.json holds no scan")
    return population_shapes(report, directory) + population_outcomes(report, directory) + \
        population_errors(report, directory)


KINDS = {"diagnosis": diagnosis, "calibration": calibration, "study": study, "population": population}


def draw(kind, directory):
    """Draws the figures of a result folder; returns the files written."""
    if kind not in KINDS:
        raise ValueError(f"unknown kind '{kind}' ({', '.join(KINDS)})")
    return KINDS[kind](directory)


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python3 -m clumpforge.figures", description=__doc__.splitlines()[0])
    parser.add_argument("kind", choices=sorted(KINDS))
    parser.add_argument("directory")
    args = parser.parse_args(argv)
    try:
        written = draw(args.kind, args.directory)
    except (OSError, ValueError, KeyError) as error:
        print(f"clumpforge figures: error: {args.directory}: {error}", file=sys.stderr)
        return 1
    for path in written:
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
