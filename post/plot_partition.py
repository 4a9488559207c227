#!/usr/bin/python3
"""Plot the load balance and halo size of the angular-sector partitions written by bench/partition.

    post/plot_partition.py [bench/results/partition.csv] [-o bench/results/partition.png]

Four panels against the rank count (2 ... 256), for the 30k, 300k and 1M charges (particles per
sector) and the 30k charge weighted by contacts:
 - top left: imbalance - 1 (max rank work / mean - 1, log scale) for the METIS-weighted sectors
   at 32 sectors per rank (the default; solid) and 16 (dotted), and equal angles at 32 (dashed);
   the 5 % target as a horizontal line;
 - top right: ghosts per rank, mean (solid) and the largest rank's (dotted), METIS at 32
   sectors per rank;
 - bottom left: halo against owned particles, METIS at 32 sectors per rank: all ghosts / N
   (solid) and the largest ghosts / owned of one rank (dotted), equal angles' all ghosts / N
   (dashed); 50 % as a horizontal line (zero, e.g. equal angles at 2 ranks with no particle
   near a boundary, is not drawn);
 - bottom right: imbalance of the METIS partition against the sectors per rank at 64 (dotted)
   and 256 ranks (solid) (granularity).
"""

import argparse
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

SERIES = [("30k", "particles", "tab:blue"), ("30k", "contacts", "tab:green"),
          ("300k", "particles", "tab:red"), ("1M", "particles", "tab:purple")]
DEFAULT_SPR = 32


def positive(values):
    """None for values <= 0, so that a log axis leaves a gap instead of failing."""
    return [v if v > 0.0 else None for v in values]


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

    def col(sel, name):
        return [float(r[name]) for r in sel]

    fig, ((ax1, ax2), (ax3, ax4)) = plt.subplots(2, 2, figsize=(15, 10))
    for charge, work, color in SERIES:
        label = f"{charge} {work}"
        marker, size = ("s", 3) if work == "contacts" else ("o", 4)
        style = dict(color=color, marker=marker, ms=size)
        for method, spr, ls in (("metis", DEFAULT_SPR, "-"), ("metis", 16, ":"),
                                ("equal-angle", DEFAULT_SPR, "--")):
            sel = select(charge, work, method, spr=spr)
            if not sel:
                continue
            name = f"{label}, {'METIS' if method == 'metis' else 'equal angle'} {spr}/rank"
            ax1.plot([int(r["nranks"]) for r in sel],
                     [max(v - 1.0, 1e-4) for v in col(sel, "imbalance")], ls, label=name, **style)
        sel = select(charge, work, "metis", spr=DEFAULT_SPR)
        x = [int(r["nranks"]) for r in sel]
        if work == "particles":
            ax2.plot(x, col(sel, "ghosts_mean"), "-", label=f"{charge}: mean", **style)
            ax2.plot(x, col(sel, "ghosts_max"), ":", label=f"{charge}: largest rank", **style)
        ax3.plot(x, positive(col(sel, "ghost_ratio")), "-", label=f"{label}: all ghosts / N",
                 **style)
        ax3.plot(x, positive(col(sel, "rank_ghost_ratio_max")), ":",
                 label=f"{label}: worst rank's ghosts / owned", **style)
        if work == "particles":
            eq = select(charge, work, "equal-angle", spr=DEFAULT_SPR)
            ax3.plot([int(r["nranks"]) for r in eq], positive(col(eq, "ghost_ratio")), "--",
                     label=f"{label}: equal angle, all ghosts / N", **style)
        for nranks, ls in ((64, ":"), (256, "-")):
            sel = select(charge, work, "metis", nranks=nranks)
            if sel:
                ax4.plot([int(r["sectors_per_rank"]) for r in sel], col(sel, "imbalance"), ls,
                         label=f"{label}, {nranks} ranks", **style)
    ranks = sorted({int(r["nranks"]) for r in rows})
    for ax in (ax1, ax2, ax3):
        ax.set_xscale("log", base=2)
        ax.set_xticks(ranks, [str(n) for n in ranks])
        ax.set_xlabel("ranks")
        ax.grid(True, which="both", alpha=0.3)
    ax1.axhline(0.05, color="k", lw=0.8, ls="-.", label="target 5 %")
    ax1.set_yscale("log")
    ax1.set_ylabel("imbalance - 1 (max / mean rank work - 1)")
    ax1.set_title("load balance")
    ax1.legend(fontsize=6, ncol=2)
    ax2.set_yscale("log")
    ax2.set_ylabel("ghosts per rank")
    ax2.set_title(f"halo volume per rank (METIS, {DEFAULT_SPR} sectors per rank)")
    ax2.legend(fontsize=7)
    ax3.axhline(0.5, color="k", lw=0.8, ls="-.", label="50 %")
    ax3.set_yscale("log")
    ax3.set_ylabel("ghosts / owned particles")
    ax3.set_title(f"halo against owned (METIS {DEFAULT_SPR}/rank; halo width 2 r_max + skin)")
    ax3.legend(fontsize=6, ncol=2)
    ax4.axhline(1.05, color="k", lw=0.8, ls="-.", label="target 1.05")
    ax4.set_xscale("log", base=2)
    sprs = sorted({int(r["sectors_per_rank"]) for r in rows})
    ax4.set_xticks(sprs, [str(n) for n in sprs])
    ax4.set_xlabel("sectors per rank")
    ax4.set_ylabel("imbalance")
    ax4.set_title("sector granularity (METIS) at 64 and 256 ranks")
    ax4.grid(True, which="both", alpha=0.3)
    ax4.legend(fontsize=6.5, ncol=2)
    fig.tight_layout()
    fig.savefig(args.output, dpi=110)
    print(f"plot_partition: wrote {args.output}")


if __name__ == "__main__":
    main()
