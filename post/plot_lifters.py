#!/usr/bin/python3
"""Plot the load on the lifter bars against their angle, from a dem2d lifters.csv.

    post/plot_lifters.py OUT/lifters.csv [-o lifters.png] [--window T] [--bins N] [--json F]
                         [--title T]

lifters.csv has one row per bar per series row (docs/output.md): time, lifter, angle_deg (the
bar's position from the bottom of the drum, in its sense of rotation), normal_N (the charge's
load on the bar's lifting face), radial_N (its load along the bar, outward positive),
torque_Nm and contacts. Forces are those of the 2D model: per slice, N. With a [shell] in the
deck it also has the shell's response per bar: tip_deflection_m (the bar's tip pushed back,
against the drum's rotation), von_mises_max_Pa (the bar's peak von Mises stress, which depends
on the mesh) and root_stress_Pa (the nominal stress of its root section).

All bars are folded onto one angle axis: every row of every bar falls into its angle's bin
(--bins over 0-360 degrees, default 72: 5 degrees). Two panels, normal and radial load against
the angle: the rows faint, the mean per bin and the largest per bin; with the shell's columns
two more, the tip deflection and the stresses. --window T keeps the rows of the last T seconds
(default: all).

Printed, and with --json written to F (one object):
  - the peak: the largest normal_N of the rows kept (`peak_normal_N`), at which angle, time and
    bar; the largest radial_N (`peak_radial_N`);
  - the mean profile's peak (`mean_peak_normal_N`, at `mean_peak_angle_deg`, a bin's centre);
  - the loaded angle window: the bins around the mean profile's peak whose mean normal load
    exceeds 10 % of that peak, as `loaded_from_deg` to `loaded_to_deg` (bin edges, in the sense
    of rotation; `loaded_to_deg` may exceed 360 when the window passes the bottom), or null
    when no bar carries any load;
  - with the shell's columns: the largest tip deflection (`peak_tip_deflection_m`, at
    `peak_tip_angle_deg`, bar `peak_tip_lifter`), the mean profile's peak
    (`mean_peak_tip_deflection_m` at `mean_peak_tip_angle_deg`), and the largest von Mises and
    root stresses (`peak_von_mises_Pa`, `peak_root_stress_Pa`).
The figure is a PNG (default: lifters.png beside the CSV), titled with run.json's deck title
(--title overrides).
"""

import argparse
import csv
import json
import os
import sys
import textwrap

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.dont_write_bytecode = True  # no __pycache__ beside the installed scripts
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import millplot  # noqa: E402

COLUMNS = ["time", "lifter", "angle_deg", "normal_N", "radial_N", "torque_Nm", "contacts"]
SHELL_COLUMNS = ["tip_deflection_m", "von_mises_max_Pa", "root_stress_Pa"]
LOADED_FRACTION = 0.1


def read_lifters(path):
    """The CSV as a dict of column name -> numpy array."""
    with open(path, newline="") as f:
        reader = csv.reader(f)
        header = next(reader, None)
        if header not in (COLUMNS, COLUMNS + SHELL_COLUMNS):
            raise SystemExit(f"{path}: not a lifters.csv (columns {header}, expected {COLUMNS}, "
                             f"with the shell's {SHELL_COLUMNS} after them)")
        rows = [r for r in reader if r]
    data = {c: np.array([float(r[k]) for r in rows]) for k, c in enumerate(header)}
    return data


def has_shell(data):
    return SHELL_COLUMNS[0] in data


def select_window(data, window):
    """The rows of the last `window` seconds (all rows when window is None)."""
    if window is None or len(data["time"]) == 0:
        return data
    start = data["time"].max() - window
    keep = data["time"] >= start
    return {c: v[keep] for c, v in data.items()}


def binned(angle, values, bins):
    """Mean and max of `values` per angle bin (NaN where a bin has no row)."""
    index = np.minimum((angle / (360.0 / bins)).astype(int), bins - 1)
    mean = np.full(bins, np.nan)
    peak = np.full(bins, np.nan)
    for b in range(bins):
        v = values[index == b]
        if len(v):
            mean[b] = v.mean()
            peak[b] = v.max()
    return mean, peak


