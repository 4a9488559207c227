#!/usr/bin/python3
"""Plot the work-precision diagram written by bench/work_precision.

    post/plot_work_precision.py [--impact IMPACT.csv] [--waterfall WATERFALL.csv] [-o OUT.png]
                                [--time cpu|wall]

Three panels. The first two are log-log, time against relative error, one line per integrator
and quantity (the time is the process's CPU time by default, which on an idle machine equals the
wall time and on a shared one is the steadier measure; --time wall plots the wall time):
  left:  binary Hertz impact (bench/results/work_precision_impact.csv): restitution error at
         e = 0.73, contact-time and peak-overlap errors at e = 1 against Hertz's closed form;
         wall time per contact.
  right: waterfall scene (bench/results/work_precision_waterfall.csv): errors of the
         time-averaged drum power and kinetic energy against the reference run; wall time of
         the run. The noise floor (the reference at another seed) is drawn as vertical lines.
  third: the waterfall errors against dt, with the noise floor and twice the standard deviation
         of the difference of two runs (from the seed-spread runs), to show whether the
         discretisation error rises above the chaotic run-to-run spread.
Points whose status is not "ok" (unstable, no-separation, diverged) are left out; errors of
exactly zero cannot be drawn on a log axis and are left out too. Each point is labelled with
dt / t_c (impact) or dt in microseconds (waterfall) at the integrator's first quantity.
"""

import argparse
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

COLORS = {"verlet": "tab:blue", "iterative-1e-6": "tab:red", "iterative-1e-3": "tab:orange"}
MARKERS = ["o", "s", "^", "D"]
STYLES = ["-", "--", ":", "-."]


def read(path):
    if not path or not os.path.exists(path):
        return []
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def num(s):
    try:
        return float(s)
    except (TypeError, ValueError):
        return float("nan")


