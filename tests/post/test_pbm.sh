#!/bin/bash
# post/pbm.py on a short real grinding run: the population-balance tables it promises, its S, b,
# d, feed and collision columns recomputed here from breakages.csv, fragments.csv, product.csv,
# series.csv and collisions.csv, its forward model against the DEM's product within the stated
# tolerance, and exit 1 naming the break when a fragments.csv row is removed (and on a broken
# mass balance).
#
#   tests/post/test_pbm.sh [DEM2D [SOURCE_DIR]]
#
# DEM2D defaults to SOURCE_DIR/build/src/dem2d, SOURCE_DIR to this script's repository. Uses
# /usr/bin/python3 (numpy, matplotlib, h5py). Everything is written in a temporary folder that
# is removed at the end. About 15-30 s on two busy cores (the run is one rank, about 6 s of CPU).
set -u

source_dir=${2:-$(cd "$(dirname "$0")/../.." && pwd)}
dem2d=${1:-$source_dir/build/src/dem2d}
py=/usr/bin/python3
post=$source_dir/post
deck=$source_dir/inputs/grinding_grate.in
work=$(mktemp -d "${TMPDIR:-/tmp}/dem2d_pbm.XXXXXX")
trap 'rm -rf "$work"' EXIT
export MPLBACKEND=Agg

source "${BASH_SOURCE[0]%/*}/checks.sh"

# --- A short run: 4 s of the grate mill, breakage from 1.5 s, spectra on -------------------------
# f_mat = 0.5 (ten times the deck's) so that some 90 breaks happen in 2.5 s; breakage starts at
# 1.5 s, once the charge is lifted, so that the default window (breakage.start to the end) has
# roughly steady rates. The spectra's size classes are the PBM's (0.14 m / sqrt(2)^k: the
# largest ore diameter of the deck is 0.14 m), so the collision columns map exactly.
run=$work/run
start=$SECONDS
check "dem2d: a 4 s grinding_grate run with the collision spectra" \
  "$dem2d" "$deck" --output "$run" --quiet --set run.duration=4 --set breakage.f_mat=0.5 \
  --set breakage.start=1.5 --set output.collision_spectra=true \
  --set output.size_class_min=0.004375 --set output.size_class_ratio=1.4142135623730951
if [ ! -s "$run/collisions.csv" ] || [ ! -s "$run/fragments.csv" ]; then
  echo "no collisions.csv or fragments.csv: nothing to post-process"
  echo "$passed passed, $((failed + 1)) failed"
  exit 1
fi
echo "dem2d run: $((SECONDS - start)) s"

# --- pbm.py: exit 0, its summary, its files -------------------------------------------------------
out=$work/pbm
if "$py" "$post/pbm.py" "$run" -o "$out/pbm.csv" --plot "$out/pbm.png" >"$work/pbm.log" 2>&1
then pass "pbm.py exits 0"; else
  fail "pbm.py exits 0"
  sed -n '1,30p' "$work/pbm.log"
fi
grep '^summary:' "$work/pbm.log"
if grep -q '^summary: .*: consistent$' "$work/pbm.log"; then pass "pbm.py: summary says consistent"
else fail "pbm.py: no 'summary: ... consistent' line"; fi

check "pbm.csv, pbm_breakage.csv, pbm_forward.csv have the promised columns" "$py" - "$out" <<'EOF'
import csv, sys
out = sys.argv[1]
want = {
    "pbm.csv": ["i", "d_lo", "d_hi", "held_kg", "S_per_s", "d_per_s", "feed_kg_s",
                "specific_collision_power_W_kg", "collisions", "mean_collision_energy_J",
                "held_run_kg", "broken_kg", "broken_net_kg", "discharged_kg", "fed_kg",
                "held_start_kg", "held_end_kg", "t0", "t1"],
    "pbm_breakage.csv": ["i", "j", "b_ij", "d_lo_i", "d_hi_i", "d_lo_j", "d_hi_j"],
    "pbm_forward.csv": ["i", "d_lo", "d_hi", "product_dem_kg", "product_pbm_kg",
                        "product_dem_passing", "product_pbm_passing", "mill_dem_kg",
                        "mill_pbm_kg", "mill_dem_passing", "mill_pbm_passing"],
}
for name, cols in want.items():
    with open(f"{out}/{name}") as f:
        r = csv.DictReader(f)
        rows = list(r)
        assert r.fieldnames == cols, (name, r.fieldnames)
        assert rows, f"{name}: no rows"
        for row in rows:
            for c in cols:
                float(row[c])  # every cell a number (inf and nan included)
n = len(list(csv.DictReader(open(f"{out}/pbm.csv"))))
assert n >= 5, n  # 0.14 m down to 0.02 m in sqrt(2) steps, and the fines
nb = len(list(csv.DictReader(open(f"{out}/pbm_breakage.csv"))))
assert nb == n * (n - 1) // 2, (n, nb)
print(f"{n} classes")
EOF
check "pbm.png is a real picture" png_ok "$out/pbm.png"

