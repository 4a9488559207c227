#!/usr/bin/python3
"""What a snapshot costs against its size, and the memory of a run that writes many.

    bench/snapshot_cost.py [--dem2d build/src/dem2d] [--label NAME] [--repeats 3]
                           [--memory-snapshots 10000] [--quick] [--memory-only]
                           [--results bench/results] [--no-plot]
    bench/snapshot_cost.py --plot-only [--results bench/results]

Cost. Runs two scenes with no snapshots and at several snapshot intervals, each run --repeats
times (the median wall time is kept):
  waterfall  inputs/waterfall.in (240 balls), 1 s simulated, intervals 0.01, 0.002, 0.0005 s;
  large      the same drum with 3 000 balls of radius 0.03 m (dt = auto), 0.1 s simulated,
             intervals 0.01, 0.002 s.
A snapshot's cost is (wall time - wall time without snapshots) / snapshots written, and the
same with the CPU time (user + system) of the run, which a loaded machine disturbs less (a
sync to disk waits without CPU); its size is snapshots.h5's size / snapshots written.
Memory. One waterfall run writing --memory-snapshots snapshots (every 10 steps), its resident
set (VmRSS) sampled every 0.1 s against the snapshots written so far (counted from the growth
of snapshots.xmf, whose grids are all the same length); the peak is VmHWM.

Prints a table per part, appends to results/snapshot_cost.csv and results/snapshot_memory.csv
(one row per scene and interval, and per sample, tagged with --label: run it once per binary to
compare them), and plots results/snapshot_cost.png (cost per snapshot against its size; RSS
against snapshots written), one colour per label.
"""

import argparse
import csv
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time

SRC = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DECK = os.path.join(SRC, "inputs", "waterfall.in")
LARGE = ["fill.0.count=3000", "fill.0.radius=0.03", "run.dt=auto"]
COST_FIELDS = ["label", "scene", "particles", "interval_s", "snapshots", "wall_s",
               "cost_ms", "cpu_ms", "bytes_per_snapshot"]
MEMORY_FIELDS = ["label", "elapsed_s", "snapshots", "rss_mb", "peak_mb"]


def child_cpu():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def run_dem2d(dem2d, out, duration, interval, sets, sample=None):
    """One run; returns (wall s, CPU s, samples), the samples from `sample(pid, elapsed)`."""
    cmd = [dem2d, "--quiet", "--overwrite", "--output", out, DECK,
           "--set", f"run.duration={duration}", "--set", f"output.snapshot_interval={interval}",
           "--set", "output.checkpoint_interval=0", "--set", "output.checkpoint_minutes=0"]
    for s in sets:
        cmd += ["--set", s]
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    cpu = child_cpu()
    start = time.perf_counter()
    proc = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    samples = []
    while sample is not None and proc.poll() is None:
        samples.append(sample(proc.pid, time.perf_counter() - start))
        time.sleep(0.1)
    _, err = proc.communicate()
    wall = time.perf_counter() - start
    if proc.returncode != 0:
        raise SystemExit(f"snapshot_cost: {' '.join(cmd)} failed:\n{err.decode()}")
    return wall, child_cpu() - cpu, [s for s in samples if s is not None]


def snapshot_count(out):
    import h5py

    with h5py.File(os.path.join(out, "snapshots.h5"), "r") as f:
        return len(f["snapshots"])


