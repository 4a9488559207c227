#!/usr/bin/env python3
"""Plot bench/many_body_error's CSV: trajectory error (short horizon, against a dt/16 reference),
energy-balance residual and the collision-energy error of the early contacts (median over
contacts matched with the reference's) against work (force evaluations per simulated second),
per scene and integrator; dt = "auto" circled.

    /usr/bin/python3 post/plot_many_body_error.py bench/results/many_body_error.csv -o out.png
"""
import argparse
import csv
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("csv")
    ap.add_argument("-o", "--output", default="many_body_error.png")
    a = ap.parse_args()
    groups = defaultdict(list)
    for r in csv.DictReader(open(a.csv)):
        groups[(r["scene"], r["integrator"])].append(r)
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.2))
    for (scene, integ), rows in sorted(groups.items()):
        rows.sort(key=lambda r: float(r["evaluations_per_s"]))
        work = [float(r["evaluations_per_s"]) for r in rows]
        style = "-o" if integ == "verlet" else "--s"
        label = f"{scene}, {integ}"
        for ax, key in zip(axes, ["trajectory_error_radii", "ledger_residual",
                                 "early_collision_median"]):
            y = [abs(float(r[key])) for r in rows]
            line, = ax.loglog(work, y, style, label=label)
            for r, w, v in zip(rows, work, y):
                if r["is_auto"] == "1":
                    ax.plot(w, v, "o", ms=13, mfc="none", color=line.get_color())
    axes[0].set_ylabel("RMS position error / mean radius")
    axes[0].set_title("short horizon after the first contact, vs dt/16")
    axes[1].set_ylabel("|energy balance residual| / drive work")
    axes[1].set_title("ledger residual over 1 s")
    axes[2].set_ylabel("median |E_peak / E_peak,ref - 1|")
    axes[2].set_title("collision energies before the horizon, 8 fills")
    for ax in axes:
        ax.set_xlabel("force evaluations per simulated second")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=8, title='circled: dt = "auto"', title_fontsize=8)
    fig.tight_layout()
    fig.savefig(a.output, dpi=120)
    print(f"wrote {a.output}")


if __name__ == "__main__":
    main()
