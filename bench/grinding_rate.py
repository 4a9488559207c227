#!/usr/bin/python3
"""Grinding at steady state against drum speed: what a grate-discharge mill costs per tonne.

    bench/grinding_rate.py [--dem2d build/src/dem2d] [--deck inputs/grinding_grate.in]
                           [--ores size-aware,thesis] [--feed-rates 20,20]
                           [--fractions 0.5,0.76,0.95,1.3] [--seeds 1] [--duration 20]
                           [--window 6] [--batches 3] [--jobs 2] [--nice 10] [--keep DIR]
                           [--results bench/results] [--no-plot]

Runs the grate-discharge mill of --deck at several fractions of the critical speed sqrt(g / R)
(`drum.critical_fraction`), one run per seed (the fill, the feed and every breakage draw change
with the seed), for two ores, two runs at a time:
  size-aware  the deck as shipped: Vogel-Peukert breakage (a size effect) with t10 progeny and
              fines;
  thesis      the same mill with the thesis's ore: breakage.model = "thesis" with Table 1's
              E_min = 0.1 J and S = 1 1/J, equal fragments with the thesis's count law (the
              fragment keys at their defaults), no fines. The deck reader refuses a key of the
              other model, so this variant is written to a temporary directory from --deck with
              the Vogel-Peukert and t10 keys taken out of [breakage].
Each ore is fed at its --feed-rates entry (kg/s). The figures are taken over the last --window
seconds of each run, by post/plot_grinding.py's window_figures (imported, not copied):
  feed, discharge   mass rates over the window (kg/s; discharge = product, fines included);
  hold-up           mean ore in the mill over the window (kg), and its change, the mean over the
                    window's second half against the first;
  D/F               discharge rate / feed rate (1 at steady state);
  D/H               discharge rate / hold-up (1/s): the grinding rate per kg of ore held, the
                    inverse of the mean residence time. At steady state the product rate equals
                    the feed rate whatever the speed, so how fast a mill grinds shows in how
                    little ore it needs to hold to keep up with the feed: D/H;
  power             mean drum drive power (W);
  kWh/t             power / discharge rate: drive energy per tonne of product over the window;
  kWh/t@F           power / feed rate: the same at steady state (discharge = feed on average),
                    without the discharge's noise (the feed rate is set; its error is the
                    power's);
  P80 window        80 % passing diameter of the product discharged in the window (product.csv's
                    particles, with the fines of the window's breaks, which are all below the
                    deck's fines_diameter, counted below it), read in log(size) between
                    consecutive particle sizes;
  P80 run, F80, RR  run.json's product P80, feed F80 and reduction ratio F80/P80 (whole run);
  kWh/t < ap.       run.json's drive work per tonne of ore ground below the aperture (whole run);
  regime            series.csv's regime over the window (the most frequent, with its share);
  steady            |hold-up change| < 5 % and 0.9 <= D/F <= 1.1, and no filling warning (a fed
                    mill whose bed filling passes 0.5 is warned in run.json; it is not steady).
Uncertainty: the window is cut into --batches batches (default 3 of 2 s); the standard error of
the discharge rate, the power and kWh/t is the standard deviation of the batch values over
sqrt(batches). The batches are shorter than a residence time (hold-up / feed, several seconds),
so they are not independent and the error is a lower bound; more seeds (--seeds 1,2,3) give the
spread between runs. Every kWh/t figure carries run.json's note on what a 2D slice's specific
energy means.

Prints a table per ore and which speed is cheapest per tonne and fastest per kg held (over all
runs and over the steady ones), writes
results/grinding_rate.csv (one row per run) and results/grinding_rate.png (product rate, kWh/t,
P80 and D/H against the fraction of critical speed, one line per ore, runs that are not steady
drawn hollow, error bars one standard error).
"""

import argparse
import collections
import csv
import math
import os
import re
import subprocess
import sys
import tempfile
import textwrap
import time
import tomllib
from concurrent.futures import ThreadPoolExecutor

import numpy as np

sys.dont_write_bytecode = True  # no __pycache__ in post/
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "post"))
import plot_grinding  # noqa: E402

