#!/usr/bin/python3
"""Write a folder of pictures about one dem2d run: energies, power, charge shape, the charge.

    post/report.py OUTDIR [-o REPORTDIR] [--snapshots N] [--max-frames N] [--no-animation]

Reads OUTDIR/series.csv, run.json, snapshots.h5 and collisions.csv (each when present) and
writes into REPORTDIR (default OUTDIR/report):
  energies.png        kinetic, rotational, potential (relative to its start), elastic and
                      dissipated energy and the drive work [kJ] against time;
  power.png           the drive power [kW]: raw samples faint, averaged bold; the shell and
                      lifter parts when the drum has lifters; kW per metre of mill on the right;
  charge_shape.png    toe and shoulder angles, bed surface angle, airborne and corotating
                      fractions against time, the regime as coloured bands;
  charge_TTT.TTTs.png the charge at a few snapshot times (evenly spaced, the last included):
                      particles at their true size coloured by speed [m/s] (discs as circles,
                      superellipses as their outlines at their angles), drum and lifters;
  collisions.png      collision energy spectra per contact type (when collisions.csv exists);
  charge.mp4          an animation of the charge (at most --max-frames frames, default 200);
                      charge.gif instead when ffmpeg is not on the PATH;
  report.md, index.html  the list of files with a caption each, and the run's key numbers:
                      critical speed, fraction of critical, regime, average power, its scaling
                      to a mill (the 2D power is that of a slice one ball diameter thick).
Files of these names left in REPORTDIR by an earlier report are removed first.
"""

import argparse
import html
import os
import re
import shutil
import sys
import time as clock

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.cm import ScalarMappable  # noqa: E402
from matplotlib.colors import Normalize  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402

sys.dont_write_bytecode = True  # no __pycache__ beside the installed scripts
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import millplot  # noqa: E402

ENERGIES = [
    ("kinetic_energy", "kinetic"),
    ("rotational_energy", "rotational"),
    ("potential_energy", "potential - initial"),
    ("elastic_energy", "elastic"),
    ("dissipated_energy", "dissipated"),
    ("drive_work", "drive work"),
]


class Run:
    """What report.py knows about one output folder."""

    def __init__(self, outdir):
        self.outdir = outdir
        self.series = millplot.read_series(os.path.join(outdir, "series.csv"))
        self.info = millplot.read_run_json(outdir)
        self.deck = millplot.deck_of(self.info)
        self.title = millplot.run_title(self.info, f"dem2d run in {outdir}")
        self.h5_path = os.path.join(outdir, "snapshots.h5")
        self.thickness, self.thickness_source = millplot.slice_thickness(self.info, self.h5_path)
        self.has_drum = millplot.has_drum(self.deck, self.series)
        has_power = self.has_drum and len(self.series["time"]) > 0
        self.mean_power, self.power_se, self.batches, self.batch_kind = (
            millplot.power_estimate(self.series, millplot.drum_speed(self.deck)) if has_power
            else (None, float("nan"), 0, "none"))
        self.per_metre = millplot.mill_scaling(self.thickness, self.mean_power)

    def caption(self):
        """What the 2D power stands for, for figure captions."""
        return millplot.slice_caption(self.thickness, self.thickness_source, self.mean_power,
                                      self.per_metre)


def regime_bands(ax, series, with_legend=True):
    """Shades the time axis by the regime column; returns the legend handles used."""
    t = series["time"]
    seen = []
    for start, end, name in millplot.regime_spans(t, millplot.regime_column(series)):
        if name == millplot.UNCLASSIFIED:
            continue
        ax.axvspan(start, end, color=millplot.REGIME_COLORS.get(name, "0.8"), alpha=0.15,
                   linewidth=0)
        if name not in seen:
            seen.append(name)
    handles = [Patch(color=millplot.REGIME_COLORS.get(n, "0.8"), alpha=0.3, label=n) for n in seen]
    if with_legend and handles:
        ax.legend(handles=handles, loc="lower right", fontsize="small", title="regime")
    return handles


def add_caption(fig, text):
    """A caption under the figure (kept clear of the axes)."""
    fig.text(0.01, 0.005, text, fontsize="small", va="bottom", ha="left", wrap=True)


