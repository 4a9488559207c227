#!/bin/bash
# lifters.csv and post/plot_lifters.py on short runs of the thesis drum (inputs/waterfall.in):
#   - lifters.csv is the same bytes on 1, 2 and 3 ranks, and after a run resumed from a
#     checkpoint on another rank count;
#   - one row per bar (0..23, in order) at every series row, at series.csv's times; the bars'
#     angles are the drum's angle (its ramp) plus their places, from the bottom, 15 degrees
#     apart; the bars' torques add up to series.csv's lifter_torque at every row; some bars
#     carry the charge (contacts, a positive normal load);
#   - a deck without lifters writes no lifters.csv; decks without a [shell] write no shell into
#     snapshots.h5;
#   - with a [shell] (inputs/shell.in): lifters.csv carries the shell's columns, the same bytes
#     on 1, 2 and 3 ranks and across a restart; a bar with no contact is barely deflected
#     against the loaded ones; run.json's shell figures (nodal loads = wall loads); the deck
#     without its [shell] runs the same bits (series.csv, the loads of lifters.csv); every
#     snapshot holds the shell (nodes on the ring and bars, a finite displacement, von Mises),
#     the same bytes on 1, 2 and 3 ranks and after the restart, and snapshots.xmf's shell grid
#     names datasets of snapshots.h5 with their shapes;
#   - post/plot_lifters.py draws a PNG, prints the CSV's own largest normal load as its peak
#     (and writes it bit for bit with --json), a loaded window around the mean profile's peak,
#     and --window keeps the rows of the last T seconds.
#
#   tests/post/test_lifters.sh [DEM2D [SOURCE_DIR]]
set -u

source_dir=${2:-$(cd "$(dirname "$0")/../.." && pwd)}
dem2d=${1:-$source_dir/build/src/dem2d}
py=/usr/bin/python3
wf=$source_dir/inputs/waterfall.in
work=$(mktemp -d "${TMPDIR:-/tmp}/dem2d_lifters.XXXXXX")
trap 'rm -rf "$work"' EXIT
export MPLBACKEND=Agg
export OMPI_MCA_mpi_yield_when_idle=1

source "${BASH_SOURCE[0]%/*}/checks.sh"

run=(--quiet --set run.duration=0.3 --set output.snapshot_interval=0)
check "run on 1 rank" "$dem2d" "$wf" "${run[@]}" --output "$work/np1"
check "run on 2 ranks" mpirun -np 2 --oversubscribe "$dem2d" "$wf" "${run[@]}" --output "$work/np2"
check "run on 3 ranks" mpirun -np 3 --oversubscribe "$dem2d" "$wf" "${run[@]}" --output "$work/np3"
check "the first half on 1 rank" "$dem2d" "$wf" "${run[@]}" --set run.duration=0.15 --output "$work/rs"
check "resumed on 2 ranks" mpirun -np 2 --oversubscribe "$dem2d" "$wf" "${run[@]}" \
  --output "$work/rs" --restart "$work/rs/checkpoint.h5"
for other in np2 np3 rs; do
  check "lifters.csv: np1 = $other, byte for byte" cmp "$work/np1/lifters.csv" "$work/$other/lifters.csv"
done

check "lifters.csv against series.csv and the drum" "$py" - "$work/np1" <<'PY'
import csv, math, sys
d = sys.argv[1]
rows = list(csv.reader(open(f"{d}/lifters.csv")))
assert rows[0] == ["time", "lifter", "angle_deg", "normal_N", "radial_N", "torque_Nm",
                   "contacts"], rows[0]
