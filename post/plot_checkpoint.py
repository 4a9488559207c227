#!/usr/bin/python3
"""Plot bench/checkpoint's CSV: checkpoint write and restart time, and file size, against N.

Usage: plot_checkpoint.py checkpoint.csv [more.csv ...] -o checkpoint.png [--scene lattice]

Left: time of write_checkpoint and of a restart (read_checkpoint + the resumed Simulation; cold:
the file evicted from the page cache first, warm: cached) against particle count, one colour per
rank count; the waterfall deck's write (240 balls) as stars. Right: file size and bytes per
particle. Given several CSVs (rounds of the bench; a `round` column is also understood), each
point is the median over the rows of the same scene, rank count and particle count, with a bar
from the smallest to the largest.
"""
import argparse
import csv
import statistics
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

COLOURS = {1: "tab:blue", 2: "tab:orange", 3: "tab:green", 4: "tab:red"}


def read(paths):
    rows = []
    for path in paths:
        with open(path) as f:
            rows.extend(csv.DictReader(f))
    return rows


def series(rows, scene):
    """{ranks: {particles: [rows]}} for one scene."""
    out = defaultdict(lambda: defaultdict(list))
    for r in rows:
        if r["scene"] == scene:
            out[int(r["ranks"])][int(r["particles"])].append(r)
    return dict(sorted(out.items()))


def stats(by_n, key, scale=1.0):
    """Particle counts, medians and the (below, above) bar lengths of column `key`."""
    n, med, lo, hi = [], [], [], []
    for count in sorted(by_n):
        values = [scale * float(r[key]) for r in by_n[count]]
        m = statistics.median(values)
        n.append(count)
        med.append(m)
        lo.append(m - min(values))
        hi.append(max(values) - m)
    return n, med, [lo, hi]


def plot_times(ax, rows, scene):
    styles = [("write_median_s", "o-", "write"), ("restart_cold_s", "^:", "restart (cold)"),
              ("restart_warm_s", "s--", "restart (warm)")]
    for p, by_n in series(rows, scene).items():
        for key, style, what in styles:
            n, med, bars = stats(by_n, key)
            ax.errorbar(n, med, yerr=bars, fmt=style, color=COLOURS.get(p), capsize=3,
                        label=f"{what}, {p} rank{'s' if p > 1 else ''}")
    for p, by_n in series(rows, "waterfall").items():
        n, med, bars = stats(by_n, "write_median_s")
        ax.errorbar(n, med, yerr=bars, fmt="*", ms=12, color=COLOURS.get(p), capsize=3,
                    label=f"waterfall deck: write, {p}")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("particles")
    ax.set_ylabel("wall time (s), median of the slowest rank")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)


def plot_sizes(ax, rows, scene):
    twin = ax.twinx()
    for p, by_n in series(rows, scene).items():
        c = COLOURS.get(p)
        n, med, _ = stats(by_n, "file_bytes", 1e-6)
        ax.plot(n, med, "o-", color=c, label=f"file size, {p} rank{'s' if p > 1 else ''}")
        n, med, _ = stats(by_n, "bytes_per_particle")
        twin.plot(n, med, "x--", color=c, label=f"bytes per particle, {p}")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("particles")
    ax.set_ylabel("checkpoint.h5 (MB)")
    twin.set_ylabel("bytes per particle")
    twin.set_ylim(0, 300)
    ax.grid(True, which="both", alpha=0.3)
    h1, l1 = ax.get_legend_handles_labels()
    h2, l2 = twin.get_legend_handles_labels()
    ax.legend(h1 + h2, l1 + l2, fontsize=7, loc="upper left")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("csv", nargs="+")
    ap.add_argument("-o", "--output", default="checkpoint.png")
    ap.add_argument("--scene", default="lattice", help="scene plotted against N (default lattice)")
    a = ap.parse_args()
    rows = read(a.csv)
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(12, 4.8))
    plot_times(ax1, rows, a.scene)
    plot_sizes(ax2, rows, a.scene)
    fig.suptitle(f"dem2d checkpoints ({a.scene} scene): write and restart time, file size")
    fig.tight_layout()
    fig.savefig(a.output, dpi=120)
    print(f"plot_checkpoint: wrote {a.output}")


if __name__ == "__main__":
    main()