HOLDUP_CHANGE_MAX = 0.05       # |hold-up change| over the window below this: steady
RATIO_RANGE = (0.9, 1.1)       # discharge / feed within this: steady

# The thesis's ore (Table 1, T34-T36): the keys it sets in [breakage], and the keys of the other
# breakage model and fragment law that the deck reader would refuse beside them.
THESIS_KEYS = {"model": '"thesis"', "minimum_energy": "0.1", "strength": "1.0",
               "fragments": '"equal"'}
OTHER_MODEL_KEYS = {"f_mat", "xw_min", "t10_a", "t10_b", "fines_diameter"}
ORES = {
    "size-aware": "size-aware ore (Vogel-Peukert, t10 progeny and fines)",
    "thesis": "thesis ore (Table 1: E_min 0.1 J, S 1 1/J, equal fragments)",
}


# --- Decks and runs ------------------------------------------------------------------------------

def thesis_deck(deck, folder):
    """The deck with the thesis's ore in [breakage], written to folder; its path."""
    out, table = [], None
    for line in open(deck, encoding="utf-8").read().splitlines(True):
        header = re.match(r"\s*\[\[?\s*([^\]]+?)\s*\]\]?", line)
        if header:
            table = header.group(1)
            out.append(line)
            if table == "breakage":
                out += [f"{k} = {v}\n" for k, v in THESIS_KEYS.items()]
            continue
        key = re.match(r"\s*([A-Za-z0-9_]+)\s*=", line)
        if table == "breakage" and key and key.group(1) in OTHER_MODEL_KEYS | set(THESIS_KEYS):
            continue
        if table is None and key and key.group(1) == "title":
            line = 'title = "Grate-discharge mill: the thesis\'s Table 1 ore, equal fragments"\n'
        out.append(line)
    path = os.path.join(folder, "thesis_" + os.path.basename(deck))
    with open(path, "w", encoding="utf-8") as f:
        f.write("".join(out))
    with open(path, "rb") as f:
        breakage = tomllib.load(f)["breakage"]
    if breakage.get("model") != "thesis" or OTHER_MODEL_KEYS & set(breakage):
        sys.exit(f"grinding_rate: could not write the thesis ore's deck from {deck}")
    return path


def run_one(args, deck, ore, feed_rate, fraction, seed, work):
    out = os.path.join(work, f"{ore}_f{fraction:.3f}_s{seed}")
    cmd = ["nice", "-n", str(args.nice), args.dem2d, "--quiet", "--overwrite", "--output", out,
           deck, "--set", f"drum.critical_fraction={fraction}", "--set", f"run.seed={seed}",
           "--set", f"run.duration={args.duration}", "--set", f"feed.mass_rate={feed_rate}",
           "--set", f"output.snapshot_interval={args.duration}"]
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    t0 = time.monotonic()
    done = subprocess.run(cmd, env=env, capture_output=True, text=True)
    wall = time.monotonic() - t0
    if done.returncode != 0:
        sys.exit(f"grinding_rate: {' '.join(cmd)} exited {done.returncode}:\n{done.stderr}")
    return out, wall, done.stderr


# --- Figures -------------------------------------------------------------------------------------

def head(series, end):
    """series' rows up to time `end` (a series that ends there)."""
    n = int(np.searchsorted(series["time"], end + 1e-9, side="right"))
    return {k: v[:n] for k, v in series.items()}


def batch_errors(series, window, batches):
    """Standard errors of the discharge rate, power and kWh/t from `batches` batch means over
    the last `window` seconds (each batch's figures by plot_grinding.window_figures)."""
    t_end = float(series["time"][-1])
    length = window / batches
    keys = ("window_discharge_rate_kg_s", "window_power_W", "window_specific_energy_kwh_per_t")
    values = {k: [] for k in keys}
    for b in range(batches):
        f = plot_grinding.window_figures(head(series, t_end - (batches - 1 - b) * length),
                                         length)
        for k in keys:
            values[k].append(f[k])
    if batches < 2:
        return {k: float("nan") for k in keys}
    return {k: float(np.std(v, ddof=1) / math.sqrt(batches)) for k, v in values.items()}