def loaded_window(mean, bins):
    """(first bin, number of bins) of the run of bins around the mean's peak above 10 % of it,
    or None when the mean is nowhere positive."""
    filled = np.where(np.isnan(mean), -np.inf, mean)
    top = int(np.argmax(filled))
    peak = filled[top]
    if not peak > 0.0:
        return None
    threshold = LOADED_FRACTION * peak
    first, count = top, 1
    while count < bins and filled[(first - 1) % bins] > threshold:
        first = (first - 1) % bins
        count += 1
    while count < bins and filled[(first + count) % bins] > threshold:
        count += 1
    return first, count


def figures(data, bins):
    """The printed and --json figures."""
    n = len(data["time"])
    out = {
        "rows": n,
        "bars": int(len(set(data["lifter"].astype(int)))) if n else 0,
        "time_from_s": float(data["time"].min()) if n else None,
        "time_to_s": float(data["time"].max()) if n else None,
        "bins": bins,
        "bin_width_deg": 360.0 / bins,
    }
    if n == 0:
        return out
    k = int(np.argmax(data["normal_N"]))
    out["peak_normal_N"] = float(data["normal_N"][k])
    out["peak_angle_deg"] = float(data["angle_deg"][k])
    out["peak_time_s"] = float(data["time"][k])
    out["peak_lifter"] = int(data["lifter"][k])
    out["peak_radial_N"] = float(data["radial_N"].max())
    mean, _ = binned(data["angle_deg"], data["normal_N"], bins)
    width = 360.0 / bins
    filled = np.where(np.isnan(mean), -np.inf, mean)
    top = int(np.argmax(filled))
    out["mean_peak_normal_N"] = float(filled[top])
    out["mean_peak_angle_deg"] = (top + 0.5) * width
    window = loaded_window(mean, bins)
    out["loaded_threshold_N"] = LOADED_FRACTION * float(filled[top]) if window else None
    out["loaded_from_deg"] = window[0] * width if window else None
    out["loaded_to_deg"] = (window[0] + window[1]) * width if window else None
    if has_shell(data):
        tip = data["tip_deflection_m"]
        k = int(np.argmax(tip))
        out["peak_tip_deflection_m"] = float(tip[k])
        out["peak_tip_angle_deg"] = float(data["angle_deg"][k])
        out["peak_tip_time_s"] = float(data["time"][k])
        out["peak_tip_lifter"] = int(data["lifter"][k])
        mean_tip, _ = binned(data["angle_deg"], tip, bins)
        filled = np.where(np.isnan(mean_tip), -np.inf, mean_tip)
        top = int(np.argmax(filled))
        out["mean_peak_tip_deflection_m"] = float(filled[top])
        out["mean_peak_tip_angle_deg"] = (top + 0.5) * width
        out["peak_von_mises_Pa"] = float(data["von_mises_max_Pa"].max())
        out["peak_root_stress_Pa"] = float(data["root_stress_Pa"].max())
    return out


