#!/usr/bin/python3
"""Run a dem2d deck at several fractions of the critical speed and plot power against speed.

    post/sweep.py DECK [--fractions 0.3,0.5,0.7] [--duration 4] [--jobs N] [--ranks R] [-o DIR]

For each fraction F of the classical critical speed sqrt(g/R) it runs

    dem2d DECK --set drum.critical_fraction=F --set run.duration=S --output DIR/f_F
          --overwrite --quiet [--set output.analysis_window=W] [--set KEY=VALUE ...]

(under `mpirun -np R` when --ranks > 1), up to --jobs runs at a time (default: the cores
available / R), each logging to DIR/f_F.log. From each run's series.csv it takes
  - the mean drive power over the last half of the run: the change of the drum's work over
    that span / its length;
  - its standard error by batch means: over whole drum turns when the half holds three or
    more, else over 8 equal parts (millplot.power_estimate);
  - the regime: the most frequent value of the regime column over the last half ('-' when the
    run is shorter than twice the analysis window);
and writes DIR/sweep.csv (fraction, speed_rad_s, speed_rpm, power_W, power_se_W, regime,
power_per_metre_W) and DIR/power_vs_speed.png: the power [kW] against the fraction of
critical speed, each point marked by its regime, a vertical line at 1 (critical), the speed in
rpm on the top axis and the power per metre of mill length on the right (the 2D power is that of
a slice one ball diameter thick). A table is printed. Exit status 0 when every run succeeded,
1 otherwise (the table and plot then show the runs that did).
"""

import argparse
import csv
import math
import os
import shutil
import subprocess
import sys
import time as clock

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402

sys.dont_write_bytecode = True  # no __pycache__ beside the installed scripts
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import millplot  # noqa: E402

DEFAULT_FRACTIONS = [round(0.2 + 0.1 * k, 2) for k in range(13)]  # 0.2 .. 1.4
CSV_COLUMNS = ["fraction", "speed_rad_s", "speed_rpm", "power_W", "power_se_W", "regime",
               "power_per_metre_W"]


def find_dem2d(given):
    """The dem2d binary: --dem2d, else dem2d on the PATH, else build/src/dem2d of this repo."""
    if given:
        return given
    on_path = shutil.which("dem2d")
    if on_path:
        return on_path
    repo = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    built = os.path.join(repo, "build", "src", "dem2d")
    if os.access(built, os.X_OK):
        return built
    raise FileNotFoundError("no dem2d on the PATH nor in build/src/dem2d; give --dem2d PATH")


def parse_fractions(text):
    """'0.3,0.5,0.7' -> [0.3, 0.5, 0.7] (positive, sorted, unique)."""
    values = sorted({float(x) for x in text.split(",") if x.strip()})
    if not values or values[0] <= 0.0:
        raise argparse.ArgumentTypeError("fractions must be positive numbers, e.g. 0.3,0.5,0.7")
    return values


