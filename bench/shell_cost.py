#!/usr/bin/python3
"""What the finite-element shell costs a run, and how its figures move with the mesh.

    bench/shell_cost.py [--dem2d build/src/dem2d] [--duration 1.0] [--rounds 3]
                        [--sizes 0.01,0.005,0.0025] [--out bench/results]

inputs/shell.in (469 discs, 0.25 m drum, a row every millisecond) is run on one rank with its
[shell] at each element size, and without the [shell] (the same deck, the table removed),
the runs taking turns round after round so that the machine's drift falls on all alike. Per
element size: the user CPU seconds (median over the rounds, with the range), the shell's extra
cost over the run without it, per lifters.csv row; the mesh (elements, free unknowns); and the
figures lifters.csv gives over the run: the largest tip deflection and root stress (which
converge as the mesh is refined) and the largest von Mises stress (which does not: the stress is
singular at the bars' feet and under point loads), each with its change against the finest
mesh. Prints a table, writes shell_cost.csv and shell_cost.png to --out.
"""

import argparse
import csv
import json
import os
import re
import resource
import subprocess
import sys
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

SOURCE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def without_shell(deck_text):
    """The deck with its [shell] table removed (up to the next table)."""
    return re.sub(r"\n\[shell\]\n(?:[^\[\n][^\n]*\n|\n)*", "\n", deck_text)


def run(dem2d, deck, out, duration, extra=()):
    before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime
    subprocess.run([dem2d, deck, "--quiet", "--overwrite", "--output", out,
                    "--set", f"run.duration={duration}", "--set", "output.snapshot_interval=0",
                    *extra], check=True, env=dict(os.environ, OMPI_MCA_mpi_yield_when_idle="1"))
    return resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime - before


def lifter_figures(folder):
    rows = list(csv.DictReader(open(os.path.join(folder, "lifters.csv"))))
    shell = json.load(open(os.path.join(folder, "run.json")))["shell"]
    return {
        "rows": len(rows) // 8,
        "elements": shell["elements"],
        "free_dofs": shell["free_dofs"],
        "tip_max_m": max(float(r["tip_deflection_m"]) for r in rows),
        "root_max_Pa": max(float(r["root_stress_Pa"]) for r in rows),
        "von_mises_max_Pa": max(float(r["von_mises_max_Pa"]) for r in rows),
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--dem2d", default=os.path.join(SOURCE, "build/src/dem2d"))
    parser.add_argument("--duration", type=float, default=1.0)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--sizes", default="0.01,0.005,0.0025")
    parser.add_argument("--out", default=os.path.join(SOURCE, "bench/results"))
    args = parser.parse_args()
    sizes = [float(x) for x in args.sizes.split(",")]
    work = tempfile.mkdtemp(prefix="dem2d_shell_cost.")
    deck = os.path.join(SOURCE, "inputs/shell.in")
    bare = os.path.join(work, "bare.in")
    with open(bare, "w") as f:
        f.write(without_shell(open(deck).read()))
    cases = [("no shell", bare, ())] + [
        (f"{1000 * h:g} mm", deck, ("--set", f"shell.element_size={h}")) for h in sizes]
    times = {name: [] for name, _, _ in cases}
    for r in range(args.rounds):
        for name, d, extra in cases:
            t = run(args.dem2d, d, os.path.join(work, name.replace(" ", "_")), args.duration,
                    extra)
            times[name].append(t)
            print(f"round {r + 1}: {name}: {t:.2f} s", file=sys.stderr)
    base = float(np.median(times["no shell"]))
    figures = {name: lifter_figures(os.path.join(work, name.replace(" ", "_")))
               for name, _, _ in cases[1:]}
    finest = figures[cases[-1][0]]
    table = []
    for name, _, _ in cases:
        t = times[name]
        row = {"case": name, "user_s_median": float(np.median(t)), "user_s_min": min(t),
               "user_s_max": max(t), "over_no_shell": float(np.median(t)) / base}
        if name in figures:
            f = figures[name]
            row.update(f)
            row["ms_per_row"] = 1e3 * (row["user_s_median"] - base) / f["rows"]
            for key in ("tip_max_m", "root_max_Pa", "von_mises_max_Pa"):
                row[key + "_vs_finest"] = f[key] / finest[key] - 1.0
        table.append(row)
    print(f"inputs/shell.in, {args.duration:g} s, one rank, {args.rounds} rounds (user CPU s)")
    print(f"{'case':>9} {'user s':>13} {'x bare':>7} {'ms/row':>7} {'elements':>8} "
          f"{'tip max m':>10} {'vs finest':>9} {'root Pa':>9} {'vs finest':>9} "
          f"{'vMises Pa':>9} {'vs finest':>9}")
    for row in table:
        line = (f"{row['case']:>9} {row['user_s_median']:6.2f} ({row['user_s_min']:.2f}-"
                f"{row['user_s_max']:.2f}) {row['over_no_shell']:7.3f}")
        if "rows" in row:
            line += (f" {row['ms_per_row']:7.3f} {row['elements']:8d} {row['tip_max_m']:10.4g} "
                     f"{row['tip_max_m_vs_finest']:+9.2%} {row['root_max_Pa']:9.4g} "
                     f"{row['root_max_Pa_vs_finest']:+9.2%} {row['von_mises_max_Pa']:9.4g} "
                     f"{row['von_mises_max_Pa_vs_finest']:+9.2%}")
        print(line)
    os.makedirs(args.out, exist_ok=True)
    keys = sorted({k for row in table for k in row}, key=lambda k: (k != "case", k))
    with open(os.path.join(args.out, "shell_cost.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        w.writerows(table)
    shelled = [row for row in table if "rows" in row]
    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    ax[0].plot([r["elements"] for r in shelled], [r["over_no_shell"] for r in shelled], "o-")
    ax[0].axhline(1.1, color="C3", lw=0.8, ls="--", label="+10 %")
    ax[0].set_xlabel("shell elements")
    ax[0].set_ylabel("run time / run without the shell")
    ax[0].legend()
    for key, label in (("tip_max_m", "tip deflection"), ("root_max_Pa", "root stress"),
                       ("von_mises_max_Pa", "peak von Mises")):
        ax[1].plot([r["elements"] for r in shelled], [r[key + "_vs_finest"] for r in shelled],
                   "o-", label=label)
    ax[1].set_xlabel("shell elements")
    ax[1].set_ylabel("largest value / finest mesh's - 1")
    ax[1].legend()
    for a in ax:
        a.set_xscale("log")
        a.grid(alpha=0.3)
    fig.suptitle(f"The shell's cost and its figures against the mesh (inputs/shell.in, "
                 f"{args.duration:g} s)")
    fig.tight_layout()
    fig.savefig(os.path.join(args.out, "shell_cost.png"), dpi=100)
    return 0


if __name__ == "__main__":
    sys.exit(main())
