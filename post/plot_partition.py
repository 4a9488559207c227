#!/usr/bin/python3
"""Plot the load balance and halo size of the angular-sector partitions written by bench/partition.

    post/plot_partition.py [bench/results/partition.csv] [-o bench/results/partition.png]

Left: imbalance - 1 (max rank work / mean - 1, log scale) against the rank count for the
METIS-weighted sectors (solid: 16 sectors per rank, dotted: 64) and equal angles (dashed), for
the 30k and 300k charges (particles per sector) and the 30k charge weighted by contacts; the 5 %
target as a horizontal line. Middle: halo fraction (all ghosts / N) against the rank count, same
styles (zero, e.g. equal angles at 2 ranks with no particle near a boundary, is not drawn).
Right: imbalance of the METIS partition at 64 ranks against the sectors per rank (granularity).
"""

import argparse
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

SERIES = [("30k", "particles", "tab:blue"), ("300k", "particles", "tab:red"),
          ("30k", "contacts", "tab:green")]


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    results = os.path.normpath(os.path.join(here, "..", "bench", "results"))
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("csv", nargs="?", default=os.path.join(results, "partition.csv"))
    ap.add_argument("-o", "--output", default=os.path.join(results, "partition.png"))
    args = ap.parse_args()
    if not os.path.exists(args.csv):
        sys.exit(f"plot_partition: {args.csv} does not exist")
    with open(args.csv, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit("plot_partition: no rows")

    def select(charge, work, method, spr=None, nranks=None):
        out = [r for r in rows if r["charge"] == charge and r["work"] == work
               and r["method"] == method
               and (spr is None or int(r["sectors_per_rank"]) == spr)
               and (nranks is None or int(r["nranks"]) == nranks)]
        key = "nranks" if nranks is None else "sectors_per_rank"
        return sorted(out, key=lambda r: int(r[key]))

    fig, (ax1, ax2, ax3) = plt.subplots(1, 3, figsize=(17, 5.2))
    for charge, work, color in SERIES:
        label = f"{charge} {work}"
        for method, spr, style in (("metis", 16, "-"), ("metis", 64, ":"),
                                   ("equal-angle", 16, "--")):
            sel = select(charge, work, method, spr=spr)
            if not sel:
                continue
            x = [int(r["nranks"]) for r in sel]
            name = f"{label}, {'METIS' if method == 'metis' else 'equal angle'}"
            if method == "metis":
                name += f" {spr}/rank"
            marker, size = ("s", 3) if work == "contacts" else ("o", 5)
            ax1.plot(x, [max(float(r["imbalance"]) - 1.0, 1e-4) for r in sel], style, color=color,
                     marker=marker, ms=size, label=name)
            if work == "particles" or method == "metis":
                ax2.plot(x, [float(r["ghost_ratio"]) for r in sel], style, color=color,
                         marker=marker, ms=size, label=name)
        sel = select(charge, work, "metis", nranks=64)
        if sel:
            ax3.plot([int(r["sectors_per_rank"]) for r in sel],
                     [float(r["imbalance"]) for r in sel], "-", color=color, marker="o", ms=3,
                     label=f"{label}, METIS, 64 ranks")
    for ax in (ax1, ax2):
        ax.set_xscale("log", base=2)
        ax.set_xlabel("ranks")
        ax.grid(True, which="both", alpha=0.3)
    ax1.axhline(0.05, color="k", lw=0.8, ls="-.", label="target 5 %")
    ax1.set_yscale("log")
    ax1.set_ylabel("imbalance - 1 (max / mean rank work - 1)")
    ax1.set_title("load balance")
    ax1.legend(fontsize=6.5)
    ax2.set_yscale("log")
    ax2.set_ylabel("ghosts / particles (all ranks)")
    ax2.set_title("halo fraction (halo width 2 r_max + skin)")
    ax2.legend(fontsize=6.5)
    ax3.axhline(1.05, color="k", lw=0.8, ls="-.", label="target 1.05")
    ax3.set_xscale("log", base=2)
    ax3.set_xlabel("sectors per rank")
    ax3.set_ylabel("imbalance")
    ax3.set_title("sector granularity at 64 ranks")
    ax3.grid(True, which="both", alpha=0.3)
    ax3.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(args.output, dpi=120)
    print(f"plot_partition: wrote {args.output}")


if __name__ == "__main__":
    main()
