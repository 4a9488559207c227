#!/usr/bin/python3
"""Grinding rate against drum speed: how fast the thesis's ore mill makes product.

    bench/grinding_rate.py [--dem2d build/src/dem2d] [--deck inputs/grinding.in]
                           [--fractions 0.5,0.76,0.95,1.3] [--seeds 1,2,3] [--start 3]
                           [--window 1] [--duration 4] [--variants "label=key=value,...;..."]
                           [--jobs 2] [--results bench/results] [--no-plot]

Runs the grinding deck at several fractions of the critical speed sqrt(g / R) (R the drum
radius), each with several seeds (the fill and every breakage draw change with the seed) and for
each ore variant (deck overrides; by default the Table 1 ore and two harder ones, E_min 1 J and
5 J), two runs at a time. Breakage starts at --start, once the regime has set in, and the rates
are taken over the --window seconds that follow:
  product    ore mass ground below the sieve aperture: the parents of every break whose
             fragments are below the aperture (breakages.csv); checked against the output at the
             end, where it must equal what the sieve let out (product.csv) plus the fines still
             in the mill (last snapshot) to round-off (no fine ore is filled or fed);
  rate       product per second, kg/s;
  per kWh    product per kWh of drive work over the same window, kg/kWh (the 2D scene's drive
             work: spheres in one plane, docs/output.md);
  breakages  breakage events per second;
  ground     the share of the ore (in the mill at the start plus fed) ground by the end.
Prints a table per variant (mean and min-max over the seeds), writes
results/grinding_rate.csv (one row per run) and results/grinding_rate.png (product rate and
product per kWh against the fraction of critical speed, each seed a dot, the means joined).
"""

import argparse
import csv
import math
import os
import subprocess
import sys
import tempfile
import tomllib
from concurrent.futures import ThreadPoolExecutor

G = 9.81


def deck_value(deck, table, key):
    """A number from a deck's [table] (the deck is TOML)."""
    with open(deck, "rb") as f:
        value = tomllib.load(f).get(table, {}).get(key)
    if value is None:
        raise SystemExit(f"grinding_rate: {deck} has no {table}.{key}")
    return float(value)


def read_csv(path):
    with open(path, encoding="ascii") as f:
        return list(csv.DictReader(f))


def last_snapshot(snapshots, ore_name):
    """The last snapshot's time, the ore's density and the radii of the ore in the mill."""
    import h5py
    import numpy as np

    with h5py.File(snapshots, "r") as h:
        names = [n.decode().rstrip("\0") if isinstance(n, bytes) else str(n)
                 for n in h["materials/name"][()]]
        ore = names.index(ore_name)
        density = float(h["materials/density"][()][ore])
        last = sorted(h["snapshots"].keys())[-1]
        s = h["snapshots"][last]
        radius = s["radius"][()][s["material"][()] == ore]
        return float(s.attrs["time"]), density, np.asarray(radius)


def run_one(args, variant, fraction, seed, omega, workdir):
    out = os.path.join(workdir, f"{variant[0]}_f{fraction:.3f}_s{seed}".replace(" ", "_"))
    cmd = [args.dem2d, "--quiet", "--output", out, args.deck,
           "--set", f"drum.speed={omega:.6f}", "--set", f"run.seed={seed}",
           "--set", f"run.duration={args.duration}",
           "--set", f"output.snapshot_interval={args.duration / 2}"]
    if args.start is not None:
        cmd += ["--set", f"breakage.start={args.start}"]
    for kv in variant[1]:
        cmd += ["--set", kv]
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    done = subprocess.run(cmd, env=env, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"grinding_rate: {' '.join(cmd)} exited {done.returncode}:\n{done.stderr}")
    return out


def value_at(series, t, key):
    """series' column key at the row nearest time t."""
    return float(min(series, key=lambda r: abs(float(r["time"]) - t))[key])


def measure(args, variant, fraction, seed, out, start, aperture):
    series = read_csv(os.path.join(out, "series.csv"))
    product = read_csv(os.path.join(out, "product.csv"))
    breaks = read_csv(os.path.join(out, "breakages.csv"))
    t_end, density, radius = last_snapshot(os.path.join(out, "snapshots.h5"), args.ore)
    if abs(t_end - float(series[-1]["time"])) > 1e-9:
        sys.exit(f"grinding_rate: {out}: last snapshot at {t_end} s, series at "
                 f"{series[-1]['time']} s")
    volume = 4.0 / 3.0 * math.pi
    # Product made by each break: a parent whose fragments are below the aperture.
    made = [(float(b["time"]), density * volume * float(b["radius"]) ** 3) for b in breaks
            if float(b["radius"]) / float(b["fragments"]) ** (1.0 / 3.0) < aperture]
    total = sum(m for _, m in made)
    # Bookkeeping check: what breaks made is what left plus the fines still in the mill.
    discharged = sum(float(p["mass"]) for p in product)
    fines = float(sum(density * volume * r**3 for r in radius if r < aperture))
    if abs(total - discharged - fines) > 1e-9 * max(total, 1.0):
        sys.exit(f"grinding_rate: {out}: product made {total} kg != discharged {discharged} + "
                 f"fines in the mill {fines} kg")
    window = args.window
    early = sum(m for t, m in made if t <= start + window)
    work = value_at(series, start + window, "drive_work") - value_at(series, start, "drive_work")
    ore_in = (value_at(series, start, "ore_mass") +
              float(series[-1]["fed_mass"]) - value_at(series, start, "fed_mass"))
    return {
        "variant": variant[0], "fraction": fraction, "seed": seed, "window_s": window,
        "product_window_kg": early, "rate_kg_s": early / window,
        "kg_per_kwh": early / (work / 3.6e6) if work > 0 else float("nan"),
        "mean_power_W": work / window,
        "breakages_per_s": sum(1 for b in breaks
                               if start < float(b["time"]) <= start + window) / window,
        "ground_fraction_end": total / ore_in, "discharged_kg": discharged,
        "fines_in_mill_kg": fines,
    }