def available_cores():
    """Cores this process may use."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:
        return os.cpu_count() or 1


def run_folder(outdir, fraction):
    """DIR/f_0.3 for fraction 0.3."""
    return os.path.join(outdir, f"f_{fraction:g}")


def command(args, dem2d, fraction):
    """The command line of one run."""
    cmd = [dem2d, args.deck, "--set", f"drum.critical_fraction={fraction:.17g}",
           "--set", f"run.duration={args.duration:.17g}", "--output",
           run_folder(args.output, fraction), "--overwrite", "--quiet"]
    window = args.window if args.window is not None else min(1.0, args.duration / 4.0)
    cmd += ["--set", f"output.analysis_window={window:.17g}"]
    for item in args.set or []:
        cmd += ["--set", item]
    if args.ranks > 1:
        cmd = [args.mpirun, "-np", str(args.ranks)] + cmd
    return cmd


def child_environment(ranks):
    """The environment of the runs: Open MPI refuses root without two variables."""
    env = dict(os.environ)
    if ranks > 1 and hasattr(os, "geteuid") and os.geteuid() == 0:
        env.setdefault("OMPI_ALLOW_RUN_AS_ROOT", "1")
        env.setdefault("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
    return env


def run_all(args, dem2d):
    """Runs every fraction, at most args.jobs at a time; returns {fraction: exit status}."""
    pending = list(args.fractions)
    running = {}
    status = {}
    env = child_environment(args.ranks)
    while pending or running:
        while pending and len(running) < args.jobs:
            fraction = pending.pop(0)
            log = open(os.path.join(args.output, f"f_{fraction:g}.log"), "w", encoding="utf-8")
            proc = subprocess.Popen(command(args, dem2d, fraction), stdout=log,
                                    stderr=subprocess.STDOUT, env=env)
            running[fraction] = (proc, log, clock.monotonic())
        for fraction, (proc, log, start) in list(running.items()):
            if proc.poll() is None:
                continue
            log.close()
            status[fraction] = proc.returncode
            del running[fraction]
            how = "done" if proc.returncode == 0 else f"FAILED (exit {proc.returncode}; see " \
                f"{os.path.join(args.output, f'f_{fraction:g}.log')})"
            print(f"  f = {fraction:<5g} {how} in {clock.monotonic() - start:.1f} s", flush=True)
        if running:
            clock.sleep(0.1)
    return status


def summarise(folder, fraction, exit_status):
    """One row of sweep.csv from a run's folder (nan power and regime 'failed' when it did not
    finish)."""
    run = millplot.read_run_json(folder)
    deck = millplot.deck_of(run)
    wc = millplot.critical_speed(deck)
    speed = millplot.drum_speed(deck)
    if speed is None and wc:
        speed = fraction * wc
    row = {"fraction": fraction, "speed_rad_s": speed if speed is not None else math.nan,
           "power_W": math.nan, "power_se_W": math.nan, "regime": "failed",
           "power_per_metre_W": math.nan, "critical": wc, "title": str(deck.get("title") or "")}
    row["speed_rpm"] = row["speed_rad_s"] * millplot.RPM_PER_RAD_S
    series_path = os.path.join(folder, "series.csv")
    if exit_status != 0 or not os.path.exists(series_path):
        return row
    series = millplot.read_series(series_path)
    if not len(series["time"]):
        return row
    row["power_W"], row["power_se_W"], _, _ = millplot.power_estimate(series, speed)
    row["regime"] = millplot.dominant_regime(series)
    thickness, _ = millplot.slice_thickness(run, os.path.join(folder, "snapshots.h5"))
    per_metre = millplot.mill_scaling(thickness, row["power_W"])
    row["power_per_metre_W"] = per_metre if per_metre is not None else math.nan
    row["thickness"] = thickness
    return row


def write_csv(path, rows):
    """sweep.csv: one row per fraction."""
    with open(path, "w", encoding="ascii", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(CSV_COLUMNS)
        for r in rows:
            writer.writerow([f"{r['fraction']:g}", f"{r['speed_rad_s']:.6g}",
                             f"{r['speed_rpm']:.6g}", f"{r['power_W']:.6g}",
                             f"{r['power_se_W']:.6g}", r["regime"],
                             f"{r['power_per_metre_W']:.6g}"])


def print_table(rows):
    """The sweep as a table on stdout."""
    print(f"{'fraction':>8} {'rad/s':>8} {'rpm':>8} {'power kW':>10} {'+/- kW':>8} "
          f"{'kW/m':>8}  regime")
    for r in rows:
        print(f"{r['fraction']:8.3g} {r['speed_rad_s']:8.4g} {r['speed_rpm']:8.4g} "
              f"{r['power_W'] / 1e3:10.4g} {r['power_se_W'] / 1e3:8.3g} "
              f"{r['power_per_metre_W'] / 1e3:8.4g}  {r['regime']}")


def plot(path, rows, title, duration):
    """power_vs_speed.png: power [kW] against fraction of critical, marked by regime."""
    ok = [r for r in rows if np.isfinite(r["power_W"])]
    fig, ax = plt.subplots(figsize=(9, 6), layout="constrained")
    if ok:
        x = np.array([r["fraction"] for r in ok])
        p = np.array([r["power_W"] for r in ok]) / 1e3
        ax.plot(x, p, color="0.6", linewidth=1.2, zorder=1)
        ax.errorbar(x, p, yerr=np.array([r["power_se_W"] for r in ok]) / 1e3, fmt="none",
                    ecolor="0.4", capsize=3, zorder=2)
    seen = []
    for r in ok:
        name = r["regime"]
        ax.scatter([r["fraction"]], [r["power_W"] / 1e3], s=70, zorder=3,
                   color=millplot.REGIME_COLORS.get(name, "black"), edgecolors="black",
                   marker=millplot.REGIME_MARKERS.get(name, "o"))
        if name not in seen:
            seen.append(name)
    ax.axvline(1.0, color="black", linestyle="--", linewidth=1.0)
    ax.text(1.0, 0.02, " critical speed", transform=ax.get_xaxis_transform(), fontsize="small")
    handles = [Line2D([], [], linestyle="none", marker=millplot.REGIME_MARKERS.get(n, "o"),
                      markersize=8, markerfacecolor=millplot.REGIME_COLORS.get(n, "black"),
                      markeredgecolor="black",
                      label="not classified" if n == millplot.UNCLASSIFIED else n) for n in seen]
    if ok:
        handles.append(Line2D([], [], color="0.4", marker="|", markersize=10, linestyle="none",
                              label="spread: std of the mean\nover 8 parts of the last half"))
    if handles:
        ax.legend(handles=handles, title="regime (last half)", loc="upper left", fontsize="small")
    critical = next((r["critical"] for r in rows if r.get("critical")), None)
    if critical:
        top = ax.secondary_xaxis("top", functions=(
            lambda f: f * critical * millplot.RPM_PER_RAD_S,
            lambda n: n / (critical * millplot.RPM_PER_RAD_S)))
        top.set_xlabel(f"drum speed [rpm] (critical: {critical * millplot.RPM_PER_RAD_S:.3g} rpm)")
    thickness = next((r["thickness"] for r in ok if r.get("thickness")), None)
    if thickness:
        right = ax.secondary_yaxis("right", functions=(lambda q: q / thickness,
                                                       lambda m: m * thickness))
        right.set_ylabel(f"per metre of mill length [kW/m] (slice {thickness * 1e3:.0f} mm)")
    ax.set_xlabel("drum speed / critical speed sqrt(g/R) [-]")
    ax.set_ylabel("mean drive power of the 2D slice [kW]")
    ax.set_ylim(bottom=min(0.0, ax.get_ylim()[0]))
    ax.set_title(f"{title}\npower against drum speed (mean over the last half of {duration:g} s)",
                 fontsize="medium")
    ax.grid(True, alpha=0.3)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter,
                                     epilog="\n".join(__doc__.split("\n")[4:]))
    parser.add_argument("deck", help="the dem2d deck (.in) to sweep")
    parser.add_argument("--fractions", type=parse_fractions, default=DEFAULT_FRACTIONS,
                        help="comma-separated fractions of the critical speed "
                        "(default 0.2,0.3,...,1.4)")
    parser.add_argument("--duration", type=float, default=4.0,
                        help="simulated time of each run [s] (default 4)")
    parser.add_argument("--jobs", type=int, help="runs at a time (default: cores / ranks)")
    parser.add_argument("--ranks", type=int, default=1, help="MPI ranks per run (default 1)")
    parser.add_argument("--window", type=float,
                        help="output.analysis_window of the runs [s] (the window of power_avg "
                        "and regime; default: a quarter of the duration, at most 1 s)")
    parser.add_argument("--set", action="append", metavar="KEY=VALUE",
                        help="more deck overrides for every run (repeatable)")
    parser.add_argument("-o", "--output", help="folder of the sweep (default: sweep_DECKNAME)")
    parser.add_argument("--dem2d", help="the dem2d binary (default: dem2d on the PATH, else "
                        "build/src/dem2d of this repository)")
    parser.add_argument("--mpirun", default="mpirun", help="mpirun for --ranks > 1")
    args = parser.parse_args(argv)
    if args.duration <= 0 or args.ranks < 1:
        parser.error("--duration must be positive and --ranks at least 1")
    args.jobs = args.jobs or max(1, available_cores() // args.ranks)
    args.output = args.output or f"sweep_{os.path.splitext(os.path.basename(args.deck))[0]}"
    try:
        dem2d = find_dem2d(args.dem2d)
    except FileNotFoundError as e:
        print(f"sweep.py: {e}", file=sys.stderr)
        return 1
    os.makedirs(args.output, exist_ok=True)
    print(f"sweep.py: {args.deck}: {len(args.fractions)} runs of {args.duration:g} s with "
          f"{dem2d}, {args.jobs} at a time, {args.ranks} rank(s) each -> {args.output}",
          flush=True)
    start = clock.monotonic()
    status = run_all(args, dem2d)
    rows = [summarise(run_folder(args.output, f), f, status[f]) for f in args.fractions]
    write_csv(os.path.join(args.output, "sweep.csv"), rows)
    title = next((r["title"] for r in rows if r["title"]), os.path.basename(args.deck))
    if args.set:  # the overrides every run shares (each run's speed is the x axis)
        title += f" [{', '.join(args.set)}]"
    plot(os.path.join(args.output, "power_vs_speed.png"), rows, title, args.duration)
    print_table(rows)
    failed = [f for f in args.fractions if status[f] != 0]
    print(f"{args.output}: sweep.csv, power_vs_speed.png ({clock.monotonic() - start:.1f} s"
          f"{'; failed: ' + ', '.join(f'{f:g}' for f in failed) if failed else ''})")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