def plot_energies(run, path):
    """energies.png: the energy terms and the drive work in kJ against time."""
    s = run.series
    fig, ax = plt.subplots(figsize=(10, 5.5), constrained_layout=True)
    for column, label in ENERGIES:
        if column not in s or not len(s[column]):
            continue
        values = s[column] - (s[column][0] if column == "potential_energy" else 0.0)
        ax.plot(s["time"], values / 1e3, label=label, linewidth=1.4)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("energy [kJ]")
    ax.set_title(f"{run.title}\nenergies and drive work")
    ax.grid(True, alpha=0.3)
    if ax.lines:
        ax.legend(loc="upper left", fontsize="small")
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_power(run, path, window):
    """power.png: raw samples faint, averaged power bold [kW]; shell/lifter parts; kW/m axis."""
    s = run.series
    t = s["time"]
    average, label = millplot.averaged_power(s, run.info, window)
    fig, ax = plt.subplots(figsize=(10, 6), layout="constrained")
    ax.plot(t, s["drum_power"] / 1e3, color="tab:red", alpha=0.2, linewidth=0.5,
            label="drive power, raw samples (clipped)")
    ax.plot(t, average / 1e3, color="tab:red", linewidth=2.4, label=f"drive power, {label}")
    if "lifter_power" in s and np.any(s["lifter_power"] != 0.0):
        for column, color, name in [("shell_power", "tab:cyan", "shell"),
                                    ("lifter_power", "tab:purple", "lifters")]:
            part, how = millplot.smoothed(s, run.info, column, window)
            ax.plot(t, part / 1e3, color=color, linewidth=1.6, label=f"{name} part, {how}")
    finite = average[np.isfinite(average)]
    if finite.size:
        ax.set_ylim(min(1.5 * float(finite.min()), -0.05 * float(finite.max())) / 1e3,
                    max(1.5 * float(finite.max()), 1e-9) / 1e3)
    if run.thickness:
        d = run.thickness
        sec = ax.secondary_yaxis("right", functions=(lambda p: p / d, lambda q: q * d))
        sec.set_ylabel("per metre of mill length [kW/m]")
    if run.mean_power is not None:
        ax.axhline(run.mean_power / 1e3, color="black", linestyle=":", linewidth=1.0,
                   label=f"mean over the last half: {power_text(run)}")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("drive power of the 2D slice [kW]")
    ax.set_title(f"{run.title}\ndrive power")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper left", fontsize="small")
    fig.get_layout_engine().set(rect=(0, 0.07, 1, 0.93))
    add_caption(fig, run.caption())
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_charge_shape(run, path):
    """charge_shape.png: toe/shoulder, surface angle, airborne/corotating fractions; regimes."""
    s = run.series
    t = s["time"]
    fig, axes = plt.subplots(3, 1, figsize=(10, 9), sharex=True, constrained_layout=True,
                             gridspec_kw={"height_ratios": [3, 2, 2]})
    ax = axes[0]
    for column, color, name in [("shoulder_angle", "tab:orange", "shoulder"),
                                ("toe_angle", "tab:blue", "toe")]:
        if column in s:
            ax.plot(t, s[column], color=color, linewidth=0.8, label=name)
    ax.set_ylabel("angle from the downward vertical [deg]\n(positive: drum's sense of rotation)")
    ax.set_title(f"{run.title}\ncharge shape (toe and shoulder: the shell layer's occupancy "
                 "averaged over the analysis window)")
    handles = regime_bands(ax, s, with_legend=False)
    lines = ax.get_legend_handles_labels()[0]
    ax.legend(handles=lines + handles, loc="upper left", fontsize="small", ncol=2)
    ax = axes[1]
    if "surface_angle" in s:
        surface = s["surface_angle"]
        ax.plot(t, surface, color="tab:green", linewidth=0.8, label="bed surface")
        if not np.any(np.isfinite(surface)):
            ax.text(0.5, 0.5, "surface_angle is nan in every row", ha="center", va="center",
                    transform=ax.transAxes, color="0.4")
    ax.set_ylabel("surface angle from\nthe horizontal [deg]")
    regime_bands(ax, s, with_legend=False)
    ax.legend(loc="upper left", fontsize="small")
    ax = axes[2]
    for column, color, name in [("airborne_fraction", "tab:red", "airborne (in free flight)"),
                                ("corotating_fraction", "tab:purple", "turning with the drum")]:
        if column in s:
            ax.plot(t, 100.0 * s[column], color=color, linewidth=0.8, label=name)
    ax.set_ylabel("particles [%]")
    ax.set_xlabel("time [s]")
    regime_bands(ax, s, with_legend=False)
    ax.legend(loc="upper left", fontsize="small")
    for ax in axes:
        ax.grid(True, alpha=0.3)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def shell_point(deck, angle_deg):
    """The point on the drum's shell [m] at an angle of series.csv's convention (from the
    downward vertical, positive in the drum's sense of rotation)."""
    drum = deck.get("drum", {})
    radius = float(drum.get("radius", 0.0))
    cx, cy = (float(c) for c in drum.get("center", [0.0, 0.0]))
    sense = -1.0 if (millplot.drum_speed(deck) or 0.0) < 0.0 else 1.0
    a = np.radians(angle_deg)
    return cx + sense * radius * np.sin(a), cy - radius * np.cos(a)


