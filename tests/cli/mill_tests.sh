#!/bin/bash
# The mill's variables and analytics through the command line:
#   - --set of one speed key replaces the deck's other one (speed, speed_rpm,
#     critical_fraction), a fill's count gives way to a fill fraction or a bed filling; two
#     alternatives both set on the command line are refused;
#   - fills by bed filling, of each law of sizes and mixed place the same particles on 1 and 3
#     ranks (snapshots bit for bit);
#   - --check prints the critical speeds, the fraction of critical, the bed filling J (and the
#     fill that asked it) and the
#     2D-to-3D slice thickness; run.json's "mill" object holds them with the regime;
#   - the shell profile's toe and shoulder are the same on 1 and 3 ranks, and land where the
#     pictures of a cataracting mill with lifters put them;
#   - the collision spectra (collisions.csv) count the same contacts on 1 and 3 ranks, and a
#     run resumed from a checkpoint on another rank count ends with the same spectra.
#
#   tests/cli/mill_tests.sh DEM2D SOURCE_DIR
set -u
dem2d=$1
src=$2
py=/usr/bin/python3
# shellcheck source=tests/cli/lib.sh
source "$(dirname "$0")/lib.sh"
# Ranks waiting for each other yield the core instead of spinning (the suite runs tests side by
# side on 2 cores).
export OMPI_MCA_mpi_yield_when_idle=1
tmp=$(mktemp -d "${TMPDIR:-/tmp}/dem2d_mill.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
wf=$src/inputs/waterfall.in

# --set in the engineer's variables (waterfall: R = 2.5 m, g = 9.81: critical 1.9809 rad/s).
expect "critical_fraction replaces speed" 0 'drum speed: +1\.3866 rad/s = 0\.700 of critical' -- \
  "$dem2d" --check --set drum.critical_fraction=0.7 "$wf"
expect "speed_rpm replaces speed" 0 'drum speed: +1\.0472 rad/s = 0\.529 of critical' -- \
  "$dem2d" --check --set drum.speed_rpm=10 "$wf"
expect "fill_fraction replaces count" 0 'fill fraction: +0\.30' -- \
  "$dem2d" --check --set fill.0.fill_fraction=0.3 "$wf"
expect "bed_filling replaces count" 0 'bed filling J: +0\.30[0-9] \(the bed with its voids / drum area, packing 0\.84; asked: fill\[0\]\.bed_filling = 0\.3\)$' -- \
  "$dem2d" --check --set fill.0.bed_filling=0.3 "$wf"
expect "fill_fraction asked" 0 'fill fraction: +0\.30[0-9]{2} \(particle cross-sections / drum area; asked: fill\[0\]\.fill_fraction = 0\.3\)$' -- \
  "$dem2d" --check --set fill.0.fill_fraction=0.3 "$wf"
expect "count asks neither" 0 'bed filling J: +0\.457 \(the bed with its voids / drum area, packing 0\.84\)$' -- \
  "$dem2d" --check "$wf"
expect "two speeds on the command line" 2 'give only one of speed, speed_rpm and critical_fraction' -- \
  "$dem2d" --check --set drum.speed_rpm=10 --set drum.critical_fraction=0.7 "$wf"
expect "two speeds on 2 ranks" 2 'give only one of speed, speed_rpm and critical_fraction' -- \
  mpirun -np 2 --oversubscribe "$dem2d" --check --set drum.speed_rpm=10 --set drum.critical_fraction=0.7 "$wf"

# --check's mill numbers: 240 balls of 0.1 m in 2.5 m: phi = 0.384, J = 0.384 / 0.84, T37
# (1 - 0.384)^(-1/4) sqrt(9.81 / 2.5) = 2.2360 rad/s, slice 0.2 m.
expect "check bed filling" 0 'bed filling J: +0\.457' -- "$dem2d" --check "$wf"
expect "check T37" 0 'with fill \(thesis T37\) 2\.2360 rad/s' -- "$dem2d" --check "$wf"
expect "check slice" 0 "2D to 3D: +the slice is 0\\.2 m thick \\(the charge's mass-weighted mean diameter" -- \
  "$dem2d" --check "$wf"

# --check names what sets dt, estimates the wall time from a trial, and says when ore breaks
# while the fill still falls.
gr=$src/inputs/grinding.in
expect "check dt set by the shortest contact" 0 'dt set by: +the shortest contact, ore against a wall of steel$' -- \
  "$dem2d" --check "$gr"
expect "check dt set by a small restitution" 0 'dt set by: .*resolved with 4[0-9]{2} steps for the restitution 0\.100 of ore against ore \(2[01](\.[0-9]+)? times as many as a restitution of 0\.7 or more needs\)' -- \
  "$dem2d" --check --set material.ore.restitution=0.1 "$gr"
expect "check wall time estimate" 0 'wall time estimate: +[0-9.e+]+ s on 1 rank \([0-9.e+]+ particle-steps/s over the first [0-9]+ steps' -- \
  "$dem2d" --check "$wf"
expect "check breakage while the fill falls" 0 'breakage from: +t = 0 s \(breakage\.start\); the fill falls until about 0\.66 s' -- \
  "$dem2d" --check --set breakage.start=0 "$gr"
expect "check breakage after the fill" 0 'breakage from: +t = 1 s \(breakage\.start\)$' -- "$dem2d" --check "$gr"
expect "check the ore's laws" 0 'breakage law: +Vogel-Peukert, f_mat 1 kg/\(J m\), x W_min 0\.05 J m/kg, each body its compliance share; t10 progeny \(A 60 %, b 1 t/kWh\), fines below 0\.02 m$' -- \
  "$dem2d" --check "$src/inputs/grinding_grate.in"
expect "check the discharge" 0 'discharge: +ore narrower than 0\.06 m \(a diameter\) in the grate ring, the last 0\.15 m inside the shell$' -- \
  "$dem2d" --check "$src/inputs/grinding_grate.in"

# An ore deck without a [sieve] says at its start that nothing leaves the mill, and run.json's
# ore object says so.
awk '/^\[sieve\]/ { skip = 1; next } /^\[/ { skip = 0 } !skip' "$gr" > "$tmp/nosieve.in"
expect "ore deck without a sieve: told" 0 'nosieve\.in: note: no \[sieve\]: nothing leaves the mill, product\.csv keeps only its header' -- \
  "$dem2d" "$tmp/nosieve.in" --quiet --set run.duration=0.002 --output "$tmp/nosieve"
expect "ore deck without a sieve: run.json" 0 '^False 0$' -- "$py" -c "
import json
o = json.load(open('$tmp/nosieve/run.json'))['ore']
print(o['sieve'], o['discharged_count'])"

# A [sieve] without `type` is told that its aperture is read as a diameter; one with it is not.
grep -v '^type = "box"' "$gr" > "$tmp/notype.in"
expect "sieve without type: the aperture read as a diameter, told" 0 'notype\.in: note: sieve\.aperture = 0\.08 m is a diameter: ore narrower than it leaves \(a deck that meant a radius gives twice the value\)' -- \
  "$dem2d" "$tmp/notype.in" --quiet --set run.duration=0.002 --output "$tmp/notype"
out=$("$dem2d" "$gr" --quiet --set run.duration=0.002 --output "$tmp/withtype" 2>&1)
grep -q 'is a diameter' <<<"$out" && fail "sieve with type: told all the same" || pass "sieve with type: no note"

# A short run with spectra on 1 and 3 ranks, and one resumed 1 -> 2 from a checkpoint at 0.3 s.
run=(--quiet --set run.duration=0.3 --set output.collision_spectra=true --set output.snapshot_interval=0.1
  --set output.analysis_window=0.2)
"$dem2d" "$wf" "${run[@]}" --output "$tmp/np1" > "$tmp/np1.log" 2>&1 || fail "np1 run: $(cat "$tmp/np1.log")"
mpirun -np 3 --oversubscribe "$dem2d" "$wf" "${run[@]}" --output "$tmp/np3" > "$tmp/np3.log" 2>&1 ||
  fail "np3 run: $(cat "$tmp/np3.log")"
"$dem2d" "$wf" "${run[@]}" --set run.duration=0.15 --output "$tmp/rs" > "$tmp/rs.log" 2>&1 ||
  fail "first half: $(cat "$tmp/rs.log")"
# The spectra cannot be rebinned: a restart with other size classes is refused (and changes
# nothing: the restart below continues the same folder).
expect_joined "restart with other size classes" 2 "waterfall\\.in: error: --restart .*checkpoint\\.h5: the checkpoint's collision spectra have [0-9]+ bins.*size_class_ratio give [0-9]+" -- \
  "$dem2d" "$wf" "${run[@]}" --set output.size_class_ratio=3 --output "$tmp/rs" --restart "$tmp/rs/checkpoint.h5"
mpirun -np 2 --oversubscribe "$dem2d" "$wf" "${run[@]}" --output "$tmp/rs" --restart "$tmp/rs/checkpoint.h5" \
  > "$tmp/rs2.log" 2>&1 || fail "restart: $(cat "$tmp/rs2.log")"

# same_spectra NAME A B: the same rows; counts and bins exactly, the energy sums to 1e-12.
same_spectra() {
  local out
  if out=$("$py" - "$2/collisions.csv" "$3/collisions.csv" 2>&1 <<'EOF'
import csv, sys
a = list(csv.DictReader(open(sys.argv[1])))
b = list(csv.DictReader(open(sys.argv[2])))
assert len(a) == len(b) and len(a) > 10, f"{len(a)} rows vs {len(b)}"
types = set()
for x, y in zip(a, b):
    for k in ("type", "size_min", "size_max", "energy_min", "energy_max", "count"):
        assert x[k] == y[k], f"{k}: {x[k]} vs {y[k]}"
    assert abs(float(x["energy"]) - float(y["energy"])) <= 1e-12 * float(x["energy"]), "energy"
    types.add(x["type"])
assert {"ball-ball", "ball-shell", "ball-lifter"} <= types, f"types {types}"
print(f"{len(a)} rows, {sum(int(x['count']) for x in a)} contacts")
EOF
  ); then pass "$1: $out"; else fail "$1: $out"; fi
}
same_spectra "spectra on 1 and 3 ranks" "$tmp/np1" "$tmp/np3"

# The shell profile's toe, shoulder and arc (series.csv, run.json) are integer sums over ranks:
# the same on 1 and 3 ranks, digit for digit.
if out=$("$py" - "$tmp/np1" "$tmp/np3" 2>&1 <<'EOF'
import csv, json, sys
rows = [list(csv.DictReader(open(f + "/series.csv"))) for f in sys.argv[1:]]
assert len(rows[0]) == len(rows[1]) > 100, [len(r) for r in rows]
for a, b in zip(*rows):
    for k in ("toe_angle", "shoulder_angle", "shell_arc"):
        assert a[k] == b[k], f"t = {a['time']}: {k} {a[k]} vs {b[k]}"
mills = [json.load(open(f + "/run.json"))["mill"] for f in sys.argv[1:]]
for k in ("toe_angle_deg", "shoulder_angle_deg", "shell_arc_deg"):
    assert mills[0][k] == mills[1][k], f"{k}: {mills[0][k]} vs {mills[1][k]}"
print(f"{len(rows[0])} rows, window toe {mills[0]['toe_angle_deg']:.1f}, shoulder "
      f"{mills[0]['shoulder_angle_deg']:.1f}")
EOF
); then pass "shell profile on 1 and 3 ranks: $out"; else fail "shell profile on 1 and 3 ranks: $out"; fi
same_spectra "spectra resumed 1 -> 2" "$tmp/np1" "$tmp/rs"

# run.json's mill object: the numbers of --check and a regime over the window.
if out=$("$py" - "$tmp/np3/run.json" "$src/post" 2>&1 <<'EOF'
import json, math, sys
m = json.load(open(sys.argv[1]))["mill"]
assert abs(m["critical_speed_rad_s"] - math.sqrt(9.81 / 2.5)) < 1e-5, m
assert abs(m["bed_filling"] - 0.384 / 0.84) < 1e-5, m
assert m["slice_thickness_m"] == 0.2, m
assert abs(m["power_per_metre_W"] - m["power_avg_W"] / 0.2) < 1e-6 * m["power_avg_W"], m
assert m["regime"] in ("slumping", "rolling", "cascading", "cascading-cataracting", "cataracting"), m
# The --set options beside the deck's title (the title is the file's).
j = json.load(open(sys.argv[1]))
assert j["overrides"] == ["run.duration=0.3", "output.collision_spectra=true",
                          "output.snapshot_interval=0.1", "output.analysis_window=0.2"], j["overrides"]
sys.path.insert(0, sys.argv[2])
import millplot
title = millplot.run_title(j, "")
assert title == j["deck"]["title"] + " [run.duration=0.3, output.collision_spectra=true, " \
    "output.snapshot_interval=0.1, output.analysis_window=0.2]", title
# No births: the particle-steps are the count times the steps.
assert j["particle_steps"] == j["particles"] * j["steps"] == 240 * j["steps"], j
print(m["regime"], round(m["power_avg_W"]), "W")
EOF
); then pass "run.json mill: $out"; else fail "run.json mill: $out"; fi

# Fills of each law of sizes, mixed and by bed filling: the same particles on 1 and 3 ranks
# (placement draws from the seed alone), snapshots compared bit for bit.
cat > "$tmp/sizes.in" <<'EOF'
title = "sizes"
[run]
duration = 0.0004
[[material]]
name = "steel"
density = 7800.0
youngs_modulus = 2.0e11
[[material]]
name = "ore"
density = 3000.0
youngs_modulus = 5.0e10
[drum]
radius = 0.5
speed = 2.0
material = "steel"
[[fill]]
material = "steel"
bed_filling = 0.15
size_distribution = "normal"
d50 = 0.04
sigma = 0.008
radius_min = 0.014
radius_max = 0.026
[[fill]]
material = "ore"
count = 150
size_distribution = "lognormal"
d50 = 0.02
geometric_sd = 1.5
radius_min = 0.004
radius_max = 0.015
mix = true
[[fill]]
material = "ore"
count = 60
size_distribution = "table"
sizes = [0.01, 0.02]
mass_fractions = [0.4, 0.6]
[output]
snapshot_interval = 0.0002
EOF
"$dem2d" --quiet "$tmp/sizes.in" --output "$tmp/sz1" > "$tmp/sz1.log" 2>&1 || fail "sizes np1: $(cat "$tmp/sz1.log")"
mpirun -np 3 --oversubscribe "$dem2d" --quiet "$tmp/sizes.in" --output "$tmp/sz3" > "$tmp/sz3.log" 2>&1 ||
  fail "sizes np3: $(cat "$tmp/sz3.log")"
expect "sizes and mix: np3 snapshots identical to np1" 0 'bit-identical' -- "$py" "$src/post/h5compare.py" \
  "$tmp/sz1/snapshots.h5" "$tmp/sz3/snapshots.h5"
expect "sizes: --check asks the bed filling" 0 'asked: fill\[0\]\.bed_filling = 0\.15\)$' -- \
  "$dem2d" --check "$tmp/sizes.in"

# The charge shape of a cataracting mill with lifters: 630 balls of 0.1 m (J = 0.3) at 0.75 of
# critical in the waterfall's drum with its 24 lifters. Pictures put the toe at about -38 deg;
# balls ride the lifters past 150 deg (a single moment's covered arc breaks at the gaps between
# lifters: its toe jumps between -30 and +75 deg). The window's profile over 3-5 s: toe -44,
# shoulder 165 (measured); windows ending at 4-6 s give toes from -37.6 to -45.8, and a layer
# half a diameter thick instead of one moves the toe by 5 deg: 10 deg of tolerance.
shape=(--quiet --set fill.0.fill_fraction=0.252 --set fill.0.radius=0.05 --set drum.critical_fraction=0.75
  --set run.duration=5 --set output.analysis_window=2 --set output.snapshot_interval=5)
"$dem2d" "$wf" "${shape[@]}" --output "$tmp/shape" > "$tmp/shape.log" 2>&1 || fail "shape run: $(cat "$tmp/shape.log")"
if out=$("$py" - "$tmp/shape/run.json" 2>&1 <<'EOF'
import json, sys
m = json.load(open(sys.argv[1]))["mill"]
assert abs(m["toe_angle_deg"] + 38.0) <= 10.0, m["toe_angle_deg"]
assert m["shoulder_angle_deg"] > 100.0, m["shoulder_angle_deg"]
assert m["regime"] == "cataracting", m["regime"]
print(f"toe {m['toe_angle_deg']:.1f}, shoulder {m['shoulder_angle_deg']:.1f} deg")
EOF
); then pass "charge shape with lifters: $out"; else fail "charge shape with lifters: $out"; fi

if [ "$failures" -gt 0 ]; then
  echo "$failures mill test(s) failed"
  exit 1
fi
echo "all mill tests passed"