rows = rows[1:]
series = list(csv.DictReader(open(f"{d}/series.csv")))
bars = 24
assert len(rows) == bars * len(series), f"{len(rows)} rows for {len(series)} series rows"
speed, ramp = 1.8, 0.5  # inputs/waterfall.in
loaded = 0
for k, s in enumerate(series):
    group = rows[bars * k: bars * (k + 1)]
    assert all(r[0] == s["time"] for r in group), f"times at series row {k}"
    assert [int(r[1]) for r in group] == list(range(bars)), f"bar order at row {k}"
    t = float(s["time"])
    turned = 0.5 * speed * t * t / ramp if t < ramp else speed * (t - 0.5 * ramp)
    torque, scale = 0.0, 0.0
    for b, r in enumerate(group):
        angle = float(r[2])
        assert 0.0 <= angle < 360.0, angle
        # Bar b stands at 360 b / 24 degrees counter-clockwise of +x at t = 0: 90 + 15 b from
        # the bottom, counter-clockwise (the drum's sense).
        want = (90.0 + 15.0 * b + math.degrees(turned)) % 360.0
        gap = abs(angle - want)
        assert min(gap, 360.0 - gap) < 1e-9, f"bar {b} at t = {t}: {angle} vs {want}"
        torque += float(r[5])
        scale += abs(float(r[5]))
        contacts = int(r[6])
        assert contacts >= 0
        if contacts == 0:
            assert float(r[3]) == 0.0 and float(r[4]) == 0.0 and float(r[5]) == 0.0, r
        else:
            loaded += 1
    lt = float(s["lifter_torque"])
    assert abs(torque - lt) <= 1e-12 * scale, f"t = {t}: sum {torque} vs {lt}"
assert loaded > 20, f"only {loaded} loaded bar rows"
assert max(float(r[3]) for r in rows) > 0.0, "no bar presses on the charge"
print(f"{len(series)} series rows, {loaded} loaded bar rows")
PY

# No lifters, no file: the drum of inputs/cascade_cataract.in has none.
check "a drum without lifters runs" "$dem2d" "$source_dir/inputs/cascade_cataract.in" --quiet \
  --set run.duration=0.002 --output "$work/bare"
if [ -e "$work/bare/lifters.csv" ]; then
  fail "no lifters, no lifters.csv"
else
  pass "no lifters, no lifters.csv"
fi

check "decks without a [shell] write no shell into snapshots.h5" "$py" - "$work/np1" "$work/bare" <<'PY'
import sys
import h5py
for d in sys.argv[1:]:
    with h5py.File(f"{d}/snapshots.h5", "r") as f:
        assert len(f["snapshots"]) > 0, d
        assert "shell" not in f and "shell_mesh" not in f, (d, list(f))
    assert 'Name="shell"' not in open(f"{d}/snapshots.xmf").read(), d
PY

# post/plot_lifters.py
if out=$("$py" "$source_dir/post/plot_lifters.py" "$work/np3/lifters.csv" -o "$work/l.png" \
  --json "$work/l.json" 2>&1); then
  pass "plot_lifters.py runs"
else
  fail "plot_lifters.py runs"
fi
sed 's/^/     /' <<<"$out"
check "plot_lifters.py: its figures against the CSV" "$py" - "$work/np3/lifters.csv" "$work/l.json" \
  "$work/l.png" "$out" <<'PY'
import csv, json, re, sys
path, js, png, printed = sys.argv[1:5]
rows = list(csv.DictReader(open(path)))
f = json.load(open(js))
normal = [float(r["normal_N"]) for r in rows]
top = max(normal)
assert f["rows"] == len(rows) and f["bars"] == 24, (f["rows"], f["bars"])
assert f["peak_normal_N"] == top, (f["peak_normal_N"], top)
k = normal.index(top)
assert f["peak_angle_deg"] == float(rows[k]["angle_deg"])
assert f["peak_lifter"] == int(rows[k]["lifter"])
assert f["peak_radial_N"] == max(float(r["radial_N"]) for r in rows)
m = re.search(r"peak normal load: ([0-9.e+-]+) N", printed)
assert m and abs(float(m.group(1)) - top) <= 1e-8 * top, printed
# The mean profile, binned here: its peak, and the loaded window's bins above 10 % of it with
# the bins on either side not.
bins = f["bins"]
width = 360.0 / bins
sums, counts = {}, {}
for r in rows:
    b = min(int(float(r["angle_deg"]) / width), bins - 1)
    sums[b] = sums.get(b, 0.0) + float(r["normal_N"])
    counts[b] = counts.get(b, 0) + 1
mean = {b: sums[b] / counts[b] for b in sums}
best = max(mean, key=mean.get)
assert abs(f["mean_peak_normal_N"] - mean[best]) <= 1e-12 * mean[best], (f, mean[best])
lo, hi = f["loaded_from_deg"], f["loaded_to_deg"]
first, count = int(round(lo / width)), int(round((hi - lo) / width))
inside = [(first + j) % bins for j in range(count)]
assert best in inside, (lo, hi, best)
assert all(mean.get(b, -1.0) > 0.1 * mean[best] for b in inside), "a bin of the window below 10 %"
if count < bins:
    for edge in (first - 1, first + count):
        assert mean.get(edge % bins, -1.0) <= 0.1 * mean[best], f"the window stops early at {edge}"
