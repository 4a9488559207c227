#!/usr/bin/python3
"""Compare drum runs that differ in the particles' shape (inputs/shapes.in and its variants).

    post/compare_shapes.py OUT_DISCS OUT_SQUARES OUT_ELLIPSES [--window 2] [-o shapes.png]
                           [--json shapes.json]

Each OUT is a dem2d output folder of the same drum with a charge of one shape; the first is the
reference of the ratios. Over the last `window` seconds of each run (the second drum turn of a
4 s run at 30 rpm) it reads:
  - series.csv: the mean shoulder and toe angles (deg from the downward vertical, positive in
    the drum's sense of rotation: how high the charge is carried) and the mean drive power (W
    per slice);
  - snapshots.h5: the particles' speeds in every snapshot of the window: mean, median, 90th
    percentile and their histogram (the velocity distribution);
  - lifters.csv, when the run wrote one: the normal load on the lifter bars against their angle,
    folded onto one angle axis, its peak bin mean and the loaded window around it (the bins
    above 10 % of it), as post/plot_lifters.py reads them; with a [shell] (inputs/shell.in) also
    the bars' largest tip deflection, the peak of their mean tip deflection per angle bin and
    its angle, and the largest root stress.
It prints a table with each figure's ratio to the reference (angles: the difference in
degrees), writes the figures as JSON (--json), and draws the last snapshot of each run side by
side with the speed histograms and the lifter loads (-o). Exit 1 when a folder lacks what it
needs, 2 on bad arguments.
"""

import argparse
import csv
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import millplot  # noqa: E402
import plot_lifters  # noqa: E402


def label_of(run, folder):
    """The run's shape as its deck and overrides say it ("discs", "superellipse n=8 aspect 1")."""
    deck = millplot.deck_of(run)
    fills = deck.get("fill", [])
    f = fills[0] if fills else {}
    if f.get("shape", "disc") != "superellipse":
        return "discs"
    return f"superellipse n={f.get('exponent', 2.0):g} aspect {f.get('aspect', 1.0):g}"


def lifter_figures(path, window, bins=72):
    """plot_lifters.py's figures of the last `window` seconds of lifters.csv (its peak of the mean
    normal load per angle bin and the loaded window around it), and the mean profile; None
    without the file."""
    if not os.path.exists(path):
        return None
    data = plot_lifters.select_window(plot_lifters.read_lifters(path), window)
    if len(data["time"]) == 0:
        return None
    mean, _ = plot_lifters.binned(data["angle_deg"], data["normal_N"], bins)
    centres = (np.arange(bins) + 0.5) * 360.0 / bins
    return plot_lifters.figures(data, bins), centres, mean


def measure(folder, window):
    """The figures of one run (see the module's docstring)."""
    run = millplot.read_run_json(folder)
    series_path = os.path.join(folder, "series.csv")
    snaps_path = os.path.join(folder, "snapshots.h5")
    for path in (series_path, snaps_path):
        if not os.path.exists(path):
            raise FileNotFoundError(f"{path} is missing")
    s = millplot.read_series(series_path)
    t = s["time"]
    t0 = t[-1] - window
    tail = t >= t0
    out = {"folder": folder, "label": label_of(run, folder), "window_s": [float(t0), float(t[-1])],
           "charge_mass_kg": run.get("charge_mass_kg"), "particles": int(s["particles"][-1]),
           "shoulder_angle_deg": float(np.nanmean(s["shoulder_angle"][tail])),
           "toe_angle_deg": float(np.nanmean(s["toe_angle"][tail])),
           "power_W": float(np.mean(s["drum_power"][tail]))}
    import h5py
    speeds, last = [], None
    with h5py.File(snaps_path, "r") as f:
        for name in millplot.list_snapshots(f):
            snap = millplot.read_snapshot(f, name)
            if snap["time"] >= t0:
                speeds.append(snap["speed"])
                last = (snap, millplot.read_outline(f, name))
    if not speeds:
        raise ValueError(f"{snaps_path} holds no snapshot in the last {window} s")
    v = np.concatenate(speeds)
    out.update({"speed_mean": float(v.mean()), "speed_median": float(np.median(v)),
                "speed_p90": float(np.percentile(v, 90.0)), "snapshots": len(speeds)})
    lifters = lifter_figures(os.path.join(folder, "lifters.csv"), window)
    if lifters is not None:
        fig, centres, mean = lifters
        out["lifter_peak_normal_N"] = fig["mean_peak_normal_N"]
        out["lifter_peak_angle_deg"] = fig["mean_peak_angle_deg"]
        out["lifter_loaded_window_deg"] = [fig["loaded_from_deg"], fig["loaded_to_deg"]]
        out["_lifter_profile"] = (centres, mean)
        if "peak_tip_deflection_m" in fig:  # the run had a [shell]
            out["tip_peak_m"] = fig["peak_tip_deflection_m"]
            out["tip_mean_peak_m"] = fig["mean_peak_tip_deflection_m"]
            out["tip_mean_peak_angle_deg"] = fig["mean_peak_tip_angle_deg"]
            out["root_stress_peak_Pa"] = fig["peak_root_stress_Pa"]
    out["_speeds"] = v
    out["_last"] = last
    out["_deck"] = millplot.deck_of(run)
    return out


