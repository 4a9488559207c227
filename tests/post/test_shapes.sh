#!/bin/bash
# Superellipses in the pictures: post/render_snapshot.py and post/report.py's charge pictures
# (post/millplot.py) draw each superellipse as its outline polygon at its angle and each disc
# as a circle. On a made-up snapshots.h5 of a mixed scene (discs, ellipses and rounded boxes of
# exponents 2 to 50 at many angles), what render_snapshot.py --json says it drew, and the
# collections millplot.draw_charge adds to the axes, are measured here: every superellipse is a
# polygon of 64 points, counter-clockwise, centred on its particle, of the area
# 4ab Gamma(1+1/n)^2 / Gamma(1+2/n) less the polygon's discretisation (an ellipse: exactly
# (K/2pi) sin(2pi/K) of it; a rounded box: at most 0.2 % less), with the long axis of an
# ellipse along its angle (the polygon's principal axis of inertia); every disc a circle of its
# radius; a snapshot without shape datasets (discs only) draws circles only. post/h5compare.py
# compares the outlines of /outlines matched by id. Then a real run of tests/post/shapes.in
# (ellipses, rounded squares, discs and a fill of superellipses in a box) on 1 and 2 ranks, and
# stopped half-way and continued with --restart.
#
#   tests/post/test_shapes.sh [DEM2D [SOURCE_DIR]]
#
# Uses /usr/bin/python3 (numpy, matplotlib, h5py). Everything is written in a temporary folder
# that is removed at the end.
set -u

source_dir=${2:-$(cd "$(dirname "$0")/../.." && pwd)}
dem2d=${1:-$source_dir/build/src/dem2d}
py=/usr/bin/python3
post=$source_dir/post
work=$(mktemp -d "${TMPDIR:-/tmp}/dem2d_shapes.XXXXXX")
trap 'rm -rf "$work"' EXIT
export MPLBACKEND=Agg

source "${BASH_SOURCE[0]%/*}/checks.sh"

# measure.py H5 JSON: checks render_snapshot.py's --json output JSON against the snapshots of H5.
cat >"$work/measure.py" <<'EOF'
import json
import math
import sys

import h5py
import numpy as np

K = 64


