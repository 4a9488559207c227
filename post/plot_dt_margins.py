#!/usr/bin/env python3
"""Plot bench/dt_margins' CSV: for each hard case and integrator, the largest factor of the auto
dt that keeps the case's physics (bar) and the first factor that fails (marker).

    /usr/bin/python3 post/plot_dt_margins.py bench/results/dt_margins.csv -o dt_margins.png
"""
import argparse
import csv

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("csv")
    ap.add_argument("-o", "--output", default="dt_margins.png")
    a = ap.parse_args()
    rows = list(csv.DictReader(open(a.csv)))
    labels = [f"{r['case']}\n{r['integrator']}" for r in rows]
    passing = [float(r["largest_passing_factor"]) for r in rows]
    failing = [float(r["first_failing_factor"]) for r in rows]
    fig, ax = plt.subplots(figsize=(max(6, 0.9 * len(rows)), 4))
    x = range(len(rows))
    ax.bar(x, passing, color=["tab:blue" if r["integrator"] == "verlet" else "tab:orange"
                              for r in rows], label="largest factor that passes")
    ax.scatter([i for i, f in zip(x, failing) if f > 0], [f for f in failing if f > 0],
               marker="x", color="k", zorder=3, label="first factor that fails")
    ax.axhline(1.0, color="grey", lw=0.8, ls="--")
    ax.set_yscale("log", base=2)
    ax.set_xticks(list(x))
    ax.set_xticklabels(labels, fontsize=8)
    ax.set_ylabel('dt / dt "auto"')
    ax.set_title('How far above dt = "auto" each hard case keeps its physics')
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(a.output, dpi=120)
    print(f"wrote {a.output}")


if __name__ == "__main__":
    main()