FIGURES = [("shoulder_angle_deg", "shoulder angle [deg]"), ("toe_angle_deg", "toe angle [deg]"),
           ("power_W", "drive power [W]"), ("speed_mean", "mean speed [m/s]"),
           ("speed_median", "median speed [m/s]"), ("speed_p90", "90th pct speed [m/s]"),
           ("lifter_peak_normal_N", "lifter mean normal load, peak [N]"),
           ("lifter_peak_angle_deg", "... at the angle [deg]"),
           ("tip_peak_m", "lifter tip deflection, max [m]"),
           ("tip_mean_peak_m", "lifter tip, mean's peak [m]"),
           ("tip_mean_peak_angle_deg", "... at the angle [deg]"),
           ("root_stress_peak_Pa", "lifter root stress, max [Pa]")]


def table(runs):
    """Each figure of each run with its ratio to the first run's (angles: the difference, deg)."""
    ref = runs[0]
    w = 32
    lines = [f"{'':28s}" + "".join(f"{r['label'][:w - 2]:>{w}s}" for r in runs)]
    lines.append(f"{'charge mass [kg]':28s}" +
                 "".join(f"{r['charge_mass_kg'] or float('nan'):>{w}.4g}" for r in runs))
    for key, name in FIGURES:
        if key not in ref:
            continue
        cells = []
        for r in runs:
            value = r.get(key, float("nan"))
            if key.endswith("_deg"):
                change = (value - ref[key] + 180.0) % 360.0 - 180.0
                cells.append(f"{value:>10.4g} ({change:+6.1f})")
            else:
                ratio = value / ref[key] if ref[key] else float("nan")
                cells.append(f"{value:>10.4g} ({ratio:5.2f}x)")
        lines.append(f"{name:28s}" + "".join(f"{c:>{w}s}" for c in cells))
    if "lifter_loaded_window_deg" in ref:
        lines.append(f"{'lifter loaded [deg]':28s}" + "".join(
            f"{'%.0f-%.0f' % tuple(r['lifter_loaded_window_deg']) if r.get('lifter_loaded_window_deg') else '-':>{w}s}"
            for r in runs))
    return "\n".join(lines)


def draw(runs, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    n = len(runs)
    has_lifters = all("_lifter_profile" in r for r in runs)
    fig, axes = plt.subplots(2, n + (1 if has_lifters else 0), figsize=(4.2 * (n + has_lifters), 8.4),
                             squeeze=False)
    vmax = max(float(np.percentile(r["_speeds"], 99.0)) for r in runs)
    for k, r in enumerate(runs):
        snap, outline = r["_last"]
        millplot.draw_charge(axes[0][k], snap, outline, r["_deck"], vmax)
        axes[0][k].set_title(f"{r['label']}\nt = {snap['time']:.2f} s")
        axes[1][k].hist(r["_speeds"], bins=40, range=(0.0, vmax), density=True, color="tab:blue")
        axes[1][k].set_xlabel("speed [m/s]")
        axes[1][k].set_ylabel("probability density [s/m]")
        axes[1][k].set_title(f"mean {r['speed_mean']:.3f} m/s")
    if has_lifters:
        ax = axes[0][n]
        for r in runs:
            centres, mean = r["_lifter_profile"]
            ax.plot(centres, mean, label=r["label"])
        ax.set_xlabel("lifter angle from the bottom [deg]")
        ax.set_ylabel("mean normal load [N]")
        ax.legend(fontsize=8)
        axes[1][n].axis("off")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("folders", nargs="+", help="dem2d output folders; the first is the reference")
    parser.add_argument("--window", type=float, default=2.0, help="the last seconds compared [2]")
    parser.add_argument("-o", "--output", help="draw the comparison to this PNG")
    parser.add_argument("--json", help="write the figures to this JSON file")
    args = parser.parse_args(argv)
    if not args.window > 0.0:
        parser.error("--window must be > 0")
    try:
        runs = [measure(folder, args.window) for folder in args.folders]
    except (OSError, ValueError, KeyError) as e:
        print(f"compare_shapes.py: {e}", file=sys.stderr)
        return 1
    print(table(runs))
    masses = [r["charge_mass_kg"] for r in runs if r["charge_mass_kg"]]
    if masses and max(masses) - min(masses) > 1e-9 * max(masses):
        print("note: the charges' masses differ: " + ", ".join(f"{m:.6g}" for m in masses))
    if args.json:
        with open(args.json, "w") as f:
            json.dump([{k: v for k, v in r.items() if not k.startswith("_")} for r in runs], f,
                      indent=1)
    if args.output:
        draw(runs, args.output)
    return 0


if __name__ == "__main__":
    sys.exit(main())