# --- S, b, d, feed and the collisions recomputed here ------------------------------------------
# From the edges and held_kg of pbm.csv (the snapshots' time average is pbm.py's), everything
# else straight from the run's files: S_j = (parents of class j broken in (t0, t1] - their
# progeny that stays in class j) / (held_j (t1 - t0)); b_ij = progeny of class j in class i / that
# net mass, the fines in the last class; d_i from product.csv; the feed against series.csv; the
# collision energy of each class from collisions.csv (the classes coincide).
check "S, b, d, feed and collision energy recomputed from the run's files agree with pbm.csv" \
  "$py" - "$run" "$out" <<'EOF'
import csv, math, sys
run, out = sys.argv[1], sys.argv[2]
rd = lambda p: list(csv.DictReader(open(p)))
rows = rd(f"{out}/pbm.csv")
n = len(rows)
lo = [float(r["d_lo"]) for r in rows]
hi = [float(r["d_hi"]) for r in rows]
held = [float(r["held_kg"]) for r in rows]
t0, t1 = float(rows[0]["t0"]), float(rows[0]["t1"])
T = t1 - t0

def cls(d):
    for i in range(n):
        if lo[i] <= d < hi[i] or (i == 0 and d == hi[0]):
            return i
    raise AssertionError(f"diameter {d} in no class")

frags = {}
for f in rd(f"{run}/fragments.csv"):
    frags.setdefault(f["parent_id"], []).append(f)
B = [0.0] * n
P = [[0.0] * n for _ in range(n)]
for b in rd(f"{run}/breakages.csv"):
    if not t0 < float(b["time"]) <= t1:
        continue
    j = cls(2 * float(b["radius"]))
    B[j] += float(b["mass"])
    for f in frags[b["parent_id"]]:
        P[cls(2 * float(f["radius"]))][j] += float(f["mass"])
    P[n - 1][j] += float(b["fines_mass"])
D = [0.0] * n
for p in rd(f"{run}/product.csv"):
    if t0 < float(p["time"]) <= t1:
        D[cls(2 * float(p["radius"]))] += float(p["mass"])
close = lambda a, b, tol=1e-9: math.isclose(a, b, rel_tol=tol, abs_tol=1e-12)
broke = 0
for j in range(n - 1):
    net = B[j] - P[j][j]
    S = net / (held[j] * T) if held[j] > 0 else (math.inf if net > 0 else 0.0)
    assert close(S, float(rows[j]["S_per_s"])), (j, S, rows[j]["S_per_s"])
    d = D[j] / (held[j] * T) if held[j] > 0 else (math.inf if D[j] > 0 else 0.0)
    assert close(d, float(rows[j]["d_per_s"])), (j, d, rows[j]["d_per_s"])
    broke += net > 0
assert broke >= 2, f"only {broke} classes broke: too short a test run"
bs = {(int(r["i"]), int(r["j"])): float(r["b_ij"]) for r in rd(f"{out}/pbm_breakage.csv")}
for j in range(n - 1):
    net = B[j] - P[j][j]
    for i in range(j + 1, n):
        want = P[i][j] / net if net > 0 else 0.0
        assert close(bs[(i, j)], want), (i, j, bs[(i, j)], want)
# The feed: the window's fed mass against series.csv's fed_mass at t0 and t1.
series = {float(r["time"]): float(r["fed_mass"]) for r in rd(f"{run}/series.csv")}
fed = sum(float(r["feed_kg_s"]) for r in rows) * T
assert close(fed, series[t1] - series[t0], 1e-9), (fed, series[t1] - series[t0])
# The collisions over [0, t1] (the default window ends at the end of the run).
E, N = [0.0] * n, [0] * n
cells = {}
for r in rd(f"{run}/collisions.csv"):
    if "ore" in r["type"].split("-"):
        a, b = float(r["size_min"]), float(r["size_max"])
        k = cls(math.sqrt(a * b) if a > 0 and math.isfinite(b) else (a if a > 0 else 0.0))
        cells[(r["type"], a, b)] = (k, float(r["energy"]))
        N[k] += int(r["count"])
for k, e in cells.values():
    E[k] += e
for i in range(n):
    hr, pw = float(rows[i]["held_run_kg"]), float(rows[i]["specific_collision_power_W_kg"])
    assert float(rows[i]["collisions"]) == N[i], (i, rows[i]["collisions"], N[i])
    if hr > 0:
        assert close(pw * hr * t1, E[i], 1e-9), (i, pw * hr * t1, E[i])
print(f"window {t0:.4g}-{t1:.4g} s: S of class 0 {float(rows[0]['S_per_s']):.4g} 1/s; "
      f"{broke} classes broke; {sum(N)} ore collisions")