def p80(diameters, masses, fines_mass=0.0, fines_diameter=0.0):
    """80 % passing diameter of particles (and fines, all below fines_diameter), read in log(size)
    between consecutive sizes of the cumulative passing; nan with no mass."""
    order = np.argsort(diameters)
    d, m = np.asarray(diameters, float)[order], np.asarray(masses, float)[order]
    total = fines_mass + float(np.sum(m))
    if not total > 0:
        return float("nan")
    passing = (fines_mass + np.cumsum(m)) / total
    below_d, below_p = (fines_diameter, fines_mass / total) if fines_mass > 0 else (None, 0.0)
    if below_p >= 0.8:
        return float("nan")  # below fines_diameter: the fines' sizes are not kept one by one
    i = int(np.argmax(passing >= 0.8 - 1e-12))
    d0, p0 = (d[i - 1], passing[i - 1]) if i > 0 else (below_d, below_p)
    if d0 is None or d0 <= 0:
        return float(d[i])
    return float(math.exp(math.log(d0) + (0.8 - p0) / (passing[i] - p0)
                          * (math.log(d[i]) - math.log(d0))))


def window_p80(data, start, fines_diameter):
    product, breaks = data["product"], data["breakages"]
    inside = product["time"] >= start if len(product.get("time", [])) else np.zeros(0, bool)
    d = 2.0 * product["radius"][inside] if inside.size else np.zeros(0)
    m = product["mass"][inside] if inside.size else np.zeros(0)
    fines = 0.0
    if "fines_mass" in breaks and len(breaks["fines_mass"]):
        fines = float(np.sum(breaks["fines_mass"][breaks["time"] >= start]))
    return p80(d, m, fines, fines_diameter)


def window_regime(series, start):
    """The most frequent regime of series.csv's rows in the window and its share."""
    regimes = series["regime"][series["time"] >= start]
    if not len(regimes):
        return "-", float("nan")
    name, count = collections.Counter(regimes.tolist()).most_common(1)[0]
    return name, count / len(regimes)


def measure(args, ore, feed_set, fraction, seed, out, wall, stderr):
    f, data = plot_grinding.summary(out, args.window)
    for warning in plot_grinding.consistency_warnings(f, data):
        sys.exit(f"grinding_rate: {out}: {warning}")
    run, grinding = data["run"], data["grinding"]
    deck = plot_grinding.millplot.deck_of(run)
    fines_diameter = float(deck.get("breakage", {}).get("fines_diameter", 0.0))
    errors = batch_errors(data["series"], args.window, args.batches)
    warnings = [w for w in run.get("warnings", []) if "bed filling" in w]
    if not warnings and "bed filling" in stderr:
        warnings = [line for line in stderr.splitlines() if "bed filling" in line]
    feed, discharge = f["window_feed_rate_kg_s"], f["window_discharge_rate_kg_s"]
    ratio = discharge / feed if feed > 0 else float("nan")
    change = f["window_holdup_change"]
    steady = (abs(change) < HOLDUP_CHANGE_MAX and RATIO_RANGE[0] <= ratio <= RATIO_RANGE[1]
              and not warnings)
    regime, share = window_regime(data["series"], f["window_start_s"])
    mill = run.get("mill", {})
    return {
        "ore": ore, "fraction": fraction,
        "speed_rad_s": fraction * plot_grinding.number(mill.get("critical_speed_rad_s")),
        "seed": seed, "duration_s": f["run_time_s"],
        "window_start_s": f["window_start_s"], "window_end_s": f["window_end_s"],
        "feed_rate_set_kg_s": feed_set,
        "feed_rate_kg_s": feed, "discharge_rate_kg_s": discharge,
        "discharge_rate_se_kg_s": errors["window_discharge_rate_kg_s"],
        "discharge_over_feed": ratio,
        "holdup_mean_kg": f["window_holdup_mean_kg"], "holdup_change": change,
        "discharge_over_holdup_per_s": discharge / f["window_holdup_mean_kg"],
        "power_W": f["window_power_W"], "power_se_W": errors["window_power_W"],
        "kwh_per_t": f["window_specific_energy_kwh_per_t"],
        "kwh_per_t_se": errors["window_specific_energy_kwh_per_t"],
        "kwh_per_t_at_feed": f["window_power_W"] / feed / 3600.0 if feed > 0 else float("nan"),
        "kwh_per_t_at_feed_se": errors["window_power_W"] / feed / 3600.0 if feed > 0
        else float("nan"),
        "p80_window_m": window_p80(data, f["window_start_s"], fines_diameter),
        "p80_run_m": f["p80_m"], "f80_run_m": f["f80_m"],
        "reduction_ratio_run": f["reduction_ratio"],
        "kwh_per_t_below_aperture_run": plot_grinding.number(
            grinding.get("specific_energy_below_aperture_kwh_per_t")),
        "regime": regime, "regime_share": share, "regime_run_json": mill.get("regime", "-"),
        "steady": steady, "filling_warning": " | ".join(warnings),
        "wall_s": wall, "specific_energy_note": f["specific_energy_note"],
    }


