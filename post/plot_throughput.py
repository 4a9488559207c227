#!/usr/bin/python3
"""Plot the cost per particle-step, memory per particle and the size-ratio sweep written by
bench/throughput.

    post/plot_throughput.py [bench/results/throughput.csv] [-o bench/results/throughput.png]
                            [--before bench/results/throughput_before.csv]

Top left: nanoseconds per particle-step (CPU time of the fastest repeat; wall time dotted) of
the drum runs against the particle count N (1e3 .. 1e5; the deposited beds, 1e4 .. 1e6, as
triangles with their cost relative to the deposited 1e4 bed and the bound of 1.3x), with the target of 15 million
particle-steps per second (66.7 ns) as a horizontal line; flat means linear scaling. The dense
sliding block and the waterfall deck are marked at their 240 balls (the block's target,
40 million particle-steps/s = 25 ns, dashed). Top right: bytes per particle against N: the
growth of resident memory, the particle store's fields and the pair lists with their
histories. Bottom left: the size-ratio sweep (same N and fill fraction; r_max / r_min = 1, 2,
5, 10): ns per particle-step and its ratio to the monodisperse cost, with the target of
1.5x. Bottom right: contacts and candidate pairs per particle of every drum run.
With --before, the runs of that CSV are drawn in grey for comparison (the same sections).
The CSV may lack the columns added later (size_ratio, rss_bytes_per_particle, ...): those panels
are then left empty.
"""

import argparse
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def num(r, key, default=float("nan")):
    v = r.get(key, "")
    try:
        return float(v)
    except (TypeError, ValueError):
        return default


