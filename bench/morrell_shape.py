#!/usr/bin/python3
"""Toe and shoulder of the charge: dem2d against Morrell's correlations.

Runs inputs/waterfall.in's drum and lifters (R = 2.5 m, 24 bars 0.1 x 0.1 m) with steel balls of
0.1 m diameter at bed fillings J = 0.2, 0.3, 0.45 (fill.0.fill_fraction = 0.84 J) and 0.6, 0.75,
0.9 of the critical speed, each for --duration seconds, and reads the toe and shoulder of the
last --window seconds from run.json's "mill" (the time-averaged shell profile,
docs/models.md "Mill analytics and regimes"). Prints a table, writes a CSV and a plot of dem2d
against Morrell.

Morrell (1996), "Power draw of wet tumbling mills and its relationship to charge dynamics", as
used in his power model (angles in radians from the horizontal on the rising side, increasing
in the mill's sense of rotation, so that the shoulder lies above that horizontal and the toe
beyond the opposite one):
    theta_T = 2.5307 (1.2796 - J) (1 - exp(-19.42 (phi_c - phi))) + pi/2
    theta_S = pi/2 - (theta_T - pi/2) ((0.3386 + 0.1041 phi) + (1.54 - 2.5673 phi) J)
phi the fraction of critical speed, phi_c the fraction at which centrifuging is complete:
phi_c = 0.35 (3.364 - J), or phi itself above that. dem2d measures from the downward vertical,
positive in the sense of rotation: the rising side's horizontal is +90 deg, so
    dem2d angle = Morrell angle (deg) + 90, taken into (-180, 180].
The CSV also holds Morrell's toe and shoulder with phi_c = 0.954 (a value sometimes used when
none is given).

    bench/morrell_shape.py [--dem2d build/src/dem2d] [--out /tmp/morrell_shape]
                           [--duration 6] [--window 3] [--jobs 2] [--reuse]
                           [--csv bench/results/morrell_shape.csv]
                           [--plot bench/results/morrell_shape.png]
"""
import argparse
import csv
import json
import math
import os
import subprocess
import sys

FILLINGS = (0.2, 0.3, 0.45)
SPEEDS = (0.6, 0.75, 0.9)
PACKING = 0.84  # docs/models.md, "Mill numbers"
BALL_RADIUS = 0.05


def morrell_rad(J, phi, phi_c=None):
    """(theta_T, theta_S) in radians, Morrell's convention."""
    if phi_c is None:
        limit = 0.35 * (3.364 - J)
        phi_c = phi if phi > limit else limit
    toe = 2.5307 * (1.2796 - J) * (1.0 - math.exp(-19.42 * (phi_c - phi))) + math.pi / 2
    shoulder = math.pi / 2 - (toe - math.pi / 2) * ((0.3386 + 0.1041 * phi) +
                                                    (1.54 - 2.5673 * phi) * J)
    return toe, shoulder


def to_dem2d(theta):
    """Morrell's angle (rad from the rising side's horizontal) in dem2d's convention (deg)."""
    a = math.degrees(theta) + 90.0
    while a > 180.0:
        a -= 360.0
    while a <= -180.0:
        a += 360.0
    return a


def morrell(J, phi, phi_c=None):
    """(toe, shoulder) in dem2d's convention, deg."""
    t, s = morrell_rad(J, phi, phi_c)
    return to_dem2d(t), to_dem2d(s)


def command(args, J, phi, folder):
    return ["nice", "-n", "10", args.dem2d, os.path.join(args.source, "inputs", "waterfall.in"),
            "--quiet", "--set", f"fill.0.fill_fraction={J * PACKING:.6g}",
            "--set", f"fill.0.radius={BALL_RADIUS}", "--set", f"drum.critical_fraction={phi}",
            "--set", f"run.duration={args.duration}",
            "--set", f"output.analysis_window={args.window}",
            "--set", f"output.snapshot_interval={args.duration}", "--output", folder]


def run_all(args, cases):
    """Runs the cases not yet done, --jobs at a time."""
    pending = [(c, f) for c, f in cases
               if not (args.reuse and os.path.exists(os.path.join(f, "run.json")))]
    running = []
    while pending or running:
        while pending and len(running) < args.jobs:
            (J, phi), folder = pending.pop(0)
            log = open(folder + ".log", "w")
            running.append((subprocess.Popen(command(args, J, phi, folder), stdout=log,
                                             stderr=subprocess.STDOUT), folder, log))
        proc, folder, log = running.pop(0)
        if proc.wait() != 0:
            sys.exit(f"dem2d failed in {folder}: see {folder}.log")
        log.close()