# --- Report --------------------------------------------------------------------------------------

def best(rows, key, pick, steady_only=True):
    """The fraction pick()s over the (steady) runs' means by fraction (None if there is none)."""
    by = collections.defaultdict(list)
    for r in rows:
        if r["steady"] or not steady_only:
            by[r["fraction"]].append(r[key])
    if not by:
        return None
    return pick(by, key=lambda fr: sum(by[fr]) / len(by[fr]))


def summarize(rows, ores, args):
    note = rows[0]["specific_energy_note"]
    for ore in ores:
        rs = [r for r in rows if r["ore"] == ore]
        print(f"\n{ORES[ore]}, fed {rs[0]['feed_rate_set_kg_s']:g} kg/s:")
        print("\n".join(textwrap.wrap(f"kWh/t: {note}", 100, initial_indent="  ",
                                      subsequent_indent="  ")))
        print(f"{'frac':>5} {'seed':>4} {'feed':>5} {'discharge kg/s':>14} {'D/F':>5} "
              f"{'hold-up kg':>10} {'change':>7} {'D/H 1/s':>7} {'power kW':>12} "
              f"{'kWh/t':>13} {'kWh/t@F':>13} {'P80 win':>7} {'P80 run':>7} {'F80':>5} {'RR':>5} "
              f"{'kWh/t<ap':>8}  {'regime':<25} steady")
        print(f"{'':>5} {'':>4} {'kg/s':>5} {'':>14} {'':>5} {'':>10} {'':>7} {'':>7} "
              f"{'':>12} {'(slice)':>13} {'(slice)':>13} {'mm':>7} {'mm':>7} {'mm':>5} {'':>5} "
              f"{'run,slice':>8}")
        for r in rs:
            regime = f"{r['regime']} {100 * r['regime_share']:.0f}%"
            steady = "yes" if r["steady"] else ("no, filling" if r["filling_warning"] else "no")
            print(f"{r['fraction']:5.2f} {r['seed']:4d} {r['feed_rate_kg_s']:5.1f} "
                  f"{r['discharge_rate_kg_s']:6.2f} ± {r['discharge_rate_se_kg_s']:5.2f} "
                  f"{r['discharge_over_feed']:5.2f} {r['holdup_mean_kg']:10.1f} "
                  f"{100 * r['holdup_change']:+6.1f}% {r['discharge_over_holdup_per_s']:7.3f} "
                  f"{r['power_W'] / 1e3:5.1f} ± {r['power_se_W'] / 1e3:4.1f} "
                  f"{r['kwh_per_t']:5.3f} ± {r['kwh_per_t_se']:5.3f} "
                  f"{r['kwh_per_t_at_feed']:5.3f} ± {r['kwh_per_t_at_feed_se']:5.3f} "
                  f"{1e3 * r['p80_window_m']:7.1f} {1e3 * r['p80_run_m']:7.1f} "
                  f"{1e3 * r['f80_run_m']:5.0f} {r['reduction_ratio_run']:5.2f} "
                  f"{r['kwh_per_t_below_aperture_run']:8.3f}  {regime:<25} {steady}")
        for r in rs:
            if r["filling_warning"]:
                print(f"  f {r['fraction']:g} seed {r['seed']}: {r['filling_warning']}")
        for what, key, pick in (("least kWh/t", "kwh_per_t", min),
                                ("least kWh/t@F", "kwh_per_t_at_feed", min),
                                ("most product per kg held (D/H)",
                                 "discharge_over_holdup_per_s", max)):
            steady = best(rs, key, pick)
            every = best(rs, key, pick, steady_only=False)
            print(f"  {what}: at {every:g} of critical over all runs; "
                  + (f"at {steady:g} over the steady runs" if steady is not None
                     else "no run is steady"))