def plot(data, bins, fig_out, path_png, title):
    width = 360.0 / bins
    centres = (np.arange(bins) + 0.5) * width
    panels = [("normal_N", "normal load on the lifting face (N per slice)", 1.0),
              ("radial_N", "radial load, outward (N per slice)", 1.0)]
    if has_shell(data):
        panels += [("tip_deflection_m", "tip deflection, pushed back (µm)", 1e6),
                   ("root_stress_Pa", "root section's nominal stress (MPa)", 1e-6),
                   ("von_mises_max_Pa", "peak von Mises stress in the bar (MPa)", 1e-6)]
    fig, axes = plt.subplots(len(panels), 1, figsize=(9, 3.5 * len(panels)), sharex=True)
    for ax, (column, label, scale) in zip(axes, panels):
        values = scale * data[column]
        mean, peak = binned(data["angle_deg"], values, bins)
        ax.plot(data["angle_deg"], values, ".", color="0.75", ms=2, label="rows")
        ax.plot(centres, mean, "-", color="C0", lw=2, label="mean per bin")
        ax.plot(centres, peak, "-", color="C3", lw=1, label="max per bin")
        ax.axhline(0.0, color="k", lw=0.5)
        if fig_out.get("loaded_from_deg") is not None:
            lo, hi = fig_out["loaded_from_deg"], fig_out["loaded_to_deg"]
            for shift in (0.0, -360.0):
                ax.axvspan(lo + shift, hi + shift, color="C2", alpha=0.12)
        ax.set_ylabel(label)
        ax.legend(loc="upper right", fontsize=8)
        ax.grid(alpha=0.3)
    axes[-1].set_xlim(0.0, 360.0)
    axes[-1].set_xticks(np.arange(0, 361, 45))
    axes[-1].set_xlabel("bar angle from the bottom of the drum, in its sense of rotation (deg)")
    if fig_out.get("loaded_from_deg") is not None:
        axes[0].set_title("shaded: the loaded window (mean normal load above 10 % of its peak)",
                          fontsize=9)
    fig.suptitle("\n".join(textwrap.wrap(title, 95)), fontsize=10)
    fig.tight_layout()
    fig.savefig(path_png, dpi=100)
    plt.close(fig)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("csv", help="lifters.csv (or the run's output folder)")
    parser.add_argument("-o", "--output", help="PNG to write (default: lifters.png beside it)")
    parser.add_argument("--window", type=float, help="only the last T seconds")
    parser.add_argument("--bins", type=int, default=72, help="angle bins over 360 deg (72)")
    parser.add_argument("--json", help="write the printed figures to this JSON file")
    parser.add_argument("--title", help="the figure's title")
    args = parser.parse_args(argv)
    path = args.csv
    if os.path.isdir(path):
        path = os.path.join(path, "lifters.csv")
    if args.bins < 1:
        parser.error("--bins must be at least 1")
    if args.window is not None and not args.window > 0.0:
        parser.error("--window must be positive")
    data = select_window(read_lifters(path), args.window)
    out = figures(data, args.bins)
    png = args.output or os.path.join(os.path.dirname(os.path.abspath(path)), "lifters.png")
    folder = os.path.dirname(os.path.abspath(path))
    title = args.title or millplot.run_title(millplot.read_run_json(folder), folder)
    title = f"lifter loads: {title}"
    if out["rows"] == 0:
        print(f"{path}: no rows" + (f" in the last {args.window} s" if args.window else ""))
    else:
        plot(data, args.bins, out, png, title)
        print(f"rows: {out['rows']} ({out['bars']} bars, t = {out['time_from_s']:.6g} to "
              f"{out['time_to_s']:.6g} s)")
        print(f"peak normal load: {out['peak_normal_N']:.9g} N at {out['peak_angle_deg']:.6g} deg "
              f"(bar {out['peak_lifter']}, t = {out['peak_time_s']:.6g} s)")
        print(f"peak radial load: {out['peak_radial_N']:.9g} N")
        print(f"mean normal load: peak {out['mean_peak_normal_N']:.6g} N at "
              f"{out['mean_peak_angle_deg']:.6g} deg")
        if out["loaded_from_deg"] is None:
            print("loaded window: none (no bar carries a load)")
        else:
            print(f"loaded window: {out['loaded_from_deg']:.6g} to {out['loaded_to_deg']:.6g} deg "
                  f"(mean normal load above {out['loaded_threshold_N']:.6g} N, 10 % of its peak)")
        if has_shell(data):
            print(f"peak tip deflection: {out['peak_tip_deflection_m']:.6g} m at "
                  f"{out['peak_tip_angle_deg']:.6g} deg (bar {out['peak_tip_lifter']}, t = "
                  f"{out['peak_tip_time_s']:.6g} s); mean profile's peak "
                  f"{out['mean_peak_tip_deflection_m']:.6g} m at "
                  f"{out['mean_peak_tip_angle_deg']:.6g} deg")
            print(f"peak stresses: von Mises {out['peak_von_mises_Pa']:.6g} Pa, root "
                  f"{out['peak_root_stress_Pa']:.6g} Pa")
        print(f"figure: {png}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(out, f, indent=1, allow_nan=False)
            f.write("\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