def cost_rows(args, tmp):
    scenes = [("waterfall", [], 240, 1.0, [0.01, 0.002, 0.0005]),
              ("large", LARGE, 3000, 0.1, [0.01, 0.002])]
    if args.quick:
        scenes = [("waterfall", [], 240, 0.2, [0.01, 0.002])]
    rows = []
    for scene, sets, particles, duration, intervals in scenes:
        walls, cpus = {}, {}
        for interval in [0] + intervals:
            out = os.path.join(tmp, f"{scene}_{interval}")
            runs = [run_dem2d(args.dem2d, out, duration, interval, sets)
                    for _ in range(args.repeats)]
            walls[interval] = statistics.median(r[0] for r in runs)
            cpus[interval] = statistics.median(r[1] for r in runs)
            if interval == 0:
                continue
            n = snapshot_count(out)
            size = os.path.getsize(os.path.join(out, "snapshots.h5"))
            rows.append({"label": args.label, "scene": scene, "particles": particles,
                         "interval_s": interval, "snapshots": n, "wall_s": f"{walls[interval]:.3f}",
                         "cost_ms": f"{1e3 * (walls[interval] - walls[0]) / n:.3f}",
                         "cpu_ms": f"{1e3 * (cpus[interval] - cpus[0]) / n:.3f}",
                         "bytes_per_snapshot": size // n})
        print(f"{scene}: {walls[0]:.2f} s without snapshots", flush=True)
    return rows


def proc_kb(pid, key):
    try:
        with open(f"/proc/{pid}/status", encoding="ascii") as f:
            for line in f:
                if line.startswith(key + ":"):
                    return int(line.split()[1])
    except OSError:
        pass
    return None


def memory_rows(args, tmp):
    """RSS against snapshots written, for one run writing args.memory_snapshots snapshots."""
    out = os.path.join(tmp, "memory")
    xmf = os.path.join(out, "snapshots.xmf")

    def sample(pid, elapsed):
        rss, peak = proc_kb(pid, "VmRSS"), proc_kb(pid, "VmHWM")
        size = os.path.getsize(xmf) if os.path.exists(xmf) else 0
        return None if rss is None else (elapsed, size, rss, peak)

    duration = args.memory_snapshots * 1e-4
    _, _, samples = run_dem2d(args.dem2d, out, duration, 1e-4, [], sample)
    n = snapshot_count(out)
    final = os.path.getsize(xmf)
    first = min((s[1] for s in samples if s[1] > 0), default=0)
    grid = (final - first) / max(n - 1, 1)  # bytes one snapshot adds to the sidecar
    rows = []
    for elapsed, size, rss, peak in samples:
        written = 0 if size == 0 else 1 + round((size - first) / grid)
        rows.append({"label": args.label, "elapsed_s": f"{elapsed:.2f}", "snapshots": written,
                     "rss_mb": f"{rss / 1024:.2f}", "peak_mb": f"{peak / 1024:.2f}"})
    return rows, n


def append_csv(path, fields, rows):
    new = not os.path.exists(path)
    with open(path, "a", newline="", encoding="ascii") as f:
        w = csv.DictWriter(f, fieldnames=fields)
        if new:
            w.writeheader()
        w.writerows(rows)


def print_cost(rows):
    print(f"{'label':>10} {'scene':>10} {'N':>6} {'interval':>9} {'snaps':>6} {'wall s':>8} "
          f"{'ms/snap':>8} {'CPU ms':>7} {'kB/snap':>8}")
    for r in rows:
        print(f"{r['label']:>10} {r['scene']:>10} {r['particles']:>6} {r['interval_s']:>9} "
              f"{r['snapshots']:>6} {r['wall_s']:>8} {r['cost_ms']:>8} {r['cpu_ms']:>7} "
              f"{r['bytes_per_snapshot'] / 1000:>8.1f}")


def print_memory(rows, n):
    marks = [r for r in rows if r["snapshots"] > 0]
    print(f"memory: {n} snapshots written")
    print(f"{'label':>10} {'snapshots':>10} {'RSS MB':>8} {'peak MB':>8}")
    for k in range(0, 11):
        target = k * n / 10
        near = min(marks, key=lambda r: abs(r["snapshots"] - target), default=None)
        if near is not None:
            print(f"{near['label']:>10} {near['snapshots']:>10} {near['rss_mb']:>8} "
                  f"{near['peak_mb']:>8}")


def plot(results):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    def read(name):
        path = os.path.join(results, name)
        if not os.path.exists(path):
            return []
        with open(path, encoding="ascii") as f:
            return list(csv.DictReader(f))

    cost, memory = read("snapshot_cost.csv"), read("snapshot_memory.csv")
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2))
    labels = list(dict.fromkeys([r["label"] for r in cost] + [r["label"] for r in memory]))
    for k, label in enumerate(labels):
        colour = f"C{k}"
        for scene, marker in (("waterfall", "o"), ("large", "s")):
            rs = [r for r in cost if r["label"] == label and r["scene"] == scene]
            if rs:
                left.plot([int(r["bytes_per_snapshot"]) / 1e3 for r in rs],
                          [float(r["cost_ms"]) for r in rs], marker, color=colour,
                          label=f"{label}, {scene} ({rs[0]['particles']} balls)")
        ms = [r for r in memory if r["label"] == label]
        if ms:
            right.plot([int(r["snapshots"]) for r in ms], [float(r["rss_mb"]) for r in ms],
                       color=colour, label=label)
    left.set_xscale("log")
    left.set_yscale("log")
    left.set_xlabel("snapshot size in snapshots.h5 (kB)")
    left.set_ylabel("wall time per snapshot (ms)")
    left.set_title("cost of a snapshot (median of repeats)")
    left.legend(fontsize=8)
    right.set_xlabel("snapshots written")
    right.set_ylabel("resident set (MB)")
    right.set_title("memory of a waterfall run, a snapshot every 10 steps")
    right.legend(fontsize=8)
    fig.tight_layout()
    path = os.path.join(results, "snapshot_cost.png")
    fig.savefig(path, dpi=120)
    print(f"wrote {path}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dem2d", default=os.path.join(SRC, "build", "src", "dem2d"))
    ap.add_argument("--label", default="dem2d")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--memory-snapshots", type=int, default=10000)
    ap.add_argument("--quick", action="store_true", help="one short scene, 1 000 snapshots")
    ap.add_argument("--memory-only", action="store_true", help="skip the cost runs")
    ap.add_argument("--results", default=os.path.join(SRC, "bench", "results"))
    ap.add_argument("--no-plot", action="store_true")
    ap.add_argument("--plot-only", action="store_true")
    args = ap.parse_args()
    os.makedirs(args.results, exist_ok=True)
    if not args.plot_only:
        if args.quick:
            args.memory_snapshots = min(args.memory_snapshots, 1000)
        with tempfile.TemporaryDirectory(prefix="snapshot_cost_") as tmp:
            if not args.memory_only:
                cost = cost_rows(args, tmp)
                print_cost(cost)
                append_csv(os.path.join(args.results, "snapshot_cost.csv"), COST_FIELDS, cost)
            memory, n = memory_rows(args, tmp)
            print_memory(memory, n)
            append_csv(os.path.join(args.results, "snapshot_memory.csv"), MEMORY_FIELDS, memory)
    if not args.no_plot:
        plot(args.results)
    return 0


if __name__ == "__main__":
    sys.exit(main())
