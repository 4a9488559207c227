#!/usr/bin/python3
"""Angle of repose against particle shape: a heap from a collapsing column (bench/repose.in).

    bench/repose_shapes.py [--dem2d build/src/dem2d] [--deck bench/repose.in] [--jobs 2]
                           [--nice 10] [--keep DIR] [--results bench/results] [--no-plot]
                           [--shapes disc,2:0.5,...] [--measure OUT]

Runs the deck once per shape (the fill's shape set with --set): discs, and superellipses given
as EXPONENT:ASPECT (default: ellipses of aspect 0.8 and 0.5, rounded squares n = 4 and 8,
rounded bars n = 8 of aspect 0.5). The heap's angle is read from the last snapshot: the floor
is cut into columns one mean particle size wide; a column's height is the highest point of the
particles over it (each body's top, from its outline for a superellipse); on each side of the
summit the columns between 20 % and 80 % of the heap's height are fitted by a straight line
(least squares) and the angle is its slope's arctangent; the table gives the two sides and
their mean. Writes bench/results/repose_shapes.csv (shape, exponent, aspect, particles, the
left, right and mean angles in degrees, the heap's height and the run's wall time) and
repose_shapes.png (the heaps and the angle against shape). --measure OUT only measures one
finished run (prints its angles).
"""

import argparse
import csv
import math
import os
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, os.path.join(ROOT, "post"))
import millplot  # noqa: E402

DEFAULT_SHAPES = "disc,2:0.8,2:0.5,4:1,8:1,8:0.5"


def parse_shape(text):
    if text == "disc":
        return {"label": "discs", "n": 2.0, "aspect": 1.0, "disc": True}
    n, aspect = (float(x) for x in text.split(":"))
    return {"label": f"n = {n:g}, b/a = {aspect:g}", "n": n, "aspect": aspect, "disc": False}


def tops(snap, outline_points=64):
    """(x, top) of every particle: its outline's points for a superellipse, its circle's for a
    disc, as arrays of all points (x, y)."""
    xs, ys = [], []
    shape = snap["shape"]
    pos = snap["position"]
    for k in range(len(pos)):
        if shape is not None:
            poly = millplot.superellipse_outlines(
                shape["a"][k:k + 1], shape["b"][k:k + 1], shape["n"][k:k + 1],
                shape["angle"][k:k + 1], pos[k:k + 1], outline_points)[0]
        else:
            t = np.linspace(0.0, 2.0 * math.pi, outline_points, endpoint=False)
            r = snap["radius"][k]
            poly = np.column_stack([pos[k, 0] + r * np.cos(t), pos[k, 1] + r * np.sin(t)])
        xs.append(poly[:, 0])
        ys.append(poly[:, 1])
    return np.concatenate(xs), np.concatenate(ys)


def heap_angles(snap):
    """The heap's left and right slope angles (deg) and its height (m), as the docstring says."""
    x, y = tops(snap)
    width = 2.0 * float(np.median(snap["radius"]))
    lo, hi = x.min(), x.max()
    edges = np.arange(lo, hi + width, width)
    k = np.clip(np.digitize(x, edges) - 1, 0, len(edges) - 2)
    height = np.full(len(edges) - 1, 0.0)
    np.maximum.at(height, k, y)
    centres = 0.5 * (edges[:-1] + edges[1:])
    top = int(np.argmax(height))
    h = float(height[top])
    angles = []
    for side in (slice(0, top + 1), slice(top, len(height))):
        cx, cy = centres[side], height[side]
        keep = (cy >= 0.2 * h) & (cy <= 0.8 * h)
        if keep.sum() < 3:
            angles.append(float("nan"))
            continue
        slope = np.polyfit(cx[keep], cy[keep], 1)[0]
        angles.append(math.degrees(math.atan(abs(slope))))
    return angles[0], angles[1], h


def measure(folder):
    import h5py
    with h5py.File(os.path.join(folder, "snapshots.h5"), "r") as f:
        names = millplot.list_snapshots(f)
        snap = millplot.read_snapshot(f, names[-1])
    left, right, h = heap_angles(snap)
    return {"left_deg": left, "right_deg": right, "mean_deg": float(np.nanmean([left, right])),
            "height_m": h, "particles": len(snap["radius"]), "_snap": snap}