def plot(rows, ores, path, aperture=None):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    panels = [("discharge_rate_kg_s", "discharge_rate_se_kg_s",
               "product (discharge) rate [kg/s]", 1.0),
              ("kwh_per_t", "kwh_per_t_se", "kWh/t of product (2D slice)", 1.0),
              ("p80_window_m", None, "product P80 [mm]", 1e3),
              ("discharge_over_holdup_per_s", None, "discharge / hold-up [1/s]", 1.0)]
    fig, axes = plt.subplots(2, 2, figsize=(12, 8.6))
    for ax, (key, err, label, scale) in zip(axes.flat, panels):
        for i, ore in enumerate(ores):
            color = f"C{i}"
            rs = sorted((r for r in rows if r["ore"] == ore), key=lambda r: r["fraction"])
            fractions = sorted({r["fraction"] for r in rs})
            mean = [scale * np.mean([r[key] for r in rs if r["fraction"] == fr])
                    for fr in fractions]
            ax.plot(fractions, mean, "-", color=color, alpha=0.7,
                    label=f"{ORES[ore]}, fed {rs[0]['feed_rate_set_kg_s']:g} kg/s")
            for r in rs:
                ax.errorbar(r["fraction"], scale * r[key],
                            yerr=scale * r[err] if err else None, fmt="o", color=color,
                            markersize=7, capsize=3,
                            markerfacecolor=color if r["steady"] else "white")
        if key == "kwh_per_t":
            for i, ore in enumerate(ores):
                rs = sorted((r for r in rows if r["ore"] == ore), key=lambda r: r["fraction"])
                ax.plot([r["fraction"] for r in rs], [r["kwh_per_t_at_feed"] for r in rs], "x--",
                        color=f"C{i}", linewidth=0.9, alpha=0.8)
            ax.set_title("dots: power / discharge rate; crosses: power / feed rate", fontsize=9)
        if key == "p80_window_m" and aperture:
            line = ax.axhline(1e3 * aperture, color="k", linestyle="--", linewidth=0.9,
                              label=f"aperture {1e3 * aperture:g} mm")
            ax.set_ylim(top=1.15e3 * aperture)
            ax.legend(handles=[line], fontsize=7.5, loc="lower left")
            ax.set_title("the product discharged in the window", fontsize=9)
        if key == "discharge_rate_kg_s":
            for i, ore in enumerate(ores):
                feed = [r["feed_rate_kg_s"] for r in rows if r["ore"] == ore]
                ax.axhline(np.mean(feed), color=f"C{i}", linestyle=":", linewidth=0.9)
        ax.set_xlabel("drum speed / critical speed sqrt(g/R)")
        ax.set_ylabel(label)
        ax.set_ylim(bottom=0)
        ax.grid(alpha=0.3)
    axes[0, 0].legend(fontsize=7.5, loc="lower left")
    axes[0, 0].set_title("dotted: feed rate", fontsize=9)
    axes[1, 1].set_title("grinding rate per kg of ore held (1 / residence time)", fontsize=9)
    r0 = rows[0]
    fig.suptitle("\n".join(textwrap.wrap(
        f"Grate-discharge mill at steady state: window t = {r0['window_start_s']:.3g} .. "
        f"{r0['window_end_s']:.3g} s of {r0['duration_s']:.3g} s; filled markers steady "
        f"(|hold-up change| < {100 * HOLDUP_CHANGE_MAX:g} %, discharge/feed "
        f"{RATIO_RANGE[0]:g}-{RATIO_RANGE[1]:g}), hollow not; bars: one standard error from batch means", 130)),
        fontsize=10)
    fig.text(0.5, 0.01, "\n".join(textwrap.wrap("kWh/t: " + r0["specific_energy_note"], 150)),
             ha="center", va="bottom", fontsize=8)
    fig.tight_layout(rect=(0, 0.05, 1, 0.96))
    fig.savefig(path, dpi=110)
    print(f"wrote {path}")