def mark_toe_shoulder(ax, run, time):
    """Marks the toe and shoulder of the series row nearest `time` on the shell."""
    s = run.series
    if "toe_angle" not in s or not len(s["time"]) or not run.deck.get("drum", {}).get("radius"):
        return
    i = int(np.argmin(np.abs(s["time"] - time)))
    for column, marker, name in [("toe_angle", "v", "toe"), ("shoulder_angle", "^", "shoulder")]:
        angle = s[column][i]
        if np.isfinite(angle):
            x, y = shell_point(run.deck, angle)
            ax.plot([x], [y], marker=marker, color="red", markersize=9, linestyle="none",
                    label=f"{name} ({angle:.0f} deg)")
    if ax.get_legend_handles_labels()[0]:
        ax.legend(loc="upper right", fontsize="small")


def speed_scale(f, names):
    """One colour scale for every picture: the largest speed in the snapshots [m/s]."""
    top = 0.0
    for name in names:
        g = f["snapshots"][name]
        speed = g["speed"][()] if "speed" in g else np.hypot(*g["velocity"][()].reshape(-1, 2).T)
        if len(speed):
            top = max(top, float(np.max(speed)))
    return top if top > 0 else 1.0


def pick_snapshots(names, count):
    """`count` snapshot names evenly spaced over the run, the last one included."""
    if not names:
        return []
    n = len(names)
    picks = {int(round((n - 1) * k / count)) for k in range(1, count + 1)} if count > 0 else set()
    picks.add(n - 1)
    return [names[i] for i in sorted(picks)]


def charge_frame_title(run, snap):
    """'t = 2.50 s   regime: cataracting   240 particles' (no regime without a drum)."""
    text = f"t = {snap['time']:.2f} s   "
    if run.has_drum:
        regime = millplot.regime_at(run.series, snap["time"])
        regime = "not classified yet" if regime == millplot.UNCLASSIFIED else regime
        text += f"regime: {regime}   "
    return text + f"{len(snap['radius'])} particles"


def plot_charge(run, f, name, vmax, path):
    """charge_TTT.png: one snapshot, particles coloured by speed, drum and lifters drawn."""
    snap = millplot.read_snapshot(f, name)
    outline = millplot.read_outline(f, name)
    fig, ax = plt.subplots(figsize=(7.5, 7), constrained_layout=True)
    circles = millplot.draw_charge(ax, snap, outline, run.deck, vmax)
    mark_toe_shoulder(ax, run, snap["time"])
    fig.colorbar(circles, ax=ax, shrink=0.8, label="speed [m/s]")
    ax.set_title(f"{run.title}\n{charge_frame_title(run, snap)}", fontsize="medium")
    fig.savefig(path, dpi=110)
    plt.close(fig)


def charge_file_name(time):
    """charge_002.500s.png: sorts in time order."""
    return f"charge_{time:07.3f}s.png"


