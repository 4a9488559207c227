#!/usr/bin/python3
"""Plot the cost per particle-step against N written by bench/throughput.

    post/plot_throughput.py [bench/results/throughput.csv] [-o bench/results/throughput.png]

Left: nanoseconds per particle-step (CPU time, and wall time dotted) of the drum runs against
the particle count N, with the target of 15 million particle-steps per second (66.7 ns) as a
horizontal line; flat means linear scaling. The waterfall deck's cost is marked too. Right: the
contacts per particle of each run (a denser contact network costs more per particle).
"""

import argparse
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    results = os.path.normpath(os.path.join(here, "..", "bench", "results"))
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("csv", nargs="?", default=os.path.join(results, "throughput.csv"))
    ap.add_argument("-o", "--output", default=os.path.join(results, "throughput.png"))
    args = ap.parse_args()
    if not os.path.exists(args.csv):
        sys.exit(f"plot_throughput: {args.csv} does not exist")
    with open(args.csv, newline="") as f:
        rows = list(csv.DictReader(f))
    drum = sorted((r for r in rows if r["section"] == "drum"), key=lambda r: int(r["n_particles"]))
    water = [r for r in rows if r["section"] == "waterfall"]
    if not drum and not water:
        sys.exit("plot_throughput: no rows")

    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(12, 5), gridspec_kw={"width_ratios": [2, 1]})
    if drum:
        n = [int(r["n_particles"]) for r in drum]
        ax.plot(n, [float(r["ns_per_particle_step_cpu"]) for r in drum], "o-", color="tab:blue",
                label="drum, dt 1e-6 s: CPU time")
        ax.plot(n, [float(r["ns_per_particle_step_wall"]) for r in drum], "o:", color="tab:blue", alpha=0.5,
                label="drum: wall time")
        for r in drum:
            ax.annotate(f"{float(r['particle_steps_per_s_cpu']) / 1e6:.1f} M/s",
                        (int(r["n_particles"]), float(r["ns_per_particle_step_cpu"])),
                        textcoords="offset points", xytext=(4, 6), fontsize=7)
        ax2.plot(n, [float(r["contacts_per_particle"]) for r in drum], "o-", color="tab:green")
    target = float(rows[0]["target_particle_steps_per_s"])
    ax.axhline(1e9 / target, color="tab:red", linestyle="--",
               label=f"target {target / 1e6:.0f} M particle-steps/s ({1e9 / target:.1f} ns)")
    for r in water:
        ax.plot([int(r["n_particles"])], [float(r["ns_per_particle_step_cpu"])], "s", color="tab:orange",
                label=f"waterfall deck ({r['n_particles']} balls, dt {float(r['dt']):g} s): "
                      f"{float(r['wall']):.1f} s wall for {float(r['steps']) * float(r['dt']):g} s")
        ax2.plot([int(r["n_particles"])], [float(r["contacts_per_particle"])], "s", color="tab:orange")
    ax.set_xscale("log")
    ax.set_ylim(bottom=0)
    ax.set_xlabel("particles N")
    ax.set_ylabel("ns per particle-step (one core)")
    ax.set_title("cost per particle-step: settled polydisperse steel (r 6-10 mm), fill 0.31,\n"
                 "hertz-mindlin + epsd; flat = linear scaling", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    ax2.set_xscale("log")
    ax2.set_ylim(bottom=0)
    ax2.set_xlabel("particles N")
    ax2.set_ylabel("contacts per particle (incl. wall)")
    ax2.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    os.makedirs(os.path.dirname(os.path.abspath(args.output)), exist_ok=True)
    fig.savefig(args.output, dpi=130)
    print(f"plot_throughput: wrote {args.output}")


if __name__ == "__main__":
    main()