def measure(args):
    os.makedirs(args.out, exist_ok=True)
    cases = [((J, phi), os.path.join(args.out, f"J{J}_phi{phi}"))
             for J in FILLINGS for phi in SPEEDS]
    run_all(args, cases)
    rows = []
    for (J, phi), folder in cases:
        mill = json.load(open(os.path.join(folder, "run.json")))["mill"]
        toe, shoulder = (float("nan") if mill.get(k) is None else mill[k]
                         for k in ("toe_angle_deg", "shoulder_angle_deg"))
        m_toe, m_shoulder = morrell(J, phi)
        g_toe, g_shoulder = morrell(J, phi, 0.954)
        rows.append({"J": J, "phi": phi, "bed_filling": mill["bed_filling"],
                     "regime": mill["regime"], "toe": toe, "shoulder": shoulder,
                     "morrell_toe": m_toe, "morrell_shoulder": m_shoulder,
                     "toe_diff": toe - m_toe, "shoulder_diff": shoulder - m_shoulder,
                     "morrell_toe_phic0954": g_toe, "morrell_shoulder_phic0954": g_shoulder})
    return rows


def print_table(rows, args):
    print(f"# waterfall drum and lifters, balls of {2 * BALL_RADIUS} m; {args.duration} s runs, "
          f"window the last {args.window} s; angles from the downward vertical (deg)")
    print("| J | phi | regime | dem2d toe | Morrell toe | diff | dem2d shoulder | "
          "Morrell shoulder | diff |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for r in rows:
        print(f"| {r['J']} | {r['phi']} | {r['regime']} | {r['toe']:.1f} | {r['morrell_toe']:.1f} "
              f"| {r['toe_diff']:+.1f} | {r['shoulder']:.1f} | {r['morrell_shoulder']:.1f} | "
              f"{r['shoulder_diff']:+.1f} |")


def write_csv(rows, path):
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        for r in rows:
            w.writerow({k: (f"{v:.4f}" if isinstance(v, float) else v) for k, v in r.items()})


def plot(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.5))
    markers = {0.2: "o", 0.3: "s", 0.45: "^"}
    colors = {0.6: "tab:blue", 0.75: "tab:orange", 0.9: "tab:red"}
    for ax, key, name in [(axes[0], "toe", "toe"), (axes[1], "shoulder", "shoulder")]:
        for r in rows:
            ax.scatter(r["morrell_" + key], r[key], marker=markers[r["J"]],
                       color=colors[r["phi"]], s=50)
        values = [r[key] for r in rows] + [r["morrell_" + key] for r in rows]
        values = [v for v in values if math.isfinite(v)]
        lo, hi = min(values) - 5, max(values) + 5
        ax.plot([lo, hi], [lo, hi], "k--", lw=0.8, label="equal")
        ax.set_xlabel(f"Morrell {name} [deg]")
        ax.set_ylabel(f"dem2d {name} (window profile) [deg]")
        ax.set_title(f"{name} angle from the downward vertical")
        ax.grid(alpha=0.3)
    for J, m in markers.items():
        axes[0].scatter([], [], marker=m, color="gray", label=f"J = {J}")
    for phi, c in colors.items():
        axes[0].scatter([], [], marker="s", color=c, label=f"{phi} of critical")
    axes[0].legend(fontsize=8)
    fig.suptitle("Charge shape: dem2d (2D slice, 24 lifters, balls 0.1 m, R 2.5 m) vs Morrell")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--source", default=os.path.dirname(here))
    p.add_argument("--dem2d", default=os.path.join(os.path.dirname(here), "build/src/dem2d"))
    p.add_argument("--out", default="/tmp/morrell_shape")
    p.add_argument("--duration", type=float, default=6.0)
    p.add_argument("--window", type=float, default=3.0)
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--reuse", action="store_true", help="keep runs that have a run.json")
    p.add_argument("--csv", default=os.path.join(here, "results", "morrell_shape.csv"))
    p.add_argument("--plot", default=os.path.join(here, "results", "morrell_shape.png"))
    args = p.parse_args()
    rows = measure(args)
    print_table(rows, args)
    write_csv(rows, args.csv)
    plot(rows, args.plot)
    print(f"wrote {args.csv} and {args.plot}")


if __name__ == "__main__":
    main()
