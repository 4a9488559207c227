#!/usr/bin/python3
"""Plot a dem2d series.csv: energies, the drive's power and torque, and the energy balance.

    post/plot_series.py OUT/series.csv [-o series.png] [--title T] [--window S]

Four panels against time:
  - the energies in kJ: kinetic, rotational, potential (relative to its first value), elastic,
    dissipated, and the drive work;
  - the drive power in kW: the raw samples (one per series row, 1 ms by default: they spike at
    every impact) faint, and the averaged power bold: the `power_avg` column (the drive's mean
    over the trailing `output.analysis_window`) when the series has it, else a centred moving
    average over --window seconds. The right-hand axis gives the power per metre of mill
    length (see below);
  - the drive torque in kN m, raw and averaged (and the shell/lifter split when lifters work);
  - the energy-balance residual (docs/output.md)

        kinetic + rotational + potential + elastic + dissipated - drive_work - its first value

    (ore scenes: - fed_energy + discharged_energy as well), which should stay near zero; its
    size relative to the largest energy term measures how well the run conserves energy.

What the 2D power stands for: the particles are spheres moving in a plane, so the model is a
slice of the mill one ball diameter thick, and its power is that slice's. The power per metre
of mill length is P / thickness, and a mill L metres long draws about L x P / thickness. The
thickness is run.json's mill.slice_thickness_m when present, else the largest particle diameter
in snapshots.h5 (both beside the CSV). The title is run.json's deck title (--title overrides).
The figure is written as a PNG (default: series.png beside the CSV) and a one-line summary is
printed.
"""

import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.dont_write_bytecode = True  # no __pycache__ beside the installed scripts
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import millplot  # noqa: E402

ENERGIES = [
    ("kinetic_energy", "kinetic"),
    ("rotational_energy", "rotational"),
    ("potential_energy", "potential"),
    ("elastic_energy", "elastic"),
    ("dissipated_energy", "dissipated"),
    ("drive_work", "drive work"),
]


def read_series(path):
    """The CSV as a dict of column name -> array (float; text columns such as regime: str)."""
    return millplot.read_series(path)


def energy_residual(s):
    """Total energy minus drive work, relative to the first row [J], and the energy scale [J]."""
    zero = np.zeros_like(s["time"])
    total = (
        s.get("kinetic_energy", zero)
        + s.get("rotational_energy", zero)
        + s.get("potential_energy", zero)
        + s.get("elastic_energy", zero)
        + s.get("dissipated_energy", zero)
        - s.get("drive_work", zero)
        - s.get("fed_energy", zero)  # ore scenes: energy carried in and out
        + s.get("discharged_energy", zero)
    )
    residual = total - total[0] if len(total) else total
    terms = [np.abs(s[c] - (s[c][0] if c == "potential_energy" else 0.0))
             for c, _ in ENERGIES if c in s and len(s[c])]
    scale = max((float(np.max(t)) for t in terms), default=0.0)
    return residual, scale


def plot_energies(ax, s):
    """Energies and drive work in kJ (potential relative to its first value)."""
    t = s["time"]
    for column, label in ENERGIES:
        if column not in s:
            continue
        values = s[column]
        if column == "potential_energy" and len(values):
            values = values - values[0]
            label = "potential - initial"
        ax.plot(t, values / 1e3, label=label, linewidth=1.2)
    ax.set_ylabel("energy [kJ]")
    ax.legend(loc="upper left", fontsize="small", ncol=2)
    ax.grid(True, alpha=0.3)


def lifters_work(s):
    """True when the series splits the drive between shell and lifters and the lifters work."""
    return "lifter_power" in s and bool(np.any(s["lifter_power"] != 0.0))


def plot_power(ax, s, average, average_label, thickness):
    """Raw power samples faint, the averaged power bold, in kW; kW per metre on the right."""
    t = s["time"]
    ax.plot(t, s["drum_power"] / 1e3, color="tab:red", alpha=0.25, linewidth=0.5,
            label="drive power, raw samples")
    ax.plot(t, average / 1e3, color="tab:red", linewidth=2.2, label=f"drive power, {average_label}")
    ax.axhline(0.0, color="0.5", linewidth=0.6)
    ax.set_ylabel("drive power of the 2D slice [kW]")
    finite = average[np.isfinite(average)]
    if finite.size:  # keep the averaged curve readable: the raw spikes may leave the axes
        top = max(float(finite.max()) * 1.6, 1e-9) / 1e3
        bottom = min(float(finite.min()) * 1.6, -0.1 * top * 1e3) / 1e3
        ax.set_ylim(bottom, top)
    if thickness:
        sec = ax.secondary_yaxis("right", functions=(lambda p: p / thickness,
                                                     lambda q: q * thickness))
        sec.set_ylabel("per metre of mill length [kW/m]")
    ax.legend(loc="upper left", fontsize="small")
    ax.grid(True, alpha=0.3)