def draw(ax, rows, quantities, time_key, label_of):
    integrators = []
    for r in rows:
        if r["integrator"] not in integrators:
            integrators.append(r["integrator"])
    for ig in integrators:
        for q, (qlabel, select, err_key) in enumerate(quantities):
            pts = []
            for r in rows:
                if r["integrator"] != ig or r["status"] != "ok" or not select(r):
                    continue
                err, wall = abs(num(r[err_key])), num(r[time_key])
                if err > 0.0 and wall > 0.0:
                    pts.append((err, wall, r))
            if not pts:
                continue
            pts.sort(key=lambda p: num(p[2]["dt"]))
            ax.plot([p[0] for p in pts], [p[1] for p in pts], color=COLORS.get(ig, "k"),
                    linestyle=STYLES[q % len(STYLES)], marker=MARKERS[q % len(MARKERS)],
                    markersize=4, label=f"{ig}: {qlabel}")
            if q == 0:
                for err, wall, r in pts:
                    ax.annotate(label_of(r), (err, wall), textcoords="offset points", xytext=(3, 3),
                                fontsize=6, color=COLORS.get(ig, "k"))
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.grid(True, which="both", alpha=0.3)
    ax.axvline(0.01, color="grey", linewidth=0.8)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    here = os.path.dirname(os.path.abspath(__file__))
    results = os.path.normpath(os.path.join(here, "..", "bench", "results"))
    ap.add_argument("--impact", default=os.path.join(results, "work_precision_impact.csv"))
    ap.add_argument("--waterfall", default=os.path.join(results, "work_precision_waterfall.csv"))
    ap.add_argument("-o", "--output", default=os.path.join(results, "work_precision.png"))
    ap.add_argument("--time", choices=["cpu", "wall"], default="cpu")
    args = ap.parse_args()

    impact, waterfall = read(args.impact), read(args.waterfall)
    if not impact and not waterfall:
        sys.exit("plot_work_precision: no data (neither CSV exists)")
    fig, axes = plt.subplots(1, 3, figsize=(20, 6.5))
    tname = "CPU time" if args.time == "cpu" else "wall time"

    ax = axes[0]
    if impact:
        tc = num(impact[0]["t_c_hertz"])
        draw(ax, impact,
             [("restitution (e = 0.73)", lambda r: num(r["restitution_asked"]) != 1.0, "restitution_err"),
              ("contact time (e = 1)", lambda r: num(r["restitution_asked"]) == 1.0, "contact_time_err"),
              ("peak overlap (e = 1)", lambda r: num(r["restitution_asked"]) == 1.0, "peak_overlap_err")],
             f"{args.time}_per_contact", lambda r: f"t_c/{tc / num(r['dt']):.0f}")
        ax.set_title(f"binary Hertz impact, steel r = 0.1 m at 2 x 5 m/s (t_c = {tc * 1e6:.0f} us)\n"
                     "labels: dt as a fraction of t_c; vertical line: 1 % error", fontsize=9)
    ax.set_xlabel("relative error (mean of |error| over 8 touch phases)")
    ax.set_ylabel(f"{tname} per contact (s)")
    ax.legend(fontsize=7, loc="upper right")

    ax = axes[1]
    if waterfall:
        tests = [r for r in waterfall if r["role"] == "test"]
        draw(ax, tests,
             [("drum power", lambda r: True, "power_err"),
              ("kinetic energy", lambda r: True, "kinetic_energy_err")],
             args.time, lambda r: f"{num(r['dt']) * 1e6:g} us")
        for r in waterfall:
            if r["role"] == "noise" and r["status"] == "ok":
                ax.axvline(abs(num(r["power_err"])), color="k", linestyle="-", linewidth=0.8, alpha=0.6,
                           label="noise floor (seed 2 vs 1): power")
                ax.axvline(abs(num(r["kinetic_energy_err"])), color="k", linestyle="--", linewidth=0.8,
                           alpha=0.6, label="noise floor (seed 2 vs 1): kinetic energy")
        ref = [r for r in waterfall if r["role"] == "reference"]
        sub = ""
        if ref:
            sub = (f"reference: verlet dt = {num(ref[0]['dt']) * 1e9:.1f} ns; "
                   f"averages over [{num(ref[0]['window_start']):g}, {num(ref[0]['duration']):g}] s")
        ax.set_title("waterfall scene (240 balls, 16-gon drum, 1.8 rad/s)\n" + sub, fontsize=9)
    ax.set_xlabel("relative error of the time average (vs reference, same seed)")
    ax.set_ylabel(f"{tname} of the run (s)")
    ax.legend(fontsize=7, loc="upper right")

    ax = axes[2]
    if waterfall:
        tests = [r for r in waterfall if r["role"] == "test"]
        names = []
        for r in tests:
            if r["integrator"] not in names:
                names.append(r["integrator"])
        for ig in names:
            rows = sorted((r for r in tests if r["integrator"] == ig and r["status"] == "ok"),
                          key=lambda r: num(r["dt"]))
            dts = [num(r["dt"]) for r in rows]
            for q, (key, qlabel) in enumerate([("power_err", "drum power"),
                                               ("kinetic_energy_err", "kinetic energy")]):
                ax.plot(dts, [max(abs(num(r[key])), 1e-6) for r in rows], color=COLORS.get(ig, "k"),
                        linestyle=STYLES[q], marker=MARKERS[q], markersize=4, label=f"{ig}: {qlabel}")
        for r in waterfall:
            if r["role"] == "noise" and r["status"] == "ok":
                ax.axhline(abs(num(r["power_err"])), color="k", linestyle="-", linewidth=0.8, alpha=0.6,
                           label="noise floor: power")
                ax.axhline(abs(num(r["kinetic_energy_err"])), color="k", linestyle="--", linewidth=0.8,
                           alpha=0.6, label="noise floor: kinetic energy")
        spread = [r for r in waterfall if r["role"] == "spread" and r["status"] == "ok"]
        if len(spread) >= 2:
            for key, style, qlabel in [("power", "-", "power"), ("kinetic_energy", "--", "kinetic energy")]:
                vals = [num(r[key]) for r in spread]
                mean = sum(vals) / len(vals)
                sd = (sum((v - mean) ** 2 for v in vals) / (len(vals) - 1)) ** 0.5 / mean
                ax.axhline(2 * 2 ** 0.5 * sd, color="tab:green", linestyle=style, linewidth=0.8,
                           label=f"2 sqrt(2) sd of {len(vals)} seeds at 1e-5 s: {qlabel}")
        unstable = [num(r["dt"]) for r in tests if r["status"] != "ok"]
        for dt in sorted(set(unstable)):
            ax.axvline(dt, color="grey", linestyle=":", linewidth=0.8)
        ax.axhline(0.01, color="grey", linewidth=0.8)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.grid(True, which="both", alpha=0.3)
        ax.set_title("waterfall: |error| of the time averages against dt\n"
                     "dotted verticals: a dt that went unstable; grey line: 1 %; green: chaotic spread",
                     fontsize=9)
        ax.legend(fontsize=7, loc="upper left")
    ax.set_xlabel("dt (s)")
    ax.set_ylabel("|relative error|")

    fig.tight_layout()
    os.makedirs(os.path.dirname(os.path.abspath(args.output)), exist_ok=True)
    fig.savefig(args.output, dpi=130)
    print(f"plot_work_precision: wrote {args.output}")


if __name__ == "__main__":
    main()
