#!/bin/bash
# The mill post-processing scripts on short real runs: post/report.py, post/plot_series.py and
# post/sweep.py exit 0, write every file they promise as a real picture (a PNG of some size with
# more than a few colours), and what they print agrees with series.csv read independently here
# (mean power, regime, critical speed; the sweep's speeds and powers); post/plot_grinding.py on
# a short grinding run, its figures against product.csv, breakages.csv, series.csv and run.json.
#
#   tests/post/test_post.sh [DEM2D [SOURCE_DIR]]
#
# DEM2D defaults to SOURCE_DIR/build/src/dem2d, SOURCE_DIR to this script's repository. Uses
# /usr/bin/python3 (numpy, matplotlib, h5py). Everything is written in a temporary folder that
# is removed at the end. About 40-60 s on two busy cores.
set -u

source_dir=${2:-$(cd "$(dirname "$0")/../.." && pwd)}
dem2d=${1:-$source_dir/build/src/dem2d}
py=/usr/bin/python3
post=$source_dir/post
deck=$source_dir/inputs/waterfall.in
work=$(mktemp -d "${TMPDIR:-/tmp}/dem2d_post.XXXXXX")
trap 'rm -rf "$work"' EXIT
export MPLBACKEND=Agg

source "${BASH_SOURCE[0]%/*}/checks.sh"

# --- Snapshot order: by index, not by name ------------------------------------------------------
# /snapshots names a snapshot by its index in at least six digits, so past 999 999 the names sort
# wrongly as text ("1000000" < "999999"). On a made-up snapshots.h5 whose names cross a million,
# every script that lists snapshots takes them in index (= time) order.
check "snapshots past 999999 in index order (millplot, render_snapshot, plot_grinding, h5compare)" \
  "$py" - "$post" "$work/order.h5" <<'EOF'
import subprocess, sys
import h5py
import numpy as np
post, path = sys.argv[1], sys.argv[2]
sys.path.insert(0, post)
names = ["000007", "999998", "999999", "1000000", "1000001"]  # in index and time order
with h5py.File(path, "w") as f:
    f["materials/name"] = [b"steel"]
    for k, name in enumerate(names):
        g = f.create_group(f"snapshots/{name}")
        g.attrs["time"], g.attrs["step"] = float(k), np.int64(10 * k)
        n = k + 1
        g["id"] = np.arange(n, dtype=np.int64)
        g["position"], g["velocity"] = np.zeros((n, 2)), np.zeros((n, 2))
        g["radius"], g["damage"] = np.full(n, 0.1), np.zeros(n)
        g["material"] = np.zeros(n, dtype=np.int32)
import h5compare, millplot, plot_grinding, render_snapshot  # noqa: E402
with h5py.File(path, "r") as f:
    assert millplot.list_snapshots(f) == names, millplot.list_snapshots(f)
    assert render_snapshot.snapshot_names(f) == names, render_snapshot.snapshot_names(f)
    pairs = h5compare.paired_snapshots(f, f, False, h5compare.Report(0))
    assert [a for a, _ in pairs] == names, pairs
times = [t for t, _, _ in plot_grinding.ore_in_mill(path, 0, count=len(names))]
assert times == [float(k) for k in range(len(names))], times
out = subprocess.run([sys.executable, f"{post}/render_snapshot.py", path, "--list"],
                     capture_output=True, text=True, check=True).stdout
listed = [line.split()[1] for line in out.splitlines() if line.strip()]
assert listed == names, listed
print("order:", " ".join(listed))
EOF

# --- A short run: 0.8 s of the waterfall deck, snapshots every 0.1 s, spectra on ------------------
run=$work/run
start=$SECONDS
check "dem2d: a 0.8 s waterfall run" \
  "$dem2d" "$deck" --output "$run" --overwrite --quiet --set run.duration=0.8 \
  --set drum.ramp_time=0.1 --set output.snapshot_interval=0.1 \
  --set output.collision_spectra=true --set output.analysis_window=0.2