def plot_torque(ax, s, window):
    """Drive torque in kN m: raw faint, centred moving average bold; shell and lifter parts."""
    t = s["time"]
    ax.plot(t, s["drum_torque"] / 1e3, color="tab:blue", alpha=0.25, linewidth=0.5,
            label="drive torque, raw samples")
    ax.plot(t, millplot.moving_average(t, s["drum_torque"], window) / 1e3, color="tab:blue",
            linewidth=2.0, label=f"drive torque, centred moving average over {window:g} s")
    if lifters_work(s):
        for column, color, label in [("shell_torque", "tab:cyan", "shell"),
                                     ("lifter_torque", "tab:purple", "lifters")]:
            ax.plot(t, millplot.moving_average(t, s[column], window) / 1e3, color=color,
                    linewidth=1.4, label=f"{label} part (averaged)")
    avg = millplot.moving_average(t, s["drum_torque"], window)
    if avg.size:
        ax.set_ylim(min(1.6 * float(avg.min()), 0.0) / 1e3, max(1.6 * float(avg.max()), 1e-9) / 1e3)
    ax.set_ylabel("drive torque [kN m]")
    ax.legend(loc="upper left", fontsize="small")
    ax.grid(True, alpha=0.3)


def plot_residual(ax, s, residual, scale):
    """The energy-balance residual in J."""
    ax.plot(s["time"], residual, color="black")
    ax.set_ylabel("energy residual [J]")
    ax.set_xlabel("time [s]")
    rel = float(np.max(np.abs(residual))) / scale if scale > 0 and len(residual) else 0.0
    ax.set_title(f"K + R + P + E + D - W - initial   (max |residual| / energy scale = {rel:.3g})",
                 fontsize="small")
    ax.grid(True, alpha=0.3)


def plot(s, title, out, run=None, thickness=None, thickness_source="", window=None):
    """Draws the four panels and the slice caption into `out`; returns (residual, scale)."""
    run = run or {}
    residual, scale = energy_residual(s)
    has_drive = "drum_power" in s and millplot.has_drum(millplot.deck_of(run), s)
    average, average_label = (millplot.averaged_power(s, run, window) if has_drive
                              else (None, ""))
    torque_window = window if window is not None else millplot.analysis_window(run)
    mean = millplot.mean_power(s) if has_drive and len(s["time"]) else None
    per_metre = millplot.mill_scaling(thickness, mean)

    fig, axes = plt.subplots(5, 1, figsize=(10, 13), sharex=False, constrained_layout=True,
                             gridspec_kw={"height_ratios": [3, 3, 2.2, 2, 0.35]})
    fig.suptitle(title)
    plot_energies(axes[0], s)
    if has_drive:
        plot_power(axes[1], s, average, average_label, thickness)
        plot_torque(axes[2], s, torque_window)
    else:
        for ax in axes[1:3]:
            ax.text(0.5, 0.5, "no drum in this scene: no drive power or torque", ha="center",
                    va="center", transform=ax.transAxes, color="0.4")
    for ax in axes[:3]:
        ax.sharex(axes[3])
        ax.tick_params(labelbottom=False)
    plot_residual(axes[3], s, residual, scale)
    caption = axes[4]
    caption.axis("off")
    if has_drive:
        text = millplot.slice_caption(thickness, thickness_source, mean, per_metre)
        caption.text(0.0, 1.0, text + "  Mean over the last half of the run.", va="top",
                     ha="left", fontsize="small", transform=caption.transAxes, wrap=True)
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return residual, scale


def main(argv=None):
    parser = argparse.ArgumentParser(
        description=__doc__.split("\n")[0],
        epilog="Reads run.json and snapshots.h5 beside the CSV when present (title, slice "
        "thickness).")
    parser.add_argument("series", help="series.csv written by dem2d")
    parser.add_argument("-o", "--output", help="PNG to write (default: series.png beside the CSV)")
    parser.add_argument("--title", help="figure title (default: the deck's title from run.json)")
    parser.add_argument("--window", type=float,
                        help="average the power over a centred window of this many seconds "
                        "(default: the power_avg column; without it, the run's analysis window, "
                        "1 s unless the deck sets output.analysis_window)")
    args = parser.parse_args(argv)
    try:
        s = read_series(args.series)
    except (OSError, ValueError) as e:
        print(f"plot_series.py: {e}", file=sys.stderr)
        return 1
    folder = os.path.dirname(os.path.abspath(args.series))
    run = millplot.read_run_json(folder)
    title = args.title or millplot.run_title(run, f"dem2d run in {os.path.basename(folder)}")
    thickness, source = millplot.slice_thickness(run, os.path.join(folder, "snapshots.h5"))
    out = args.output or os.path.join(folder, "series.png")
    residual, scale = plot(s, title, out, run, thickness, source, args.window)
    n = len(s["time"])
    worst = float(np.max(np.abs(residual))) if n else 0.0
    span = f"t = {s['time'][0]:g} .. {s['time'][-1]:g} s" if n else "no rows"
    power = ""
    if n and "drum_power" in s and millplot.has_drum(millplot.deck_of(run), s):
        power = f", mean power over the last half {millplot.mean_power(s) / 1e3:.4g} kW"
    print(f"{out}: {n} rows, {span}{power}, max |energy residual| = {worst:.6g} J"
          f" ({worst / scale if scale > 0 else 0.0:.3g} of the energy scale {scale:.6g} J)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