EOF

# --- The forward model against the DEM ----------------------------------------------------------
# Tolerance (pbm.py's): the product's cumulative % passing within 5 % in every class and its mass
# within 10 %. The DEM's product per class is recomputed here from product.csv and the fines.
check "forward model: the product within 5 % passing and 10 % in mass of the DEM's" \
  "$py" - "$run" "$out" <<'EOF'
import csv, math, sys
run, out = sys.argv[1], sys.argv[2]
rd = lambda p: list(csv.DictReader(open(p)))
rows = rd(f"{out}/pbm_forward.csv")
n = len(rows)
lo = [float(r["d_lo"]) for r in rows]
hi = [float(r["d_hi"]) for r in rows]
t0, t1 = float(rd(f"{out}/pbm.csv")[0]["t0"]), float(rd(f"{out}/pbm.csv")[0]["t1"])
dem = [0.0] * n
for p in rd(f"{run}/product.csv"):
    if t0 < float(p["time"]) <= t1:
        d = 2 * float(p["radius"])
        k = [i for i in range(n) if lo[i] <= d < hi[i] or (i == 0 and d == hi[0])][0]
        dem[k] += float(p["mass"])
for b in rd(f"{run}/breakages.csv"):
    if t0 < float(b["time"]) <= t1:
        dem[n - 1] += float(b["fines_mass"])
for i in range(n):
    assert math.isclose(dem[i], float(rows[i]["product_dem_kg"]), rel_tol=1e-9, abs_tol=1e-9), i
dp = max(abs(float(r["product_dem_passing"]) - float(r["product_pbm_passing"])) for r in rows)
total_dem = sum(float(r["product_dem_kg"]) for r in rows)
total_pbm = sum(float(r["product_pbm_kg"]) for r in rows)
rel = 100 * (total_pbm - total_dem) / total_dem
assert total_dem > 5.0, f"only {total_dem} kg of product: too short a test run"
assert dp <= 5.0, f"product passing differs by {dp:.3g} %"
assert abs(rel) <= 10.0, f"product mass differs by {rel:.3g} %"
series = {float(r["time"]): float(r["ore_mass"]) for r in rd(f"{run}/series.csv")}
mill = sum(float(r["mill_dem_kg"]) for r in rows)
assert math.isclose(mill, series[t1], rel_tol=1e-9), (mill, series[t1])
print(f"product DEM {total_dem:.4g} kg, PBM {total_pbm:.4g} kg ({rel:+.2f} %), "
      f"max passing difference {dp:.2f} %")
EOF

# --- Options: coarser classes and a window -------------------------------------------------------
if "$py" "$post/pbm.py" "$run" --classes 2 --window 2 4 -o "$work/coarse/pbm.csv" \
  >"$work/coarse.log" 2>&1 && grep -q ' 4 classes (ratio 2 ' "$work/coarse.log" &&
  grep -q 'window 2-4 s' "$work/coarse.log"; then
  pass "pbm.py --classes 2 --window 2 4: 4 classes over 2-4 s"
else
  fail "pbm.py --classes 2 --window 2 4"
  sed -n '1,20p' "$work/coarse.log"
fi

# --- Broken inputs: exit 1 with a message naming what broke ---------------------------------------
# A fragments.csv row removed: the break it belongs to is named (its parent id and time).
cp -r "$run" "$work/no_fragment"
row=$(sed -n 4p "$run/fragments.csv")
parent=$(cut -d, -f2 <<<"$row")
sed -i 4d "$work/no_fragment/fragments.csv"
"$py" "$post/pbm.py" "$work/no_fragment" -o "$work/no_fragment/pbm.csv" >"$work/broken.log" 2>&1
rc=$?
if [ "$rc" -eq 1 ] && grep -q "error: the break of particle $parent at t = " "$work/broken.log"
then pass "a fragments.csv row removed: exit 1 naming the break of particle $parent"
else
  fail "a fragments.csv row removed: exit $rc, expected 1 naming the break of particle $parent"
  sed -n '1,10p' "$work/broken.log"
fi
# A product.csv row removed inside the window: the window's mass balance fails.
cp -r "$run" "$work/no_product"
sed -i '$d' "$work/no_product/product.csv"
"$py" "$post/pbm.py" "$work/no_product" -o "$work/no_product/pbm.csv" >"$work/broken2.log" 2>&1
rc=$?
if [ "$rc" -eq 1 ] && grep -q "error: window mass balance" "$work/broken2.log"
then pass "a product.csv row removed: exit 1 on the window's mass balance"
else
  fail "a product.csv row removed: exit $rc, expected 1 on the window's mass balance"
  sed -n '1,10p' "$work/broken2.log"
fi

echo "pbm tests: $((SECONDS - start)) s"
finish