KEYS = ("rate_kg_s", "kg_per_kwh", "mean_power_W", "breakages_per_s", "ground_fraction_end")


def summarize(rows, variants, fractions, critical):
    means = {}
    for label, _ in variants:
        print(f"{label}:")
        print(f"{'fraction':>9} {'rad/s':>6} {'product kg/s':>21} {'product kg/kWh':>23} "
              f"{'power kW':>9} {'breaks/s':>9} {'ground at end':>14}")
        for f in fractions:
            rs = [r for r in rows if r["variant"] == label and r["fraction"] == f]
            m = {k: sum(r[k] for r in rs) / len(rs) for k in KEYS}
            span = {k: (min(r[k] for r in rs), max(r[k] for r in rs)) for k in KEYS}
            print(f"{f:9.3f} {f * critical:6.3f} {m['rate_kg_s']:7.1f} "
                  f"({span['rate_kg_s'][0]:5.1f}-{span['rate_kg_s'][1]:5.1f}) "
                  f"{m['kg_per_kwh']:8.0f} ({span['kg_per_kwh'][0]:6.0f}-"
                  f"{span['kg_per_kwh'][1]:6.0f}) {m['mean_power_W'] / 1e3:9.1f} "
                  f"{m['breakages_per_s']:9.1f} {100 * m['ground_fraction_end']:13.1f}%")
            means[(label, f)] = m
        best = max(fractions, key=lambda f: means[(label, f)]["rate_kg_s"])
        print(f"  fastest grinding (mean product rate): {best:.3f} of critical")
    return means


def plot(rows, means, variants, fractions, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    for ax, key, label in ((axes[0], "rate_kg_s", "product rate (kg/s)"),
                           (axes[1], "kg_per_kwh", "product per drive energy (kg/kWh)")):
        for i, (name, _) in enumerate(variants):
            color = f"C{i}"
            rs = [r for r in rows if r["variant"] == name]
            ax.plot([r["fraction"] for r in rs], [r[key] for r in rs], "o", color=color,
                    alpha=0.4)
            ax.plot(fractions, [means[(name, f)][key] for f in fractions], "-s", color=color,
                    label=f"{name} (mean; dots: seeds)")
        ax.set_xlabel("drum speed / critical speed sqrt(g/R)")
        ax.set_ylabel(label)
        ax.set_ylim(bottom=0)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("inputs/grinding.in: ore ground below the sieve aperture in the first "
                 f"{rows[0]['window_s']:g} s of grinding")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    print(f"wrote {path}")


def parse_variants(text):
    """'label=key=value,key=value;label2=' -> [(label, [key=value, ...]), ...]"""
    out = []
    for item in text.split(";"):
        label, _, sets = item.partition("=")
        out.append((label.strip(), [kv for kv in sets.split(",") if kv]))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--dem2d", default="build/src/dem2d")
    ap.add_argument("--deck", default="inputs/grinding.in")
    ap.add_argument("--ore", default="ore", help="the breakable material's name")
    ap.add_argument("--fractions", default="0.5,0.76,0.95,1.3")
    ap.add_argument("--seeds", default="1,2,3")
    ap.add_argument("--duration", type=float, default=4.0)
    ap.add_argument("--start", type=float, default=3.0,
                    help="[breakage] start (s): grinding begins once the regime has set in")
    ap.add_argument("--window", type=float, default=1.0,
                    help="seconds of grinding, from [breakage] start, the rates are taken over")
    ap.add_argument("--variants", default="Table 1 ore (E_min 0.1 J)=;"
                    "harder ore (E_min 1 J)=breakage.minimum_energy=1.0;"
                    "hard ore (E_min 5 J)=breakage.minimum_energy=5.0")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--results", default="bench/results")
    ap.add_argument("--no-plot", action="store_true")
    args = ap.parse_args()

    radius = deck_value(args.deck, "drum", "radius")
    start = deck_value(args.deck, "breakage", "start") if args.start is None else args.start
    aperture = deck_value(args.deck, "sieve", "aperture")
    if start + args.window > args.duration:
        sys.exit("grinding_rate: --duration must reach [breakage] start + --window")
    critical = math.sqrt(G / radius)
    fractions = [float(f) for f in args.fractions.split(",")]
    seeds = [int(s) for s in args.seeds.split(",")]
    variants = parse_variants(args.variants)
    jobs = [(v, f, s) for v in variants for f in fractions for s in seeds]
    with tempfile.TemporaryDirectory(prefix="grinding_rate_") as work:
        with ThreadPoolExecutor(max_workers=args.jobs) as pool:
            outs = list(pool.map(
                lambda j: run_one(args, j[0], j[1], j[2], j[1] * critical, work), jobs))
        rows = [measure(args, v, f, s, out, start, aperture)
                for (v, f, s), out in zip(jobs, outs)]
    print(f"{args.deck}: {args.duration} s per run, grinding from {start} s, rates over "
          f"{args.window} s, critical speed sqrt(g/R) = {critical:.3f} rad/s, seeds {args.seeds}; "
          f"product made = discharged + fines in the mill at the end, checked for every run")
    means = summarize(rows, variants, fractions, critical)
    os.makedirs(args.results, exist_ok=True)
    csv_path = os.path.join(args.results, "grinding_rate.csv")
    with open(csv_path, "w", newline="", encoding="ascii") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    print(f"wrote {csv_path}")
    if not args.no_plot:
        plot(rows, means, variants, fractions, os.path.join(args.results, "grinding_rate.png"))


if __name__ == "__main__":
    main()