assert "loaded window: " in printed
assert open(png, "rb").read(8) == b"\x89PNG\r\n\x1a\n"
print(f"peak {top} N, loaded {lo} to {hi} deg")
PY
check "plot_lifters.py --window keeps the last T seconds" "$py" - "$source_dir/post/plot_lifters.py" \
  "$work/np3/lifters.csv" "$work" <<'PY'
import csv, json, subprocess, sys
script, path, work = sys.argv[1:4]
rows = list(csv.DictReader(open(path)))
end = max(float(r["time"]) for r in rows)
subprocess.run([sys.executable, script, path, "--window", "0.1", "--json", f"{work}/w.json",
                "-o", f"{work}/w.png"], check=True, capture_output=True)
f = json.load(open(f"{work}/w.json"))
kept = [r for r in rows if float(r["time"]) >= end - 0.1]
assert f["rows"] == len(kept) < len(rows), (f["rows"], len(kept), len(rows))
assert f["peak_normal_N"] == max(float(r["normal_N"]) for r in kept)
PY


# --- The shell: inputs/shell.in -------------------------------------------------------------------
sh=$source_dir/inputs/shell.in
srun=(--quiet --set run.duration=0.12 --set output.snapshot_interval=0.04)
check "shell: run on 1 rank" "$dem2d" "$sh" "${srun[@]}" --output "$work/s1"
check "shell: run on 2 ranks" mpirun -np 2 --oversubscribe "$dem2d" "$sh" "${srun[@]}" --output "$work/s2"
check "shell: run on 3 ranks" mpirun -np 3 --oversubscribe "$dem2d" "$sh" "${srun[@]}" --output "$work/s3"
check "shell: the first half on 2 ranks" mpirun -np 2 --oversubscribe "$dem2d" "$sh" "${srun[@]}" \
  --set run.duration=0.06 --output "$work/srs"
check "shell: resumed on 1 rank" "$dem2d" "$sh" "${srun[@]}" --output "$work/srs" \
  --restart "$work/srs/checkpoint.h5"
for other in s2 s3 srs; do
  check "shell: lifters.csv s1 = $other, byte for byte" cmp "$work/s1/lifters.csv" "$work/$other/lifters.csv"
done
# One-way: the charge sees the rigid drum, so the deck without its [shell] (the shell's material
# still defined) runs the same bits.
sed '/^\[shell\]/,/^element_size/d' "$sh" > "$work/bare_shell.in"
check "shell: the deck without its [shell]" "$dem2d" "$work/bare_shell.in" "${srun[@]}" --output "$work/s0"
check "shell: series.csv the same bytes without the [shell]" cmp "$work/s1/series.csv" "$work/s0/series.csv"
check "shell: lifters.csv's loads the same without the [shell]" "$py" - "$work/s1" "$work/s0" <<'PY'
import csv, sys
a, b = (list(csv.reader(open(f"{d}/lifters.csv"))) for d in sys.argv[1:3])
assert len(a) == len(b) and len(b[0]) == 7, (len(a), len(b), b[0])
assert all(x[:7] == y for x, y in zip(a, b)), "the loads differ"
PY
check "shell: lifters.csv's shell columns and run.json" "$py" - "$work/s1" <<'PY'
import csv, json, sys
d = sys.argv[1]
rows = list(csv.reader(open(f"{d}/lifters.csv")))
assert rows[0][7:] == ["tip_deflection_m", "von_mises_max_Pa", "root_stress_Pa"], rows[0]
rows = [[float(x) for x in r] for r in rows[1:]]
assert len(rows) == 8 * 121, len(rows)
loaded = [r for r in rows if r[6] > 0 and r[3] > 0]
free = [r for r in rows if r[6] == 0]
assert len(loaded) > 50 and len(free) > 50, (len(loaded), len(free))
top = max(r[7] for r in rows)
assert top > 0, top
# A bar the charge presses on its lifting face bends back; a bar without a contact moves only
# with the ring, far less.
assert sum(1 for r in loaded if r[7] > 0) > 0.9 * len(loaded)
assert max(abs(r[7]) for r in free) < 0.2 * top, (max(abs(r[7]) for r in free), top)
# Its root section carries nothing (no load on the bar); the ring's strain reaches into its foot.
assert all(r[9] == 0 for r in free), "a root stress in a bar without a contact"
assert max(r[8] for r in free) < 0.2 * max(r[8] for r in rows)
assert all(r[8] >= 0 and r[9] >= 0 for r in rows)
shell = json.load(open(f"{d}/run.json"))["shell"]
assert shell["depth_m"] == 0.0116 and shell["elements"] > 500, shell
assert shell["last_nodal_load_error_N_per_m"] <= 1e-12 * shell["last_load_N_per_m"], shell
assert shell["last_records"] > 10, shell
print(f"{len(loaded)} loaded and {len(free)} free bar rows; peak tip {top:.3g} m")
PY
check "shell: the snapshots' shell on 1, 2, 3 ranks and across the restart" "$py" - "$work" <<'PY'
import json, math, os, sys
import xml.etree.ElementTree as ET
import h5py
import numpy as np
work = sys.argv[1]
R, t, h = 0.25, 0.01, 0.02  # inputs/shell.in: drum radius, shell thickness, bar height
centre = np.zeros(2)
info = json.load(open(f"{work}/s1/run.json"))["shell"]