def floats(text, kind=float):
    return [kind(x) for x in text.split(",") if x.strip()]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                 epilog="The figures' definitions are in the script's docstring.")
    ap.add_argument("--dem2d", default="build/src/dem2d")
    ap.add_argument("--deck", default="inputs/grinding_grate.in",
                    help="a fed grate-discharge ore deck (its ore is the size-aware ore)")
    ap.add_argument("--ores", default="size-aware,thesis", help="of: " + ", ".join(ORES))
    ap.add_argument("--feed-rates", default="20,20",
                    help="feed mass rate (kg/s) of each ore of --ores, in order")
    ap.add_argument("--fractions", default="0.5,0.76,0.95,1.3",
                    help="drum speeds as fractions of the critical speed sqrt(g/R)")
    ap.add_argument("--seeds", default="1")
    ap.add_argument("--duration", type=float, default=20.0, help="simulated seconds per run")
    ap.add_argument("--window", type=float, default=6.0,
                    help="steady-state window: the last this many seconds")
    ap.add_argument("--batches", type=int, default=3,
                    help="batches of the window for the standard errors")
    ap.add_argument("--jobs", type=int, default=2, help="runs at a time (one rank each)")
    ap.add_argument("--nice", type=int, default=10)
    ap.add_argument("--keep", metavar="DIR", help="keep the runs' output folders in DIR")
    ap.add_argument("--results", default="bench/results")
    ap.add_argument("--no-plot", action="store_true")
    args = ap.parse_args()

    ores = [o.strip() for o in args.ores.split(",") if o.strip()]
    feeds = floats(args.feed_rates)
    if any(o not in ORES for o in ores) or len(feeds) != len(ores):
        ap.error(f"--ores takes names of {', '.join(ORES)}, --feed-rates one rate per ore")
    if not 0 < args.window < args.duration or args.batches < 1:
        ap.error("need 0 < --window < --duration and --batches >= 1")
    fractions, seeds = floats(args.fractions), floats(args.seeds, int)
    t0 = time.monotonic()
    with tempfile.TemporaryDirectory(prefix="grinding_rate_") as tmp:
        work = args.keep or tmp
        os.makedirs(work, exist_ok=True)
        decks = {"size-aware": args.deck, "thesis": thesis_deck(args.deck, work)}
        jobs = [(o, feed, fr, s) for o, feed in zip(ores, feeds) for fr in fractions
                for s in seeds]
        with ThreadPoolExecutor(max_workers=args.jobs) as pool:
            outs = list(pool.map(lambda j: run_one(args, decks[j[0]], j[0], j[1], j[2], j[3],
                                                   work), jobs))
        rows = [measure(args, o, feed, fr, s, *out) for (o, feed, fr, s), out in zip(jobs, outs)]
    wall = time.monotonic() - t0
    print(f"{args.deck}: {len(rows)} runs of {args.duration:g} s at {args.jobs} at a time, "
          f"steady-state window the last {args.window:g} s ({args.batches} batches for the "
          f"standard errors, ± one standard error), seeds {args.seeds}; wall {wall:.0f} s "
          f"(a run {min(r['wall_s'] for r in rows):.0f}-{max(r['wall_s'] for r in rows):.0f} s)")
    print("P80 win: the product discharged in the window; P80 run, F80, RR (F80/P80) and "
          "kWh/t<ap (per tonne ground below the aperture): run.json, the whole run")
    summarize(rows, ores, args)
    os.makedirs(args.results, exist_ok=True)
    csv_path = os.path.join(args.results, "grinding_rate.csv")
    with open(csv_path, "w", newline="", encoding="utf-8") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    print(f"wrote {csv_path}")
    if not args.no_plot:
        with open(args.deck, "rb") as f:
            aperture = tomllib.load(f).get("sieve", {}).get("aperture")
        plot(rows, ores, os.path.join(args.results, "grinding_rate.png"), aperture)


if __name__ == "__main__":
    main()
