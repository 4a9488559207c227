#!/usr/bin/python3
"""Plot bench/size_blocks's CSV: each size's time per particle-step over the first size's, block
by block in the same round (one box per size, whiskers at the extremes; the dashed line is the
bound, the grey line 1).

Usage: plot_size_blocks.py size_blocks.csv [more.csv ...] [--bound 1.3] -o size_blocks.png
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
    ap.add_argument("--bound", type=float, default=1.3)
    ap.add_argument("-o", "--output", required=True)
    args = ap.parse_args()
    ratios = defaultdict(list)
    for path in args.csv:
        with open(path) as f:
            for row in csv.DictReader(f):
                ratios[int(row["n_particles"])].append(float(row["over_first_size"]))
    sizes = sorted(ratios)
    fig, ax = plt.subplots(figsize=(max(5, 1.1 * len(sizes)), 4))
    ax.boxplot([ratios[n] for n in sizes], whis=(0, 100))
    ax.set_xticks(range(1, len(sizes) + 1))
    ax.set_xticklabels([f"{n:g}" for n in sizes])
    ax.axhline(1.0, color="grey", lw=0.8)
    ax.axhline(args.bound, color="red", lw=0.8, ls="--", label=f"bound {args.bound:g}x")
    ax.set_xlabel("particles (deposited bed, one core)")
    ax.set_ylabel(f"time / N={sizes[0]:g} time, same round")
    ax.set_title("cost against size (interleaved blocks, one process)", fontsize=10)
    ax.legend(loc="upper left")
    fig.tight_layout()
    fig.savefig(args.output, dpi=120)


if __name__ == "__main__":
    main()