if [ ! -s "$run/series.csv" ]; then
  echo "no series.csv: nothing to post-process"
  echo "$passed passed, $((failed + 1)) failed"
  exit 1
fi

# --- The sweep runs in the background while the report is drawn ----------------------------------
sweep=$work/sweep
"$py" "$post/sweep.py" "$deck" --fractions 0.4,0.9 --duration 0.5 --jobs 2 -o "$sweep" \
  --dem2d "$dem2d" --set drum.ramp_time=0.1 --set output.snapshot_interval=0.25 \
  >"$work/sweep.log" 2>&1 &
sweep_pid=$!

# --- power_estimate: batch means over whole drum turns ------------------------------------------
# A made-up series: 10 s at 1 ms rows, the drum turning in 1 s (speed 2 pi rad/s), the power in
# the last half constant within each turn at 10, 12, 11, 13, 9 kW: mean 11 kW, standard error
# std(ddof=1) / sqrt(5) = 0.7071 kW; a speed that leaves fewer than 3 turns: 8 equal parts.
check "power_estimate: batch means over drum turns" "$py" - "$post" <<'EOF'
import sys
import numpy as np
sys.path.insert(0, sys.argv[1])
import millplot
t = np.round(np.arange(0, 10001) * 1e-3, 9)
p = np.where(t < 5, 20e3, np.choose(np.clip(((t - 5 - 1e-9) // 1).astype(int), 0, 4),
                                    [10e3, 12e3, 11e3, 13e3, 9e3]))
work = np.concatenate([[0.0], np.cumsum(p[1:] * 1e-3)])  # the power of row k over (t_k-1, t_k]
s = {"time": t, "drum_work": work, "drum_power": p}
mean, se, n, kind = millplot.power_estimate(s, 2 * np.pi)
assert (n, kind) == (5, "drum turns"), (n, kind)
expect = np.std([10, 12, 11, 13, 9], ddof=1) / np.sqrt(5) * 1e3
assert abs(mean - 11e3) < 1e-6 and abs(se - expect) < 1e-6, (mean, se, expect)
mean, se, n, kind = millplot.power_estimate(s, 2 * np.pi / 2.0)
assert (n, kind) == (8, "equal parts"), (n, kind)
print(f"mean {mean / 1e3:.4g} kW +/- {se / 1e3:.4g} kW over {n} {kind}")
EOF

# --- report.py ----------------------------------------------------------------------------------
report=$work/report
check "report.py exits 0" "$py" "$post/report.py" "$run" -o "$report" --max-frames 8 \
  --snapshots 2
expected=(energies.png power.png charge_shape.png charge_000.400s.png charge_000.800s.png
          report.md index.html)
if [ -f "$run/collisions.csv" ]; then expected+=(collisions.png); fi
if command -v ffmpeg >/dev/null; then expected+=(charge.mp4); else expected+=(charge.gif); fi
missing=""
for f in "${expected[@]}"; do [ -s "$report/$f" ] || missing+=" $f"; done
if [ -z "$missing" ]; then pass "report.py wrote ${expected[*]}"; else
  fail "report.py did not write:$missing"
fi
if [ -f "$run/collisions.csv" ]; then
  echo "note: dem2d wrote collisions.csv; report.py drew it"
else
  echo "note: dem2d wrote no collisions.csv: collisions.png is checked on a made-up one below"
fi

# The index's numbers against series.csv and run.json read here.
check "report.md: critical speed, fraction, regime and mean power agree with series.csv" \
  "$py" - "$run" "$report/report.md" <<'EOF'
import csv, json, math, re, sys
run, md = sys.argv[1], open(sys.argv[2], encoding="utf-8").read()
rows = list(csv.DictReader(open(f"{run}/series.csv", encoding="ascii")))
t = [float(r["time"]) for r in rows]
half = [r for r in rows if float(r["time"]) >= t[-1] / 2]
work = float(half[-1]["drum_work"]) - float(half[0]["drum_work"])
power = work / (float(half[-1]["time"]) - float(half[0]["time"]))
regimes = [r["regime"] for r in half if r["regime"] != "-"]
assert regimes, "the run's regime column is '-' over the last half"
regime = max(sorted(set(regimes)), key=regimes.count)
assert re.search(rf"\| regime \| {regime} ", md), f"report.md lacks '| regime | {regime}'"
m = re.search(r"\| mean drive power, last half of the run \| ([0-9.e+-]+) kW", md)
assert m and math.isclose(float(m.group(1)) * 1e3, power, rel_tol=1e-3), (m and m.group(1), power)
assert power > 0, power
deck = json.load(open(f"{run}/run.json"))["deck"]
wc = math.sqrt(9.81 / deck["drum"]["radius"])
assert f"{wc:.4g} rad/s" in md, f"critical speed {wc:.4g} rad/s not in report.md"
assert f"| fraction of critical speed | {deck['drum']['speed'] / wc:.3f} |" in md
assert "| slice thickness (2D power is for this slice) | 0.2 m" in md
assert "kW/m" in md and "charge_000.800s.png" in md and "energies.png" in md
# One power figure with its standard error by batch means, and no second mean beside it.
row = re.search(r"\| mean drive power, last half of the run \| [0-9.e+-]+ kW ± ([0-9.e+-]+) kW "
                r"\(standard error of ([0-9]+) batch means over (drum turns|equal parts)\)", md)
assert row and float(row.group(1)) > 0 and int(row.group(2)) >= 2, row
assert "power_avg at the end" not in md
print(f"regime {regime}, mean power {power / 1e3:.4g} kW")
EOF
# shown FILE...: index.html shows each picture.
shown() {
  local f
  for f in "$@"; do
    grep -q "src='$f'" "$report/index.html" || { echo "not shown: $f"; return 1; }
  done
}
check "index.html shows every picture" shown energies.png power.png charge_shape.png \
  charge_000.800s.png
if command -v ffmpeg >/dev/null && command -v ffprobe >/dev/null; then
  frames=$(ffprobe -v error -count_frames -select_streams v:0 -show_entries \
    stream=nb_read_frames -of csv=p=0 "$report/charge.mp4" 2>/dev/null)
  if [ "$frames" = 8 ]; then pass "charge.mp4 has --max-frames 8 frames"; else
    fail "charge.mp4 has '$frames' frames, expected 8"
  fi
else  # without ffmpeg the animation is a GIF of the same frames
  check "charge.gif has --max-frames 8 frames" "$py" -c "
from PIL import Image
im = Image.open('$report/charge.gif')
assert im.n_frames == 8, im.n_frames"
fi

# The collision spectra on a made-up collisions.csv of the documented layout (two types, one
# size class, log bins from 0 J, an open last bin), in a copy of the run folder.
fake=$work/fake
mkdir -p "$fake"
cp "$run/series.csv" "$run/run.json" "$fake/"
"$py" - "$fake/collisions.csv" <<'EOF'
import sys
edges = [0.0] + [1e-12 * 10 ** (k / 10) for k in range(181)] + [float("inf")]
with open(sys.argv[1], "w", encoding="ascii") as f:
    f.write("type,size_min,size_max,energy_min,energy_max,count,energy\n")
    for kind, centre in [("ball-ball", 100), ("ball-shell", 120)]:
        for size_min, size_max in [(0.128, 0.256), (0.256, float("inf"))]:
            for i in range(len(edges) - 1):
                count = max(0, 50 - abs(i - centre)) if size_min < 0.2 else 0
                lo, hi = edges[i], edges[i + 1]
                f.write(f"{kind},{size_min},{size_max},{lo!r},{hi!r},{count},12.5\n")
EOF
check "report.py without snapshots, with a made-up collisions.csv" \
  "$py" "$post/report.py" "$fake" --no-animation
charges=("$fake"/report/charge_0*.png)
if grep -q "collisions.png" "$fake/report/report.md" && [ ! -e "${charges[0]}" ]; then
  pass "report.md lists collisions.png; no charge pictures without snapshots.h5"
else fail "report on the made-up folder"; fi

# --- plot_series.py -----------------------------------------------------------------------------
if out=$("$py" "$post/plot_series.py" "$run/series.csv" -o "$work/series.png" 2>&1) &&
  grep -q "mean power over the last half" <<<"$out"; then
  pass "plot_series.py SERIES -o PNG exits 0 and prints the mean power"
else fail "plot_series.py: $out"; fi

# --- Refusals -------------------------------------------------------------------------------------
if "$py" "$post/report.py" "$work/nowhere" >/dev/null 2>&1; then
  fail "report.py on a missing folder exits 0"
else pass "report.py on a missing folder exits non-zero"; fi
if "$py" "$post/sweep.py" "$deck" --fractions 0.5,-1 -o "$work/bad" >/dev/null 2>&1; then
  fail "sweep.py --fractions 0.5,-1 exits 0"
else pass "sweep.py refuses a negative fraction"; fi

# --- sweep.py -------------------------------------------------------------------------------------
if wait "$sweep_pid"; then pass "sweep.py (2 fractions, 0.5 s) exits 0"; else
  fail "sweep.py exited non-zero"
  sed -n '1,20p' "$work/sweep.log"
fi
check "sweep.csv: 2 rows, speeds f * sqrt(g/R), finite positive power rising with speed" \
  "$py" - "$sweep/sweep.csv" <<'EOF'
import csv, math, sys
rows = list(csv.DictReader(open(sys.argv[1], encoding="ascii")))
assert len(rows) == 2, rows
assert [float(r["fraction"]) for r in rows] == [0.4, 0.9], rows
wc = math.sqrt(9.81 / 2.5)
for r in rows:
    f = float(r["fraction"])
    assert math.isclose(float(r["speed_rad_s"]), f * wc, rel_tol=1e-5), r
    assert math.isclose(float(r["speed_rpm"]), f * wc * 30 / math.pi, rel_tol=1e-5), r
    assert r["regime"] in {"slumping", "rolling", "cascading", "cataracting", "centrifuging"}, r
low, high = (float(r["power_W"]) for r in rows)
assert math.isfinite(high) and high > 0, high
assert high > low > 0, (low, high)
assert math.isclose(float(rows[1]["power_per_metre_W"]), high / 0.2, rel_tol=1e-4), rows[1]
print(f"power {low / 1e3:.3g} kW at 0.4, {high / 1e3:.3g} kW at 0.9 of critical")
EOF
check "every PNG is a real picture (report, made-up spectra, plot_series, sweep)" \
  png_ok "$report"/*.png "$fake/report/collisions.png" "$work/series.png" \
  "$sweep/power_vs_speed.png"
if grep -qE "^ +0\.9 .*kW/m|^ +0\.9 " "$work/sweep.log"; then pass "sweep.py printed its table"
else fail "sweep.py printed no table row for 0.9"; sed -n '1,20p' "$work/sweep.log"; fi

# --- plot_grinding.py on a real grinding run ------------------------------------------------------
# The grate-discharge deck for 2 s with a weak ore that starts breaking at 0.2 s: breakage,
# fines and discharge all happen (about 10 s on two busy cores at np 2). What plot_grinding.py
# prints and writes as JSON is checked against product.csv, breakages.csv, series.csv and
# run.json read here.
grind=$work/grind
grind_start=$SECONDS
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
launch=(mpirun -np 2)
if ! command -v mpirun >/dev/null; then
  launch=()
  echo "note: no mpirun on the PATH: the grinding run on one rank"
fi
check "dem2d: a 2 s grate-discharge grinding run (np 2)" \
  "${launch[@]}" "$dem2d" "$source_dir/inputs/grinding_grate.in" --output "$grind" --overwrite \
  --quiet --set run.duration=2.0 --set breakage.f_mat=1.5 --set breakage.start=0.2 \
  --set drum.ramp_time=0.2 --set output.snapshot_interval=0.25
echo "note: the grinding run took $((SECONDS - grind_start)) s"
# plot_grinding.py with the default window and with --window 0.5: its output kept for the checks.
for w in third 0.5; do
  opts=()
  if [ "$w" != third ]; then opts=(--window "$w"); fi
  if "$py" "$post/plot_grinding.py" "$grind" -o "$work/grinding_$w.png" "${opts[@]}" \
    --json "$work/grinding_$w.json" >"$work/grinding_$w.txt" 2>&1; then
    pass "plot_grinding.py OUTDIR ${opts[*]:-(default window)} --json FILE exits 0"
  else
    fail "plot_grinding.py OUTDIR ${opts[*]:-} --json FILE exited non-zero"
    sed -n '1,15p' "$work/grinding_$w.txt"
  fi
done
check "grinding PNGs are real pictures" png_ok "$work/grinding_third.png" "$work/grinding_0.5.png"
# grinding_check WINDOW: the printed lines and the JSON against the run's files read here.
grinding_check() {
  "$py" - "$grind" "$work/grinding_$1.txt" "$work/grinding_$1.json" "$1" <<'EOF'
import csv, json, re, sys
run_dir, printed_path, json_path, window = sys.argv[1:5]
text = open(printed_path, encoding="utf-8").read()
assert "warning" not in text, text
printed = dict(re.findall(r"^(\w+) = (\S+)", text, re.M))
mine = json.load(open(json_path, encoding="utf-8"))
run = json.load(open(f"{run_dir}/run.json", encoding="utf-8"))
g = run["grinding"]


def rows(name):
    return list(csv.DictReader(open(f"{run_dir}/{name}", encoding="ascii")))


def close(a, b, rel=1e-9):
    return abs(a - b) <= rel * max(abs(a), abs(b))


def same(key, value, rel=1e-9):
    """The printed figure (10 digits) and the JSON one both equal `value`."""
    assert key in printed and key in mine, (key, sorted(printed))
    assert close(float(printed[key]), value, max(rel, 1e-9)), (key, printed[key], value)
    assert close(mine[key], value, rel), (key, mine[key], value)


product, breakages, series = rows("product.csv"), rows("breakages.csv"), rows("series.csv")
# The run ground: ore broke, fines went out with the product, particles were discharged.
fines = sum(float(r["fines_mass"]) for r in breakages)
assert len(breakages) > 0 and fines > 0 and len(product) > 0, (len(breakages), fines)
# Breakages: breakages.csv's rows = series.csv's count = run.json's.
assert len(breakages) == int(float(series[-1]["breakages"])) == run["ore"]["breakages"]
same("breakages", len(breakages), 0.0)
# Product: product.csv + the fines = run.json's product mass = series' last discharged_mass.
mass = sum(float(r["mass"]) for r in product) + fines
assert close(mass, g["product_mass_kg"]), (mass, g["product_mass_kg"])
assert close(mass, float(series[-1]["discharged_mass"])), mass
same("product_mass_kg", mass)
# F80, P80, reduction ratio: run.json's, each in the class of sizes.csv where its stream
# crosses 80 % passing.
for key in ("f80_m", "p80_m", "reduction_ratio"):
    same(key, g[key], 0.0)
    assert float(printed[key]) == g[key], (key, printed[key], g[key])
sizes = rows("sizes.csv")
for key, stream in (("f80_m", "fed"), ("p80_m", "product")):
    k = next(i for i, r in enumerate(sizes) if float(r[f"{stream}_passing"]) >= 80.0)
    low = float(sizes[k - 1]["diameter"]) if k else 0.0
    assert low <= g[key] <= float(sizes[k]["diameter"]) * (1 + 1e-6), (key, g[key], low)
# The window: the last third of the run (or --window S); its first row the first at or after
# t_end - S; rates and power from the differences between its first and last rows.
t = [float(r["time"]) for r in series]
span = float(window) if window != "third" else (t[-1] - t[0]) / 3
r0 = next(i for i, x in enumerate(t) if x >= t[-1] - span)
dt = t[-1] - t[r0]


def col(name):
    return [float(r[name]) for r in series]


feed = (col("fed_mass")[-1] - col("fed_mass")[r0]) / dt
discharge = (col("discharged_mass")[-1] - col("discharged_mass")[r0]) / dt
power = (col("drum_work")[-1] - col("drum_work")[r0]) / dt
hold = col("ore_mass")[r0:]
middle = (t[r0] + t[-1]) / 2
first = [m for x, m in zip(t[r0:], hold) if x < middle]
second = [m for x, m in zip(t[r0:], hold) if x >= middle]
change = (sum(second) / len(second) - sum(first) / len(first)) / (sum(first) / len(first))
assert discharge > 0 and feed > 0 and power > 0, (feed, discharge, power)
same("window_feed_rate_kg_s", feed)
same("window_discharge_rate_kg_s", discharge)
same("window_holdup_mean_kg", sum(hold) / len(hold))
same("window_holdup_change", change)
same("window_power_W", power)
same("window_specific_energy_kwh_per_t", power / discharge / 3600)
# Every kWh/t figure is printed with run.json's note beside it.
note = g["specific_energy_note"]
kwh = [line for line in text.splitlines() if "kWh/t" in line]
assert len(kwh) >= 2 and all(note in line for line in kwh), kwh
assert mine["specific_energy_note"] == note
print(f"product {mass:.6g} kg, P80 {g['p80_m']:.4g} m, window {dt:.3g} s: feed {feed:.4g} "
      f"kg/s, discharge {discharge:.4g} kg/s, {power / discharge / 3600:.4g} kWh/t")
EOF
}
check "plot_grinding.py's figures agree with the run's files (the last third of the run)" \
  grinding_check third
check "plot_grinding.py's figures agree with the run's files (--window 0.5)" grinding_check 0.5
# The ore by its name: run.json's [breakage] material found in snapshots.h5's /materials (the
# real run: 'ore' is material 1), else in run.json's material list, else [feed]'s, [sieve]'s;
# series.csv's regime kept as words.
check "plot_grinding.py: the ore by name, the regime as words" "$py" - "$post" "$grind" <<'EOF'
import copy, json, sys
sys.path.insert(0, sys.argv[1])
import plot_grinding
d = sys.argv[2]
run = json.load(open(f"{d}/run.json", encoding="utf-8"))
assert plot_grinding.ore_material(run, f"{d}/snapshots.h5")[:2] == (1, "ore")
swapped = copy.deepcopy(run)
swapped["deck"]["material"].reverse()  # without snapshots: the deck's order
assert plot_grinding.ore_material(swapped, None)[:2] == (0, "ore")
swapped["deck"]["breakage"]["material"] = "steel"  # the breakage material comes first
assert plot_grinding.ore_material(swapped, None)[:2] == (1, "steel")
del swapped["deck"]["breakage"], swapped["deck"]["feed"]  # the sieve's material
assert plot_grinding.ore_material(swapped, None)[:2] == (0, "ore")
del swapped["deck"]["sieve"]
assert plot_grinding.ore_material(swapped, None)[0] is None
s = plot_grinding.read_csv(f"{d}/series.csv")
assert s["regime"].dtype.kind == "U" and s["time"].dtype.kind == "f"
assert "cataracting" in set(s["regime"]), set(s["regime"])
EOF
echo "note: the grinding section took $((SECONDS - grind_start)) s"

echo "post-processing tests: $((SECONDS - start)) s"
finish