def run_one(args, shape, folder):
    cmd = [args.dem2d, args.deck, "--quiet", "--overwrite", "--output", folder]
    if not shape["disc"]:
        cmd += ["--set", "fill.0.shape=superellipse", "--set", f"fill.0.exponent={shape['n']}",
                "--set", f"fill.0.aspect={shape['aspect']}"]
    if args.nice:
        cmd = ["nice", "-n", str(args.nice)] + cmd
    t0 = time.time()
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed ({done.returncode}): {done.stderr[-500:]}")
    out = measure(folder)
    out["wall_s"] = time.time() - t0
    return out


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--dem2d", default=os.path.join(ROOT, "build", "src", "dem2d"))
    p.add_argument("--deck", default=os.path.join(HERE, "repose.in"))
    p.add_argument("--shapes", default=DEFAULT_SHAPES)
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--nice", type=int, default=10)
    p.add_argument("--keep", help="keep the runs in this folder")
    p.add_argument("--results", default=os.path.join(HERE, "results"))
    p.add_argument("--no-plot", action="store_true")
    p.add_argument("--measure", help="only measure this finished run's heap")
    args = p.parse_args(argv)
    if args.measure:
        r = measure(args.measure)
        print(f"left {r['left_deg']:.1f} deg, right {r['right_deg']:.1f} deg, mean "
              f"{r['mean_deg']:.1f} deg, height {r['height_m']:.4f} m, {r['particles']} particles")
        return 0
    shapes = [parse_shape(s) for s in args.shapes.split(",")]
    work = args.keep or tempfile.mkdtemp(prefix="dem2d_repose.")
    os.makedirs(work, exist_ok=True)
    folders = [os.path.join(work, f"shape_{k}") for k in range(len(shapes))]
    with ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        results = list(pool.map(lambda sf: run_one(args, *sf), zip(shapes, folders)))
    os.makedirs(args.results, exist_ok=True)
    path = os.path.join(args.results, "repose_shapes.csv")
    print(f"{'shape':22s} {'left':>7s} {'right':>7s} {'mean':>7s} {'height':>8s} {'wall s':>7s}")
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["shape", "exponent", "aspect", "particles", "left_deg", "right_deg",
                    "mean_deg", "height_m", "wall_s"])
        for s, r in zip(shapes, results):
            w.writerow([s["label"], s["n"], s["aspect"], r["particles"], f"{r['left_deg']:.2f}",
                        f"{r['right_deg']:.2f}", f"{r['mean_deg']:.2f}", f"{r['height_m']:.4f}",
                        f"{r['wall_s']:.1f}"])
            print(f"{s['label']:22s} {r['left_deg']:7.1f} {r['right_deg']:7.1f} "
                  f"{r['mean_deg']:7.1f} {r['height_m']:8.4f} {r['wall_s']:7.1f}")
    print(f"wrote {path}")
    if not args.no_plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, axes = plt.subplots(len(shapes) + 1, 1, figsize=(8, 2.0 * (len(shapes) + 1)))
        for ax, s, r in zip(axes, shapes, results):
            millplot.particle_collections(ax, r["_snap"],
                                          facecolors=["tab:brown"] * len(r["_snap"]["radius"]))
            ax.set_xlim(-0.5, 0.5)
            ax.set_ylim(0.0, max(rr["height_m"] for rr in results) * 1.2)
            ax.set_aspect("equal")
            ax.set_title(f"{s['label']}: {r['mean_deg']:.1f} deg", fontsize=9)
        axes[-1].bar([s["label"] for s in shapes], [r["mean_deg"] for r in results])
        axes[-1].set_ylabel("angle of repose [deg]")
        axes[-1].tick_params(axis="x", labelsize=7)
        fig.tight_layout()
        png = os.path.join(args.results, "repose_shapes.png")
        fig.savefig(png, dpi=100)
        print(f"wrote {png}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
