#!/usr/bin/python3
"""Plot bench/strong_scaling's CSV: speedup and communication share against rank count.

Usage: plot_strong_scaling.py strong_scaling.csv -o strong_scaling.png
"""
import argparse
import csv
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("csv")
    ap.add_argument("-o", "--output", default="strong_scaling.png")
    a = ap.parse_args()
    rows = defaultdict(list)
    with open(a.csv) as f:
        for r in csv.DictReader(f):
            rows[r["scene"]].append(r)
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
    top = 2
    for scene, rs in rows.items():
        rs.sort(key=lambda r: int(r["ranks"]))
        p = [int(r["ranks"]) for r in rs]
        top = max(top, max(p))
        line, = ax1.plot(p, [float(r["speedup"]) for r in rs], "o-", label=scene)
        if "ceiling" in rs[0]:
            ax1.plot(p, [float(r["ceiling"]) for r in rs], "s--", color=line.get_color(), alpha=0.6,
                     label=f"{scene}: ceiling (free communication)")
        ax2.plot(p, [100 * float(r["comm_share"]) for r in rs], "o-", label=scene)
    ax1.plot([1, top], [1, top], "k:", label="ideal")
    ax1.axhline(1.9, color="grey", lw=0.8, ls="--", label="target 1.9 (drum30k, 2 ranks)")
    ax1.set_xlabel("ranks")
    ax1.set_ylabel("speedup over 1 rank")
    ax1.legend()
    ax2.set_xlabel("ranks")
    ax2.set_ylabel("time in communication (% of wall)")
    ax2.legend()
    fig.suptitle("dem2d strong scaling (angular sectors, METIS)")
    fig.tight_layout()
    fig.savefig(a.output, dpi=120)
    print(f"plot_strong_scaling: wrote {a.output}")


if __name__ == "__main__":
    main()
