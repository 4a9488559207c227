#!/usr/bin/python3
"""The cost per particle-step from 1e4 to 1e6 particles, in rounds: the size bound (within
1.3x of the 1e4 cost) measured so that the machine's speed phases cancel.

    bench/size_rounds.py [--throughput build/bench/throughput] [--sizes 10000,30000,100000,1000000]
                         [--rounds 5] [--cpu 0] [--against OTHER_THROUGHPUT]
                         [--label NAME] [--against-label NAME] [--results bench/results]
                         [--csv size_rounds.csv]

This machine's speed moves by up to 1.4x over minutes, so one long `throughput` run that walks
the sizes in turn can put 1e4 in a fast phase and 1e6 in a slow one. Here each size runs as its
own short process (`throughput --sections deposited --deposited N`, the deposited and loaded
beds of bench/settled_drum.hpp, pinned to one core with taskset), the sizes back to back in a
round, and each size's cost is divided by the first size's cost in the same round. The table
gives the median and range of that ratio over the rounds.

With --against, every run is paired with the same run of a second `throughput` binary, the
order alternating from round to round, and the table adds the ratio of the two at each size
(this binary over the other): a before/after measurement of a change at every size.

The beds come from RESULTS/cache (made on first use: the 1e6 bed deposits in seconds but loads
for 80 000 steps, an hour or more of one core). Writes RESULTS/CSV (one row per run: label,
round, N, ns per particle-step by CPU time, the ratio to the first size in the round, memory
per particle) and a plot beside it (the ratio per round against N, with the 1.3x bound).
"""

import argparse
import csv
import os
import shutil
import statistics
import subprocess
import sys
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
BOUND = 1.3


def run_once(binary, n, cpu, results):
    """One throughput run of the deposited bed of n particles: its CSV row as a dict."""
    with tempfile.TemporaryDirectory(prefix="size_rounds_") as tmp:
        os.symlink(os.path.join(results, "cache"), os.path.join(tmp, "cache"))
        cmd = [binary, "--sections", "deposited", "--deposited", str(n), "--results", tmp,
               "--no-plot"]
        if cpu is not None and shutil.which("taskset"):
            cmd = ["taskset", "-c", str(cpu)] + cmd
        done = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        path = os.path.join(tmp, "throughput.csv")
        if done.returncode != 0 or not os.path.exists(path):
            sys.exit(f"size_rounds: {' '.join(cmd)} failed (exit {done.returncode}):\n"
                     + done.stdout[-2000:])
        with open(path, newline="") as f:
            rows = [r for r in csv.DictReader(f) if r["section"] == "deposited"]
        if not rows:
            sys.exit(f"size_rounds: {' '.join(cmd)} wrote no deposited row")
        return rows[-1]


def spread(values):
    return f"{statistics.median(values):.3f} ({min(values):.3f}-{max(values):.3f})"


def parse_args():
    a = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    a.add_argument("--throughput", default=os.path.join(ROOT, "build", "bench", "throughput"))
    a.add_argument("--sizes", default="10000,30000,100000,1000000")
    a.add_argument("--rounds", type=int, default=5)
    a.add_argument("--cpu", type=int, default=0, help="core to pin to (-1: none)")
    a.add_argument("--against", help="a second throughput binary, run in pairs with the first")
    a.add_argument("--label", default="this", help="this binary's name in the CSV")
    a.add_argument("--against-label", default="against", help="the other binary's name")
    a.add_argument("--results", default=os.path.join(HERE, "results"))
    a.add_argument("--csv", default="size_rounds.csv")
    args = a.parse_args()
    try:
        args.sizes = [int(s) for s in args.sizes.split(",")]
    except ValueError:
        a.error(f"--sizes {args.sizes!r}: a comma-separated list of particle counts, e.g. "
                "10000,100000")
    if not args.sizes or min(args.sizes) < 1000 or args.rounds < 1:
        a.error("--sizes: counts of at least 1000; --rounds: at least 1")
    if args.against and args.against_label == args.label:
        a.error("--label and --against-label must differ")
    for b in [args.throughput] + ([args.against] if args.against else []):
        if not os.access(b, os.X_OK):
            a.error(f"{b}: not an executable throughput binary (build it: scripts/build)")
    return args


def measure(args):
    """Rounds of every size; with --against, each run paired with the other binary's."""
    cpu = None if args.cpu < 0 else args.cpu
    binaries = [(args.label, args.throughput)]
    if args.against:
        binaries.append((args.against_label, args.against))
    rows = []
    for rnd in range(1, args.rounds + 1):
        first = {}
        for n in args.sizes:
            order = binaries if rnd % 2 or len(binaries) == 1 else binaries[::-1]
            for label, binary in order:
                r = run_once(binary, n, cpu, args.results)
                ns = float(r["ns_per_particle_step_cpu"])
                first.setdefault(label, ns)
                rows.append({"label": label, "round": rnd, "n_particles": n,
                             "ns_per_particle_step_cpu": f"{ns:.3f}",
                             "over_first_in_round": f"{ns / first[label]:.3f}",
                             "rss_bytes_per_particle": r.get("rss_bytes_per_particle", "")})
                print(f"round {rnd} {label:>8} N = {n:>8}: {ns:7.2f} ns per particle-step, "
                      f"{ns / first[label]:.3f} of N = {args.sizes[0]}", flush=True)
    return rows


def report(args, rows):
    print(f"\nN            ns per particle-step    over N = {args.sizes[0]} in its round"
          + ("    this / against (pairs)" if args.against else ""))
    for n in args.sizes:
        mine = [r for r in rows if r["label"] == args.label and r["n_particles"] == n]
        ns = [float(r["ns_per_particle_step_cpu"]) for r in mine]
        over = [float(r["over_first_in_round"]) for r in mine]
        line = f"{n:<12} {min(ns):7.2f}-{max(ns):<7.2f}         {spread(over)}"
        if args.against:
            other = {r["round"]: float(r["ns_per_particle_step_cpu"]) for r in rows
                     if r["label"] == args.against_label and r["n_particles"] == n}
            line += "    " + spread([float(r["ns_per_particle_step_cpu"]) / other[r["round"]]
                                     for r in mine])
        if n != args.sizes[0] and statistics.median(over) > BOUND:
            line += f"    above the {BOUND}x bound"
        print(line)


def plot(args, rows, path):
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    for label, marker in ((args.label, "o"), (args.against_label, "s")):
        mine = [r for r in rows if r["label"] == label]
        if not mine:
            continue
        for rnd in sorted({r["round"] for r in mine}):
            pts = [(r["n_particles"], float(r["over_first_in_round"])) for r in mine
                   if r["round"] == rnd]
            ax.plot(*zip(*pts), marker=marker, alpha=0.5,
                    color="C0" if label == args.label else "grey",
                    label=label if rnd == 1 else None)
    ax.axhline(BOUND, ls="--", color="C3", label=f"{BOUND}x bound")
    ax.set_xscale("log")
    ax.set_xlabel("particles (deposited bed, one core)")
    ax.set_ylabel(f"cost per particle-step / cost at N = {args.sizes[0]}")
    ax.set_title("Cost against size, one line per round")
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def main():
    args = parse_args()
    os.makedirs(os.path.join(args.results, "cache"), exist_ok=True)
    rows = measure(args)
    report(args, rows)
    out = os.path.join(args.results, args.csv)
    with open(out, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    png = os.path.splitext(out)[0] + ".png"
    plot(args, rows, png)
    print(f"wrote {out} and {png}")


if __name__ == "__main__":
    main()