def spectrum_points(rows):
    """(bin centres [J], counts) of collisions.csv rows of one (type, size class), without the
    first bin (it starts at 0 J and has no place on a log axis)."""
    rows = sorted((r for r in rows if r["energy_min"] > 0.0), key=lambda r: r["energy_min"])
    centres = [np.sqrt(r["energy_min"] * r["energy_max"]) if np.isfinite(r["energy_max"])
               else r["energy_min"] * 10 ** 0.05 for r in rows]
    return np.array(centres), np.array([r["count"] for r in rows], dtype=float)


def size_label(size_min, size_max):
    """'d 128-256 mm' for a size class."""
    hi = "inf" if not np.isfinite(size_max) else f"{size_max * 1e3:.3g}"
    return f"d {size_min * 1e3:.3g}-{hi} mm"


def plot_collisions(run, rows, path):
    """collisions.png: count per log energy bin against peak normal strain energy, log-log,
    one panel per contact type, one line per size class."""
    cells = {}
    for r in rows:
        cells.setdefault(r["type"], {}).setdefault((r["size_min"], r["size_max"]), []).append(r)
    types = [t for t in cells if any(r["count"] > 0 for rs in cells[t].values() for r in rs)]
    ncols = min(3, max(1, len(types)))
    nrows = max(1, -(-len(types) // ncols))
    fig, axes = plt.subplots(nrows, ncols, figsize=(5 * ncols, 4 * nrows), squeeze=False,
                             sharex=True, constrained_layout=True)
    fig.suptitle(f"{run.title}\ncollision energy spectra (contacts that ended, since the start)")
    for ax, kind in zip(axes.flat, types):
        total, energy = 0, 0.0
        for (lo, hi), rs in sorted(cells[kind].items()):
            x, y = spectrum_points(rs)
            total += sum(r["count"] for r in rs)
            energy += rs[0]["energy"]
            if y.sum() > 0:
                ax.step(x, np.where(y > 0, y, np.nan), where="mid", label=size_label(lo, hi))
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_title(f"{kind}: {total} contacts, sum of peaks {energy:.3g} J", fontsize="small")
        ax.set_xlabel("peak normal strain energy [J]")
        ax.set_ylabel("contacts per bin (10 per decade) [-]")
        ax.grid(True, which="both", alpha=0.2)
        ax.legend(fontsize="x-small", title="smaller particle", title_fontsize="x-small")
    for ax in list(axes.flat)[len(types):]:
        ax.axis("off")
    if not types:
        axes[0, 0].text(0.5, 0.5, "no contact has ended", ha="center",
                        transform=axes[0, 0].transAxes)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return len(types)


def animation_frames(names, max_frames):
    """At most max_frames snapshot names, evenly spread, the first and last included."""
    if len(names) <= max_frames:
        return list(names)
    idx = np.unique(np.linspace(0, len(names) - 1, max_frames).round().astype(int))
    return [names[i] for i in idx]


def write_animation(run, f, names, vmax, path, max_frames):
    """The animation through matplotlib's FFMpegWriter (path ending .mp4) or, without ffmpeg,
    its PillowWriter (.gif); returns the number of frames. The layout is fixed and the axes
    bare, so that a frame costs only the drawing of the particles."""
    from matplotlib.animation import FFMpegWriter, PillowWriter  # noqa: PLC0415
    from matplotlib.collections import LineCollection  # noqa: PLC0415

    frames = animation_frames(names, max_frames)
    times = [float(f["snapshots"][n].attrs["time"]) for n in frames]
    spacing = (times[-1] - times[0]) / (len(times) - 1) if len(times) > 1 else 0.05
    fps = int(np.clip(round(1.0 / spacing) if spacing > 0 else 20, 5, 30))
    fig = plt.figure(figsize=(6.4, 6.0), dpi=100)
    ax = fig.add_axes([0.02, 0.02, 0.80, 0.88])
    ax.set_axis_off()
    ax.set_aspect("equal")
    fig.colorbar(ScalarMappable(Normalize(0.0, vmax), "viridis"),
                 cax=fig.add_axes([0.85, 0.12, 0.03, 0.68]), label="speed [m/s]")
    title = fig.text(0.5, 0.97, "", ha="center", va="top", fontsize="small")
    walls = ax.add_collection(LineCollection([], colors="0.15", linewidths=1.5))
    first = millplot.read_snapshot(f, frames[0])
    xlim, ylim = millplot.charge_limits(run.deck, first, millplot.read_outline(f, frames[0]))
    ax.set_xlim(*xlim)
    ax.set_ylim(*ylim)
    circles = None
    if path.endswith(".gif"):
        writer = PillowWriter(fps=fps, metadata={"title": run.title})
    else:
        writer = FFMpegWriter(fps=fps, metadata={"title": run.title}, bitrate=2000,
                              extra_args=["-pix_fmt", "yuv420p"])
    with writer.saving(fig, path, dpi=100):
        for name in frames:
            snap = millplot.read_snapshot(f, name)
            for c in circles or []:  # the rows may change order and size between snapshots
                c.remove()
            circles = millplot.particle_collection(ax, snap, vmax)
            outline = millplot.read_outline(f, name)
            if outline is None:
                outline = millplot.deck_outline(run.deck, snap["time"])
            walls.set_segments([] if outline is None else list(outline))
            title.set_text(f"{run.title}\n{charge_frame_title(run, snap)}")
            writer.grab_frame()
    plt.close(fig)
    return len(frames)


def fmt(value, unit="", digits=4):
    """A number with its unit, or 'unknown'."""
    if value is None or (isinstance(value, float) and not np.isfinite(value)):
        return "unknown"
    return f"{value:.{digits}g} {unit}".strip()


def regime_text(run):
    """The regime for the index: the most frequent over the last half, and the last one."""
    s = run.series
    if "regime" not in s:
        return "unknown (series.csv has no regime column)"
    regime = millplot.dominant_regime(s)
    if regime == millplot.UNCLASSIFIED:
        return (f"not classified (the regime column is '-' over the whole run; the analysis "
                f"window is {millplot.analysis_window(run.info):g} s)")
    last = millplot.regime_at(s, s["time"][-1])
    return f"{regime} (most frequent over the last half; at the end: {last})"


def power_text(run):
    """The one power figure to quote: the mean over the last half with its standard error by
    batch means (millplot.power_estimate)."""
    if run.mean_power is None:
        return "unknown"
    text = fmt(run.mean_power / 1e3, "kW")
    if np.isfinite(run.power_se):
        text += (f" ± {run.power_se / 1e3:.2g} kW (standard error of {run.batches} batch means "
                 f"over {run.batch_kind})")
    return text


def mill_numbers(run):
    """[(quantity, value)] of a drum scene: regime, power and its scaling to a mill."""
    rows = [("regime", regime_text(run)),
            ("mean drive power, last half of the run", power_text(run))]
    rows.append(("slice thickness (2D power is for this slice)",
                 f"{fmt(run.thickness, 'm')} ({run.thickness_source})" if run.thickness
                 else run.thickness_source))
    rows.append(("power per metre of mill length (mean power / slice thickness)",
                 fmt(None if run.per_metre is None else run.per_metre / 1e3, "kW/m")))
    return rows


def key_numbers(run):
    """[(quantity, value)] for the index: speeds, regime, power and its scaling to a mill."""
    s, deck = run.series, run.deck
    drum = deck.get("drum", {})
    wc, w = millplot.critical_speed(deck), millplot.drum_speed(deck)
    rows = [("title", run.title), ("deck", str(run.info.get("deck_path", "unknown")))]
    if drum.get("radius"):
        rows.append(("drum radius", fmt(float(drum["radius"]), "m")))
    if wc:
        rows.append(("critical speed sqrt(g/R)",
                     f"{wc:.4g} rad/s ({wc * millplot.RPM_PER_RAD_S:.4g} rpm)"))
    if w is not None:
        rows.append(("drum speed", f"{w:.4g} rad/s ({w * millplot.RPM_PER_RAD_S:.4g} rpm)"))
    if w is not None and wc:
        rows.append(("fraction of critical speed", f"{abs(w) / wc:.3f}"))
    t = s["time"]
    if len(t):
        rows.append(("simulated", f"{t[-1]:.4g} s, {int(s['particles'][-1])} particles at the end"
                     if "particles" in s else f"{t[-1]:.4g} s"))
    if run.has_drum:
        rows += mill_numbers(run)
    mill = run.info.get("mill")
    if isinstance(mill, dict):
        rows += [(f"run.json mill.{k}", str(v)) for k, v in mill.items()]
    if "wall_time_s" in run.info:
        rows.append(("wall time", f"{float(run.info['wall_time_s']):.3g} s on "
                     f"{run.info.get('ranks', '?')} rank(s)"))
    return rows


def write_markdown(path, run, numbers, files):
    """report.md: key numbers as a table, then the files with captions (images inline)."""
    lines = [f"# {run.title}", "", f"Report on `{os.path.abspath(run.outdir)}` written by "
             "post/report.py.", "", "## Key numbers", "", "| quantity | value |", "| --- | --- |"]
    lines += [f"| {q} | {v} |" for q, v in numbers]
    lines += ["", run.caption().replace("\n", " "), "", "## Files", ""]
    for name, caption in files:
        lines.append(f"- [{name}]({name}): {caption}")
    lines.append("")
    for name, _ in files:
        if name.endswith(".png"):
            lines += [f"![{name}]({name})", ""]
    with open(path, "w", encoding="utf-8") as fh:
        fh.write("\n".join(lines))


def write_html(path, run, numbers, files):
    """index.html: the same as report.md, with the pictures shown."""
    e = html.escape
    parts = [f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{e(run.title)}</title>"
             "</head><body style='font-family:sans-serif;max-width:1100px'>",
             f"<h1>{e(run.title)}</h1><p>{e(os.path.abspath(run.outdir))}</p>",
             "<h2>Key numbers</h2><table border='1' cellpadding='4' style='border-collapse:"
             "collapse'>"]
    parts += [f"<tr><td>{e(q)}</td><td>{e(v)}</td></tr>" for q, v in numbers]
    parts += [f"</table><p>{e(run.caption())}</p><h2>Files</h2><ul>"]
    parts += [f"<li><a href='{e(n)}'>{e(n)}</a>: {e(c)}</li>" for n, c in files]
    parts.append("</ul>")
    for name, caption in files:
        if name.endswith(".png"):
            parts.append(f"<h3>{e(name)}</h3><p>{e(caption)}</p><img src='{e(name)}' "
                         "style='max-width:100%'>")
        elif name.endswith(".gif"):
            parts.append(f"<h3>{e(name)}</h3><p>{e(caption)}</p><img src='{e(name)}' "
                         "style='max-width:100%'>")
        elif name.endswith(".mp4"):
            parts.append(f"<h3>{e(name)}</h3><video src='{e(name)}' controls "
                         "style='max-width:100%'></video>")
    parts.append("</body></html>\n")
    with open(path, "w", encoding="utf-8") as fh:
        fh.write("\n".join(parts))


def snapshot_pictures(run, reportdir, args, files):
    """The charge pictures and the animation; appends (file, caption) to files."""
    import h5py  # noqa: PLC0415

    with h5py.File(run.h5_path, "r") as f:
        names = millplot.list_snapshots(f)
        if not names:
            print("report.py: snapshots.h5 holds no snapshot: no charge pictures")
            return
        vmax = speed_scale(f, names)
        walls = ("with the drum and lifters, toe and shoulder marked" if run.has_drum
                 else "with the walls")
        for name in pick_snapshots(names, args.snapshots):
            time = float(f["snapshots"][name].attrs["time"])
            out = charge_file_name(time)
            plot_charge(run, f, name, vmax, os.path.join(reportdir, out))
            files.append((out, f"the charge at t = {time:.3g} s, coloured by speed "
                          f"(0-{vmax:.3g} m/s), {walls}"))
        if args.no_animation:
            return
        movie = "charge.mp4" if shutil.which("ffmpeg") else "charge.gif"
        if movie.endswith(".gif"):
            print("report.py: ffmpeg is not on the PATH: the animation is a GIF (charge.gif)")
        frames = write_animation(run, f, names, vmax, os.path.join(reportdir, movie),
                                 args.max_frames)
        files.append((movie, f"animation of the charge coloured by speed, {frames} "
                      f"frames from {len(names)} snapshots"))


REPORT_FILES = re.compile(r"^(energies|power|charge_shape|collisions|charge_\d+\.\d+s)\.png$"
                          r"|^(charge\.mp4|charge\.gif|report\.md|index\.html)$")


def remove_stale(reportdir):
    """Removes the files an earlier report wrote into reportdir (only names this script
    writes), so that the folder holds this run's pictures only."""
    for name in os.listdir(reportdir):
        if REPORT_FILES.match(name):
            os.remove(os.path.join(reportdir, name))


def series_pictures(run, reportdir, args, files):
    """energies.png, power.png and charge_shape.png; appends (file, caption) to files."""
    plot_energies(run, os.path.join(reportdir, "energies.png"))
    files.append(("energies.png", "energies and drive work [kJ] against time (potential "
                  "relative to its start)"))
    if run.has_drum and "drum_power" in run.series:
        plot_power(run, os.path.join(reportdir, "power.png"), args.window)
        files.append(("power.png", "drive power of the 2D slice [kW]: raw samples (one per series "
                      "row) faint, time average bold; per metre of mill length on the right axis"))
    if run.has_drum and "toe_angle" in run.series:
        plot_charge_shape(run, os.path.join(reportdir, "charge_shape.png"))
        files.append(("charge_shape.png", "toe, shoulder and bed surface angles [deg], airborne "
                      "and corotating fractions [%] against time; regimes shaded"))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter,
                                     epilog="\n".join(__doc__.split("\n")[4:]))
    parser.add_argument("outdir", help="a dem2d output folder (series.csv, run.json, ...)")
    parser.add_argument("-o", "--output", help="folder for the report (default: OUTDIR/report)")
    parser.add_argument("--snapshots", type=int, default=4,
                        help="charge pictures evenly spaced over the run, the last included "
                        "(default 4)")
    parser.add_argument("--max-frames", type=int, default=200,
                        help="most frames in charge.mp4 (default 200)")
    parser.add_argument("--no-animation", action="store_true", help="skip charge.mp4")
    parser.add_argument("--window", type=float,
                        help="average the power over a centred window of this many seconds "
                        "(default: series.csv's power_avg column)")
    args = parser.parse_args(argv)
    args.max_frames = max(1, min(args.max_frames, 200))
    start = clock.monotonic()
    try:
        run = Run(args.outdir)
    except (OSError, ValueError) as e:
        print(f"report.py: {e}", file=sys.stderr)
        return 1
    reportdir = args.output or os.path.join(args.outdir, "report")
    os.makedirs(reportdir, exist_ok=True)
    remove_stale(reportdir)
    files = []
    series_pictures(run, reportdir, args, files)
    if os.path.exists(run.h5_path):
        try:
            snapshot_pictures(run, reportdir, args, files)
        except (OSError, KeyError) as e:  # a file still being written, or not dem2d's
            print(f"report.py: cannot read {run.h5_path}: {e}: no charge pictures",
                  file=sys.stderr)
    collisions = os.path.join(args.outdir, "collisions.csv")
    if os.path.exists(collisions):
        kinds = plot_collisions(run, millplot.read_collisions(collisions),
                                os.path.join(reportdir, "collisions.png"))
        files.append(("collisions.png", f"collision energy spectra of {kinds} contact types: "
                      "contacts per log bin of peak normal strain energy [J], per size class"))
    else:
        print("report.py: no collisions.csv (set output.collision_spectra = true): no spectra")
    numbers = key_numbers(run)
    write_markdown(os.path.join(reportdir, "report.md"), run, numbers, files)
    write_html(os.path.join(reportdir, "index.html"), run, numbers, files)
    for name, caption in files:
        print(f"  {name}: {caption}")
    print(f"{reportdir}: {len(files)} files, report.md and index.html "
          f"({clock.monotonic() - start:.1f} s)")
    for quantity, value in numbers[2:]:
        print(f"  {quantity}: {value}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
