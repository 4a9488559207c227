#!/usr/bin/python3
"""Plot a dem2d series.csv: energies, drum torque and power, and the energy-balance residual.

    post/plot_series.py OUT/series.csv [-o series.png]

The energy balance (docs/output.md) is

    kinetic + rotational + potential + elastic + dissipated - drive_work = constant,

(ore scenes: - fed_energy + discharged_energy as well)

so the residual plotted in the bottom panel, that sum minus its value in the first row, should
stay near zero; its size relative to the largest energy term measures how well a run conserves
energy. The figure is written as a PNG (default: series.png beside the CSV), and a one-line
summary is printed.
"""

import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

ENERGIES = [
    ("kinetic_energy", "kinetic"),
    ("rotational_energy", "rotational"),
    ("potential_energy", "potential"),
    ("elastic_energy", "elastic"),
    ("dissipated_energy", "dissipated"),
    ("drive_work", "drive work"),
]


def read_series(path):
    """The CSV as a dict of column name -> float array (one element per row)."""
    with open(path, encoding="ascii") as f:
        header = f.readline().strip().split(",")
        rows = [line.strip().split(",") for line in f if line.strip()]
    if not header or header[0] != "time":
        raise ValueError(f"{path}: not a dem2d series.csv (first column is not 'time')")
    data = np.array(rows, dtype=float).reshape(len(rows), len(header))
    return {name: data[:, i] for i, name in enumerate(header)}


def energy_residual(s):
    """Total energy minus drive work, relative to the first row, and the energy scale."""
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


def plot(s, title, out):
    t = s["time"]
    residual, scale = energy_residual(s)
    fig, axes = plt.subplots(3, 1, figsize=(9, 10), sharex=True, constrained_layout=True)
    fig.suptitle(title)

    ax = axes[0]
    for column, label in ENERGIES:
        if column not in s:
            continue
        values = s[column]
        if column == "potential_energy" and len(values):
            values = values - values[0]
            label = "potential - initial"
        ax.plot(t, values, label=label)
    ax.set_ylabel("energy [J]")
    ax.legend(loc="best", fontsize="small")
    ax.grid(True, alpha=0.3)

    ax = axes[1]
    if "drum_power" in s:
        ax.plot(t, s["drum_power"], color="tab:red", label="drum power")
    ax.set_ylabel("drum power [W]")
    ax.grid(True, alpha=0.3)
    if "drum_torque" in s:
        twin = ax.twinx()
        twin.plot(t, s["drum_torque"], color="tab:blue", linestyle="--", alpha=0.7,
                  label="drum torque")
        twin.set_ylabel("drum torque [N m]")
        lines = ax.get_lines() + twin.get_lines()
        ax.legend(lines, [line.get_label() for line in lines], loc="best", fontsize="small")

    ax = axes[2]
    ax.plot(t, residual, color="black")
    ax.set_ylabel("energy residual [J]")
    ax.set_xlabel("time [s]")
    rel = float(np.max(np.abs(residual))) / scale if scale > 0 and len(residual) else 0.0
    ax.set_title(f"K + R + P + E + D - W - initial   (max |residual| / energy scale = {rel:.3g})",
                 fontsize="small")
    ax.grid(True, alpha=0.3)

    fig.savefig(out, dpi=120)
    plt.close(fig)
    return residual, scale


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("series", help="series.csv written by dem2d")
    parser.add_argument("-o", "--output", help="PNG to write (default: series.png beside the CSV)")
    parser.add_argument("--title", help="figure title (default: the CSV's path)")
    args = parser.parse_args(argv)
    try:
        s = read_series(args.series)
    except (OSError, ValueError) as e:
        print(f"plot_series.py: {e}", file=sys.stderr)
        return 1
    out = args.output or os.path.join(os.path.dirname(os.path.abspath(args.series)), "series.png")
    residual, scale = plot(s, args.title or args.series, out)
    n = len(s["time"])
    worst = float(np.max(np.abs(residual))) if n else 0.0
    span = f"t = {s['time'][0]:g} .. {s['time'][-1]:g} s" if n else "no rows"
    print(f"{out}: {n} rows, {span}, max |energy residual| = {worst:.6g} J"
          f" ({worst / scale if scale > 0 else 0.0:.3g} of the energy scale {scale:.6g} J)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