def shoelace(v):
    x, y = v[:, 0], v[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def centroid_and_axis(v):
    """Area centroid and the angle of the principal axis of least inertia (the long axis)."""
    x, y = v[:, 0], v[:, 1]
    x1, y1 = np.roll(x, -1), np.roll(y, -1)
    cross = x * y1 - x1 * y
    area = 0.5 * cross.sum()
    cx = ((x + x1) * cross).sum() / (6 * area)
    cy = ((y + y1) * cross).sum() / (6 * area)
    x, y, x1, y1 = x - cx, y - cy, x1 - cx, y1 - cy
    cross = x * y1 - x1 * y
    ixx = ((y * y + y * y1 + y1 * y1) * cross).sum() / 12  # integral of y^2
    iyy = ((x * x + x * x1 + x1 * x1) * cross).sum() / 12  # integral of x^2
    ixy = ((x * y1 + 2 * x * y + 2 * x1 * y1 + x1 * y) * cross).sum() / 24
    return np.array([cx, cy]), 0.5 * math.atan2(2 * ixy, iyy - ixx)


def exact_area(a, b, n):
    return 4 * a * b * math.gamma(1 + 1 / n) ** 2 / math.gamma(1 + 2 / n)


h5_path, drawn_path = sys.argv[1], sys.argv[2]
drawn = json.load(open(drawn_path))
problems, outlines_seen = [], 0
with h5py.File(h5_path, "r") as f:
    for picture in drawn:
        g = f["snapshots"][picture["snapshot"]]
        ids = list(g["id"][()])
        row = {int(i): k for k, i in enumerate(ids)}
        shaped = "semi_axis_a" in g
        a = g["semi_axis_a"][()] if shaped else g["radius"][()]
        b = g["semi_axis_b"][()] if shaped else g["radius"][()]
        n = g["exponent"][()] if shaped else np.full(len(ids), 2.0)
        angle, pos, radius = g["angle"][()], g["position"][()], g["radius"][()]
        want_outlines = {int(ids[k]) for k in range(len(ids)) if a[k] != b[k] or n[k] != 2}
        got_outlines = {o["id"] for o in picture["outlines"]}
        got_circles = {c["id"] for c in picture["circles"]}
        if got_outlines != want_outlines:
            problems.append(f"{picture['snapshot']}: outlines of {sorted(got_outlines)}, not {sorted(want_outlines)}")
        if got_circles != set(map(int, ids)) - want_outlines:
            problems.append(f"{picture['snapshot']}: circles of {sorted(got_circles)}")
        for c in picture["circles"]:
            k = row[c["id"]]
            if c["radius"] != radius[k] or c["centre"] != list(pos[k]):
                problems.append(f"circle {c['id']}: {c} is not particle row {k}")
        for o in picture["outlines"]:
            k, v = row[o["id"]], np.array(o["vertices"])
            where = f"{picture['snapshot']} id {o['id']} (a {a[k]:.4g}, b {b[k]:.4g}, n {n[k]:.4g}, angle {angle[k]:.4g})"
            outlines_seen += 1
            if v.shape != (K, 2):
                problems.append(f"{where}: {v.shape} vertices")
                continue
            ratio = shoelace(v) / exact_area(a[k], b[k], n[k])
            if n[k] == 2:
                regular = K / (2 * math.pi) * math.sin(2 * math.pi / K)
                if abs(ratio - regular) > 1e-9:
                    problems.append(f"{where}: area ratio {ratio:.12f}, not the {K}-gon's {regular:.12f}")
            elif not 0.998 < ratio <= 1.0:
                problems.append(f"{where}: area ratio {ratio:.6f} (negative: clockwise)")
            centre, axis = centroid_and_axis(v)
            if np.linalg.norm(centre - pos[k]) > 1e-9 * (1 + np.abs(pos[k]).max()):
                problems.append(f"{where}: centred at {centre}, not {pos[k]}")
            if abs(a[k] - b[k]) > 0.05 * max(a[k], b[k]):
                long_axis = angle[k] if a[k] > b[k] else angle[k] + math.pi / 2
                turn = (axis - long_axis + math.pi / 2) % math.pi - math.pi / 2
                if abs(turn) > 1e-6:
                    problems.append(f"{where}: long axis at {axis:.6f} rad, the particle's at {long_axis:.6f} (mod pi)")
print("\n".join(problems))
print(f"{outlines_seen} outlines measured")
sys.exit(1 if problems or (outlines_seen == 0 and "--no-shapes" not in sys.argv) else 0)
EOF

# A mixed scene: row k a disc when k % 4 == 0, else an ellipse or rounded box of exponent
# 2, 3, 4, 8, 20 or 50 with semi-axes 0.05 and 0.02-0.05 m at angle 0.37 k - 2 rad (several
# full turns, both signs); snapshot 000001 moves and turns them; 000002 has no shape datasets.
check "made-up mixed scene written" "$py" - "$work/mixed.h5" <<'EOF'
import sys
import h5py
import numpy as np
with h5py.File(sys.argv[1], "w") as f:
    f["materials/name"] = [b"steel", b"ore"]
    count = 36
    k = np.arange(count)
    disc = k % 4 == 0
    exponents = np.array([2.0, 3.0, 4.0, 8.0, 20.0, 50.0])
    for version in range(3):
        g = f.create_group(f"snapshots/{version:06d}")
        g.attrs["time"], g.attrs["step"] = 0.1 * version, np.int64(100 * version)
        g["id"] = (1000 + 7 * k[::-1]).astype(np.int64)  # not in id order
        g["material"] = (k % 2).astype(np.int32)
        g["position"] = np.column_stack([0.13 * (k % 6) + 0.01 * version, 0.13 * (k // 6) - 0.02 * version])
        g["velocity"] = np.column_stack([np.sin(k), np.cos(k)])
        g["angle"] = 0.37 * k - 2.0 + 0.5 * version
        g["spin"] = np.zeros(count)
        a = np.full(count, 0.05)
        b = np.where(disc, 0.05, 0.02 + 0.03 * (k % 5) / 4.0)
        n = np.where(disc, 2.0, exponents[k % 6])
        bound = np.where(n == 2, np.maximum(a, b), np.sqrt(a * a + b * b))  # enough for drawing
        g["radius"] = bound
        g["speed"] = np.ones(count)
        if version < 2:
            g["semi_axis_a"], g["semi_axis_b"], g["exponent"] = a, b, n
EOF

check "render_snapshot.py draws superellipses as outlines at their angles (--json measured)" \
  bash -c "'$py' '$post/render_snapshot.py' '$work/mixed.h5' --all -o '$work/frames' --json '$work/drawn.json' &&
           '$py' '$work/measure.py' '$work/mixed.h5' '$work/drawn.json'"
check "render_snapshot.py --color speed, one snapshot" \
  bash -c "'$py' '$post/render_snapshot.py' '$work/mixed.h5' --index 1 --color speed -o '$work/one.png' --json '$work/one.json' &&
           '$py' '$work/measure.py' '$work/mixed.h5' '$work/one.json'"

# The picture itself: a particle's pixels. Snapshot 000000 drawn large, then the colour at the
# tips of each ellipse's long axis (inside, 90 % of the way out) and of its short axis turned
# to the long one's direction (outside the shape) read from the PNG through the axes' transform.
check "the PNG has each ellipse's colour at its long axis and the background beside it" \
  "$py" - "$post" "$work/mixed.h5" "$work/pixels.png" <<'EOF'
import sys
sys.path.insert(0, sys.argv[1])
import h5py
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import millplot
with h5py.File(sys.argv[2], "r") as f:
    snap = millplot.read_snapshot(f, "000000")
fig, ax = plt.subplots(figsize=(8, 8), dpi=100)
ax.set_xlim(-0.1, 0.8)
ax.set_ylim(-0.1, 0.8)
ax.set_aspect("equal")
ax.set_axis_off()
red = (1.0, 0.0, 0.0, 1.0)
millplot.particle_collections(ax, snap, facecolors=[red] * len(snap["id"]), edgecolors="none")
fig.savefig(sys.argv[3], dpi=100)
img = plt.imread(sys.argv[3])
height = img.shape[0]
def colour(xy):
    px, py = ax.transData.transform(xy)
    return img[int(round(height - py)), int(round(px)), :3]
s, bad, tested = snap["shape"], [], 0
for k in millplot.shaped_rows(snap):
    a, b, theta = s["a"][k], s["b"][k], s["angle"][k]
    if a - b < 0.02:
        continue
    tested += 1
    along = np.array([np.cos(theta), np.sin(theta)])
    for sign in (1, -1):
        inside = snap["position"][k] + sign * 0.9 * a * along
        if not np.allclose(colour(inside), [1, 0, 0], atol=0.05):
            bad.append(f"row {k}: not red at {inside} on its long axis")
    across = np.array([-np.sin(theta), np.cos(theta)])
    outside = snap["position"][k] + 0.9 * a * across  # past the short semi-axis b <= 0.03
    if np.allclose(colour(outside), [1, 0, 0], atol=0.05):
        bad.append(f"row {k}: red at {outside}, beyond its short axis")
print("\n".join(bad))
print(f"{tested} ellipses tested")
sys.exit(1 if bad or tested < 5 else 0)
EOF

check "report.py's charge picture (millplot.draw_charge): outlines and circles" \
  "$py" - "$post" "$work/mixed.h5" "$work/drawn_report.json" <<'EOF'
import json, sys
sys.path.insert(0, sys.argv[1])
import h5py
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
import millplot
import render_snapshot
pictures = []
with h5py.File(sys.argv[2], "r") as f:
    for name in ("000000", "000001", "000002"):
        snap = millplot.read_snapshot(f, name)
        fig, ax = plt.subplots()
        millplot.draw_charge(ax, snap, None, {}, 1.0)
        drawn = [c for c in ax.collections if hasattr(c, "rows")]
        snap["position"] = snap["position"]
        pictures.append(render_snapshot.drawn_shapes(snap, drawn))
        plt.close(fig)
json.dump(pictures, open(sys.argv[3], "w"))
EOF
check "report.py's charge picture measured" "$py" "$work/measure.py" "$work/mixed.h5" "$work/drawn_report.json"

# post/h5compare.py compares the particles' outlines (/outlines/NAME/points) matched by id: the
# made-up scene with outlines, again with its rows in another order (equal), and with one
# outline point moved by an ulp (a difference naming the outline).
check "h5compare.py matches outlines by id and finds a changed point" \
  "$py" - "$post" "$work" <<'EOF'
import subprocess, sys
import h5py
import numpy as np
post, work = sys.argv[1], sys.argv[2]
sys.path.insert(0, post)
import millplot
def write(path, order, nudge=False):
    with h5py.File(f"{work}/mixed.h5", "r") as src, h5py.File(path, "w") as f:
        f["materials/name"] = src["materials/name"][()]
        for name in ("000000", "000001"):
            g, s = f.create_group(f"snapshots/{name}"), src["snapshots"][name]
            for key, value in s.attrs.items():
                g.attrs[key] = value
            for field in s:
                g[field] = s[field][()][order]
            snap = millplot.read_snapshot(src, name)
            sh = snap["shape"]
            pts = millplot.superellipse_outlines(sh["a"], sh["b"], sh["n"], sh["angle"],
                                                 snap["position"], 24).astype(np.float32)[order]
            if nudge and name == "000001":
                pts[5, 3, 1] = np.nextafter(pts[5, 3, 1], np.float32(1))
            f[f"outlines/{name}/points"] = pts.reshape(-1, 2)
order = np.arange(36)
write(f"{work}/a.h5", order)
write(f"{work}/b.h5", order[::-1].copy())
write(f"{work}/c.h5", order[::-1].copy(), nudge=True)
same = subprocess.run([sys.executable, f"{post}/h5compare.py", f"{work}/a.h5", f"{work}/b.h5"],
                      capture_output=True, text=True)
assert same.returncode == 0, same.stdout + same.stderr
differ = subprocess.run([sys.executable, f"{post}/h5compare.py", f"{work}/a.h5", f"{work}/c.h5"],
                        capture_output=True, text=True)
assert differ.returncode == 1 and "/snapshots/000001/outline" in differ.stdout, differ.stdout
print(same.stdout, differ.stdout)
EOF

# --- A real run: tests/post/shapes.in (ellipses, rounded squares and discs into a box) ----------
# On 1 and 2 ranks: the two files agree bit for bit (post/h5compare.py, outlines included), both
# sidecars pass tests/io/check_xdmf.py (the outlines' polygons measured against the shape
# datasets), the first snapshot holds the deck's shapes and angles, render_snapshot.py's
# pictures measure as above, and report.py makes its charge pictures.
deck=$source_dir/tests/post/shapes.in
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
check "dem2d runs tests/post/shapes.in on 1 and 2 ranks" \
  bash -c "'$dem2d' --quiet --output '$work/run1' '$deck' &&
           mpirun -np 2 --oversubscribe '$dem2d' --quiet --output '$work/run2' '$deck'"
check "run.json counts the superellipse solves: none unconverged, 1-10 evaluations each" \
  "$py" -c "
import json, sys
c = json.load(open(sys.argv[1]))['superellipse_contacts']
assert c['pair_solves'] > 0 and c['wall_solves'] > 0, c
assert c['pair_unconverged'] == 0 and c['wall_unconverged'] == 0, c
assert 0 < c['pair_cold_starts'] < c['pair_solves'], c
assert 1.0 <= c['depth_evaluations_per_pair_solve'] <= 10.0, c
# The histogram of evaluations per pair solve: every solve in one bin, and its mean (each bin
# between its least and its most evaluations) holds the mean reported (printed to 4 digits).
h = c['depth_evaluations_histogram']
bins = {'1': (1, 1), '2': (2, 2), '3': (3, 3), '4': (4, 4), '5-8': (5, 8), '9-16': (9, 16),
        '17+': (17, float('inf'))}
assert list(h) == list(bins), h
assert sum(h.values()) == c['pair_solves'], c
least = sum(bins[k][0] * v for k, v in h.items()) / c['pair_solves']
most = sum(bins[k][1] * v for k, v in h.items() if v > 0) / c['pair_solves']
mean = c['depth_evaluations_per_pair_solve']
assert least * (1 - 5e-4) <= mean <= most * (1 + 5e-4), (least, mean, most, h)
" "$work/run1/run.json"
check "1 and 2 ranks: the same snapshots, outlines included (h5compare.py)" \
  "$py" "$post/h5compare.py" "$work/run1/snapshots.h5" "$work/run2/snapshots.h5"
check "check_xdmf.py on both runs' snapshots.xmf" \
  bash -c "'$py' '$source_dir/tests/io/check_xdmf.py' '$work/run1/snapshots.xmf' &&
           '$py' '$source_dir/tests/io/check_xdmf.py' '$work/run2/snapshots.xmf'"
check "the first snapshot holds the deck's shapes and angles" \
  "$py" - "$deck" "$work/run1/snapshots.h5" <<'EOF'
import sys, tomllib
import h5py
import numpy as np
deck = tomllib.load(open(sys.argv[1], "rb"))
with h5py.File(sys.argv[2], "r") as f:
    g = f["snapshots/000000"]
    pos, a, b, n, angle = (g[k][()] for k in ("position", "semi_axis_a", "semi_axis_b", "exponent", "angle"))
    assert "outlines" in f and len(f["outlines/000000/points"]) == 24 * len(pos)
bad = []
fill = deck["fill"][0]
assert len(pos) == len(deck["particle"]) + fill["count"], len(pos)
for p in deck["particle"]:
    k = int(np.argmin(np.hypot(*(pos - np.array(p["position"])).T)))
    if p.get("shape") == "superellipse":
        want = (p["semi_axes"][0], p["semi_axes"][1], p.get("exponent", 2.0), np.radians(p["angle"]))
    else:
        want = (p["radius"], p["radius"], 2.0, 0.0)
    got = (a[k], b[k], n[k], angle[k])
    if got[:3] != want[:3] or abs(got[3] - want[3]) > 1e-12:
        bad.append(f"particle at {p['position']}: (a, b, n, angle) = {got}, the deck's {want}")
# The fill's particles: superellipses of b / a = aspect, n = exponent.
rest = np.ones(len(pos), bool)
for p in deck["particle"]:
    rest[int(np.argmin(np.hypot(*(pos - np.array(p["position"])).T)))] = False
if not (np.allclose(b[rest] / a[rest], fill["aspect"], rtol=1e-12) and np.all(n[rest] == fill["exponent"])):
    bad.append(f"the fill's particles: b/a {b[rest] / a[rest]}, n {n[rest]}")
print("\n".join(bad))
assert not bad
EOF
check "render_snapshot.py on the run: outlines at their angles (--json measured)" \
  bash -c "'$py' '$post/render_snapshot.py' '$work/run1/snapshots.h5' --all -o '$work/run_frames' --json '$work/run.json' &&
           '$py' '$work/measure.py' '$work/run1/snapshots.h5' '$work/run.json'"
check "report.py on the run makes its charge pictures" \
  bash -c "'$py' '$post/report.py' '$work/run1' --no-animation > '$work/report.log' 2>&1 &&
           ls '$work/run1/report/'charge_*.png > /dev/null"

# A run stopped at 0.15 s (its checkpoint) and continued with --restart on 2 ranks: its
# snapshots.h5 continues the first part's (the snapshots after the checkpoint replaced), the
# same as the uninterrupted run's snapshot for snapshot, outlines included, and its sidecar
# lists them all with their outlines.
check "a run continued with --restart: the same snapshots and outlines as the whole run" \
  bash -c "'$dem2d' --quiet --output '$work/part' --set run.duration=0.15 '$deck' &&
           mpirun -np 2 --oversubscribe '$dem2d' --quiet --output '$work/part' --restart '$work/part/checkpoint.h5' '$deck' &&
           '$py' '$post/h5compare.py' --by-step --allow-added '$work/run1/snapshots.h5' '$work/part/snapshots.h5' &&
           '$py' '$source_dir/tests/io/check_xdmf.py' '$work/part/snapshots.xmf' &&
           test \$('$py' -c 'import h5py, sys; f = h5py.File(sys.argv[1]); print(len(f[\"outlines\"]) == len(f[\"snapshots\"]))' '$work/part/snapshots.h5') = True"

# post/compare_shapes.py on two short runs of inputs/shapes.in's drum with a thinner charge
# (discs, then ellipses of the same count and mass): its figures are the series' and the
# snapshots' own means over the window, the reference's ratios are 1 and the masses agree.
shapes_deck=$source_dir/inputs/shapes.in
check "compare_shapes.py: discs against ellipses, figures recomputed from the runs" \
  bash -c "'$dem2d' --quiet --output '$work/sd' --set run.duration=0.2 --set fill.0.bed_filling=0.1 --set output.snapshot_interval=0.02 '$shapes_deck' &&
           '$dem2d' --quiet --output '$work/se' --set run.duration=0.2 --set fill.0.bed_filling=0.1 --set output.snapshot_interval=0.02 --set fill.0.shape=superellipse --set fill.0.aspect=0.5 '$shapes_deck' &&
           '$py' '$post/compare_shapes.py' '$work/sd' '$work/se' --window 0.1 --json '$work/cmp.json' -o '$work/cmp.png' > '$work/cmp.txt' &&
           test -s '$work/cmp.png' &&
           '$py' - '$work/sd' '$work/se' '$work/cmp.json' <<'PY'
import csv, json, sys
import h5py
import numpy as np
runs = json.load(open(sys.argv[3]))
assert runs[0]['label'] == 'discs', runs[0]['label']
assert runs[1]['label'].startswith('superellipse n=2 aspect 0.5'), runs[1]['label']
for folder, r in zip(sys.argv[1:3], runs):
    rows = list(csv.DictReader(open(folder + '/series.csv')))
    t = np.array([float(x['time']) for x in rows])
    tail = t >= t[-1] - 0.1
    sh = np.nanmean(np.array([float(x['shoulder_angle']) for x in rows])[tail])
    pw = np.mean(np.array([float(x['drum_power']) for x in rows])[tail])
    assert abs(sh - r['shoulder_angle_deg']) <= 1e-9 * abs(sh), (sh, r['shoulder_angle_deg'])
    assert abs(pw - r['power_W']) <= 1e-9 * abs(pw) + 1e-12, (pw, r['power_W'])
    f = h5py.File(folder + '/snapshots.h5', 'r')
    v = []
    for name in f['snapshots']:
        g = f['snapshots'][name]
        if g.attrs['time'] >= t[-1] - 0.1:
            vel = np.asarray(g['velocity'][()]).reshape(-1, 2)
            v.append(np.hypot(vel[:, 0], vel[:, 1]))
    v = np.concatenate(v)
    assert abs(v.mean() - r['speed_mean']) <= 1e-6 * v.mean(), (v.mean(), r['speed_mean'])
assert abs(runs[0]['charge_mass_kg'] - runs[1]['charge_mass_kg']) <= 1e-12 * runs[0]['charge_mass_kg']
assert runs[0]['particles'] == runs[1]['particles']
text = open(sys.argv[3].replace('cmp.json', 'cmp.txt')).read()
assert [l for l in text.splitlines() if l.startswith('drive power')][0].split('W]')[1].split()[1:3] == ['(', '1.00x)'], text
print('compare_shapes figures recomputed')
PY"

finish