def read(d):
    out = {}
    with h5py.File(f"{d}/snapshots.h5", "r") as f:
        assert "shell" in f and "shell_mesh" in f, list(f)
        assert sorted(f["shell"]) == sorted(f["snapshots"]), (list(f["shell"]), list(f["snapshots"]))
        m = {k: f["shell_mesh"][k][()] for k in f["shell_mesh"]}
        for name in f["snapshots"]:
            g = f["shell"][name]
            assert g.attrs["time"] == f["snapshots"][name].attrs["time"]
            assert g.attrs["step"] == f["snapshots"][name].attrs["step"]
            out[int(g.attrs["step"])] = {k: g[k][()] for k in ("points", "displacement", "von_mises")}
    return m, out

mesh, snaps = read(f"{work}/s1")
nodes, elements = info["nodes"], info["elements"]
assert mesh["elements"].shape == (elements, 9) and mesh["elements"].dtype == np.int64
assert mesh["elements"].min() == 0 and mesh["elements"].max() == nodes - 1
assert len(np.unique(mesh["elements"])) == nodes
assert mesh["element_bar"].shape == (elements,)
assert set(mesh["element_bar"].tolist()) == set(range(-1, 8))
q = mesh["quadrilaterals"]
assert q.shape == (4 * elements, 4) and mesh["quadrilateral_bar"].shape == (4 * elements,)
assert np.array_equal(mesh["quadrilateral_bar"], np.repeat(mesh["element_bar"], 4))
for e in (0, elements // 2, elements - 1):  # four quarters over the element's 9 nodes
    assert sorted(set(q[4 * e:4 * e + 4].ravel())) == sorted(mesh["elements"][e]), e
assert len(snaps) == 4, sorted(snaps)  # t = 0, 0.04, 0.08, 0.12
top = 0.0
for step, s in snaps.items():
    assert s["points"].shape == (nodes, 2) and s["displacement"].shape == (nodes, 2)
    assert s["von_mises"].shape == (nodes,)
    r = np.hypot(*(s["points"] - centre).T)
    assert r.min() >= R - h - 1e-9 and r.max() <= R + t + 1e-9, (r.min(), r.max())
    assert abs(r.max() - (R + t)) < 1e-9, r.max()  # the outer surface is meshed
    for k in ("displacement", "von_mises"):
        assert np.all(np.isfinite(s[k])), (step, k)
    assert np.all(s["von_mises"] >= 0)
    u = np.hypot(*s["displacement"].T)
    top = max(top, u.max())
    if u.max() > 0:
        assert s["von_mises"].max() > 0
last = snaps[max(snaps)]
u_last = np.hypot(*last["displacement"].T).max()
assert 0 < u_last and abs(u_last - info["last_max_displacement_m"]) <= 1e-9 * u_last, (
    u_last, info["last_max_displacement_m"])
assert 0 < top < 1e-5, top  # steel under a few kilograms of charge: below a micrometre
# The mesh turns with the drum: the same drum-frame node, turned from one snapshot to the next.
first = snaps[min(snaps)]["points"]
assert not np.array_equal(first, last["points"])
assert np.allclose(np.hypot(*first.T), np.hypot(*last["points"].T), rtol=0, atol=1e-12)

for other in ("s2", "s3", "srs"):
    m2, s2 = read(f"{work}/{other}")
    for k in mesh:
        assert np.array_equal(mesh[k], m2[k]), (other, k)
    common = set(snaps) & set(s2)
    assert len(common) == 4, (other, sorted(s2))
    for step in common:
        for k in snaps[step]:
            assert np.array_equal(snaps[step][k], s2[step][k]), (other, step, k)

# snapshots.xmf: every snapshot has a shell grid whose DataItems are datasets of snapshots.h5
# with the dimensions stated.
for d in ("s1", "srs"):
    root = ET.parse(f"{work}/{d}/snapshots.xmf").getroot()
    with h5py.File(f"{work}/{d}/snapshots.h5", "r") as f:
        grids = [g for g in root.iter("Grid") if g.get("Name") == "shell"]
        assert len(grids) == len(f["snapshots"]), (d, len(grids))
        for g in grids:
            topo = g.find("Topology")
            assert topo.get("TopologyType") == "Quadrilateral"
            assert int(topo.get("NumberOfElements")) == 4 * elements
            names = {a.get("Name"): a for a in g.findall("Attribute")}
            assert set(names) == {"displacement", "von_mises", "bar"}, names
            assert names["displacement"].get("AttributeType") == "Vector"
            assert names["von_mises"].get("Center") == "Node"
            assert names["bar"].get("Center") == "Cell"
            for item in g.iter("DataItem"):
                file, path = item.text.strip().split(":")
                assert file == "snapshots.h5", file
                dims = tuple(int(x) for x in item.get("Dimensions").split())
                assert path in f, path
                assert f[path].shape == dims, (path, f[path].shape, dims)
            geometry = g.find("Geometry/DataItem").text.strip().split(":")[1]
            assert geometry.startswith("/shell/") and geometry.endswith("/points"), geometry
print(f"{nodes} nodes, {elements} elements, {len(snaps)} snapshots; largest displacement {top:.3g} m")
PY
for other in s3 srs; do
  check "shell: h5compare.py s1 = $other (the shell too)" "$py" "$source_dir/post/h5compare.py" \
    --by-step --allow-added "$work/s1/snapshots.h5" "$work/$other/snapshots.h5"
done
check "shell: check_xdmf.py on snapshots.xmf (1 rank, restarted)" \
  bash -c "'$py' '$source_dir/tests/io/check_xdmf.py' '$work/s1/snapshots.xmf' &&
           '$py' '$source_dir/tests/io/check_xdmf.py' '$work/srs/snapshots.xmf'"
check "shell: render_snapshot.py draws the shell" "$py" - "$source_dir/post/render_snapshot.py" \
  "$work/s1" <<'PY'
import json, subprocess, sys
script, d = sys.argv[1:3]
subprocess.run([sys.executable, script, f"{d}/snapshots.h5", "-o", f"{d}/r.png", "--json",
                f"{d}/r.json"], check=True, capture_output=True)
elements = json.load(open(f"{d}/run.json"))["shell"]["elements"]
assert json.load(open(f"{d}/r.json"))[-1]["shell_cells"] == 4 * elements
assert open(f"{d}/r.png", "rb").read(8) == b"\x89PNG\r\n\x1a\n"
PY
check "plot_lifters.py: the shell's figures" "$py" - "$source_dir/post/plot_lifters.py" \
  "$work/s3/lifters.csv" "$work" <<'PY'
import csv, json, subprocess, sys
script, path, work = sys.argv[1:4]
subprocess.run([sys.executable, script, path, "--json", f"{work}/s.json", "-o", f"{work}/s.png"],
               check=True, capture_output=True)
f = json.load(open(f"{work}/s.json"))
rows = list(csv.DictReader(open(path)))
tip = [float(r["tip_deflection_m"]) for r in rows]
assert f["peak_tip_deflection_m"] == max(tip), f
assert f["peak_tip_lifter"] == int(rows[tip.index(max(tip))]["lifter"])
assert f["peak_von_mises_Pa"] == max(float(r["von_mises_max_Pa"]) for r in rows)
assert f["peak_root_stress_Pa"] == max(float(r["root_stress_Pa"]) for r in rows)
assert open(f"{work}/s.png", "rb").read(8) == b"\x89PNG\r\n\x1a\n"
PY

finish