def draw(axes, rows, style, label_suffix, grey=False):
    ax, axm, axr, axc = axes
    drum = sorted((r for r in rows if r["section"] == "drum"), key=lambda r: int(r["n_particles"]))
    ratio = sorted((r for r in rows if r["section"] == "ratio"), key=lambda r: num(r, "size_ratio"))
    c = (lambda col: "0.6") if grey else (lambda col: col)
    if drum:
        n = [int(r["n_particles"]) for r in drum]
        ax.plot(n, [num(r, "ns_per_particle_step_cpu") for r in drum], "o" + style, color=c("tab:blue"),
                label="drum, dt 1e-6 s: CPU time" + label_suffix)
        if not grey:
            ax.plot(n, [num(r, "ns_per_particle_step_wall") for r in drum], "o:", color="tab:blue",
                    alpha=0.4, label="drum: wall time")
            for r in drum:
                ax.annotate(f"{num(r, 'particle_steps_per_s_cpu') / 1e6:.1f} M/s",
                            (int(r["n_particles"]), num(r, "ns_per_particle_step_cpu")),
                            textcoords="offset points", xytext=(4, 6), fontsize=7)
        for key, col, name in (("rss_bytes_per_particle", "tab:purple", "resident memory growth"),
                               ("store_bytes_per_particle", "tab:green", "particle store"),
                               ("pair_bytes_per_particle", "tab:brown", "pair lists + histories")):
            y = [num(r, key) for r in drum]
            if any(v == v for v in y):
                axm.plot(n, y, "o" + style, color=c(col), label=name + label_suffix)
        axc.plot(n, [num(r, "contacts_per_particle") for r in drum], "o" + style, color=c("tab:green"),
                 label="contacts (incl. wall)" + label_suffix)
        y = [num(r, "candidates_per_particle") for r in drum]
        if any(v == v for v in y):
            axc.plot(n, y, "^" + style, color=c("tab:olive"), label="candidate pairs" + label_suffix)
    dep = sorted((r for r in rows if r["section"] == "deposited"), key=lambda r: int(r["n_particles"]))
    if dep:
        n = [int(r["n_particles"]) for r in dep]
        ax.plot(n, [num(r, "ns_per_particle_step_cpu") for r in dep], "v" + style, color=c("tab:cyan"),
                label="deposited bed, drum still: CPU time" + label_suffix)
        base = [num(r, "ns_per_particle_step_cpu") for r in dep if int(r["n_particles"]) == 10000]
        if base and not grey:
            ax.axhline(1.3 * base[0], color="tab:cyan", linestyle=":",
                       label=f"1.3 x the deposited 1e4 bed ({1.3 * base[0]:.1f} ns)")
            for r in dep:
                ax.annotate(f"{num(r, 'ns_per_particle_step_cpu') / base[0]:.2f}x",
                            (int(r["n_particles"]), num(r, "ns_per_particle_step_cpu")),
                            textcoords="offset points", xytext=(4, -12), fontsize=7, color="tab:cyan")
        axc.plot(n, [num(r, "contacts_per_particle") for r in dep], "v" + style, color=c("tab:cyan"),
                 label="contacts, deposited beds" + label_suffix)
    for r in rows:
        if r["section"] not in ("waterfall", "block"):
            continue
        col = "tab:orange" if r["section"] == "waterfall" else "tab:red"
        what = (f"waterfall deck ({r['n_particles']} balls): {num(r, 'wall'):.1f} s wall for "
                f"{num(r, 'steps') * num(r, 'dt'):g} s" if r["section"] == "waterfall" else
                f"dense sliding block ({r['n_particles']} balls, "
                f"{num(r, 'contacts_per_particle'):.2f} contacts/particle): "
                f"{num(r, 'particle_steps_per_s_cpu') / 1e6:.1f} M/s")
        ax.plot([int(r["n_particles"])], [num(r, "ns_per_particle_step_cpu")],
                "s" if r["section"] == "waterfall" else "D", color=c(col),
                label=what + label_suffix)
        axc.plot([int(r["n_particles"])], [num(r, "contacts_per_particle")],
                 "s" if r["section"] == "waterfall" else "D", color=c(col))
    if ratio:
        x = [num(r, "size_ratio") for r in ratio]
        axr.plot(x, [num(r, "ns_per_particle_step_cpu") for r in ratio], "o" + style, color=c("tab:blue"),
                 label=f"ns per particle-step (N = {ratio[0]['n_particles']})" + label_suffix)
        if not grey:
            for r in ratio:
                cost = num(r, "cost_vs_mono", 0.0)
                axr.annotate((f"{cost:.2f}x\n" if cost > 0 else "") +
                             f"{num(r, 'contacts_per_particle'):.2f} c, "
                             f"{num(r, 'candidates_per_particle'):.2f} p",
                             (num(r, "size_ratio"), num(r, "ns_per_particle_step_cpu")),
                             textcoords="offset points", xytext=(5, -18), fontsize=7)


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    results = os.path.normpath(os.path.join(here, "..", "bench", "results"))
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("csv", nargs="?", default=os.path.join(results, "throughput.csv"))
    ap.add_argument("-o", "--output", default=os.path.join(results, "throughput.png"))
    ap.add_argument("--before", default=None, help="an earlier CSV, drawn in grey")
    args = ap.parse_args()
    if not os.path.exists(args.csv):
        sys.exit(f"plot_throughput: {args.csv} does not exist")
    rows = read(args.csv)
    if not rows:
        sys.exit("plot_throughput: no rows")

    fig, grid = plt.subplots(2, 2, figsize=(13, 9))
    ax, axm, axr, axc = grid[0][0], grid[0][1], grid[1][0], grid[1][1]
    if args.before:
        draw((ax, axm, axr, axc), read(args.before), "--", " (before)", grey=True)
    draw((ax, axm, axr, axc), rows, "-", "")
    target = num(rows[0], "target_particle_steps_per_s", 15e6)
    ax.axhline(1e9 / target, color="tab:red", linestyle="--",
               label=f"target {target / 1e6:.0f} M particle-steps/s ({1e9 / target:.1f} ns)")
    if any(r["section"] == "block" for r in rows):
        ax.axhline(25.0, color="tab:red", linestyle=":", label="block target 40 M/s (25 ns)")
    ax.set_xscale("log")
    ax.set_ylim(bottom=0)
    ax.set_xlabel("particles N")
    ax.set_ylabel("ns per particle-step (one core)")
    ax.set_title("settled polydisperse steel drum (r 6-10 mm), fill 0.31, hertz-mindlin + epsd;\n"
                 "flat = linear scaling", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    axm.set_xscale("log")
    axm.set_ylim(bottom=0)
    axm.set_xlabel("particles N")
    axm.set_ylabel("bytes per particle")
    axm.set_title("memory per particle (drum runs)", fontsize=9)
    axm.grid(True, which="both", alpha=0.3)
    axm.legend(fontsize=7)
    ratio = [r for r in rows if r["section"] == "ratio"]
    mono = [r for r in ratio if num(r, "size_ratio") == 1.0]
    if mono:
        base = num(mono[0], "ns_per_particle_step_cpu")
        axr.axhline(1.5 * base, color="tab:red", linestyle="--",
                    label=f"target: 1.5 x monodisperse ({1.5 * base:.1f} ns)")
    axr.set_xscale("log")
    axr.set_xticks([1, 2, 5, 10])
    axr.set_xticklabels(["1", "2", "5", "10"])
    axr.set_ylim(bottom=0)
    axr.set_xlabel("size ratio r_max / r_min (r_max = 10 mm, log-uniform radii)")
    axr.set_ylabel("ns per particle-step")
    axr.set_title("size ratio, same N and fill fraction, dt 5e-7 s\n"
                  "(labels: cost / monodisperse; contacts and candidate pairs per particle)", fontsize=9)
    axr.grid(True, which="both", alpha=0.3)
    axr.legend(fontsize=7)
    axc.set_xscale("log")
    axc.set_ylim(bottom=0)
    axc.set_xlabel("particles N")
    axc.set_ylabel("per particle")
    axc.set_title("contacts and candidate pairs per particle (square: waterfall, diamond: block)",
                  fontsize=9)
    axc.grid(True, which="both", alpha=0.3)
    axc.legend(fontsize=7)
    fig.tight_layout()
    os.makedirs(os.path.dirname(os.path.abspath(args.output)), exist_ok=True)
    fig.savefig(args.output, dpi=110)
    print(f"plot_throughput: wrote {args.output}")


if __name__ == "__main__":
    main()
