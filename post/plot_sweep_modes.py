#!/usr/bin/python3
"""Plot bench/sweep_modes's CSV: each mode's time per particle-step over the first mode's, block
by block (one box per mode and particle count; the line at 1 is the first mode).

Usage: plot_sweep_modes.py sweep_modes.csv [more.csv ...] -o sweep_modes.png
"""
import argparse
import csv
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("csv", nargs="+")
    ap.add_argument("-o", "--output", required=True)
    args = ap.parse_args()
    ratios = defaultdict(list)
    for path in args.csv:
        with open(path) as f:
            for row in csv.DictReader(f):
                key = (int(row["n_particles"]), int(row["mode"]))
                ratios[key].append(float(row["over_first_mode"]))
    keys = sorted(ratios)
    fig, ax = plt.subplots(figsize=(max(5, 1.1 * len(keys)), 4))
    ax.boxplot([ratios[k] for k in keys], whis=(0, 100))
    ax.set_xticks(range(1, len(keys) + 1))
    ax.set_xticklabels([f"N={n:g}\nmode {m}" for n, m in keys])
    ax.axhline(1.0, color="grey", lw=0.8)
    ax.set_ylabel("time per particle-step / first mode's (same round)")
    ax.set_title("steps per sweep: 1 = one at a time, K = up to K per sweep")
    fig.tight_layout()
    fig.savefig(args.output, dpi=120)


if __name__ == "__main__":
    main()
