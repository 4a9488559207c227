#!/usr/bin/env bash
# Checkpoints and --restart (docs/output.md): a run stopped at a checkpoint and continued gives
# the uninterrupted run's particles bit for bit, on the same and on other rank counts (1 -> 1,
# 1 -> 2, 3 -> 2), for both integrators and through breakage, feed and sieve; its series.csv and
# ore logs continue the interrupted run's; a deck whose physics differs, a checkpoint at the
# deck's end, a file that is not a checkpoint and --restart with --overwrite are refused (exit 2).
# Usage: restart_tests.sh PATH/TO/dem2d SOURCE_DIR
set -u
dem2d=$1
src=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
# Ranks waiting for each other yield the core instead of spinning (runs of 2 and 3 ranks on the
# 2 cores the suite shares).
export OMPI_MCA_mpi_yield_when_idle=1
py=/usr/bin/python3
# pass, fail and expect_joined, shared with cli_tests.sh.
# shellcheck source=tests/cli/lib.sh
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"

# on NP ARGS...: dem2d on NP ranks (1: no mpirun).
on() {
  local np=$1
  shift
  if [ "$np" -eq 1 ]; then "$dem2d" "$@"; else mpirun -np "$np" --oversubscribe "$dem2d" "$@"; fi
}

# same_particles NAME REF OUT: every snapshot of the reference has its twin (by step) in OUT,
# bit for bit; OUT may hold more (a snapshot where an interrupted run stopped).
same_particles() {
  local out
  if out=$("$py" "$src/post/h5compare.py" "$2/snapshots.h5" "$3/snapshots.h5" --by-step --allow-added 2>&1); then
    pass "$1: $(tail -1 <<<"$out")"
  else
    fail "$1: snapshots differ"; echo "$out" | head -8
  fi
}

# same_series NAME REF OUT: the same rows; the counts, the grinding's totals, the charge's
# counted fractions and angles and the regime exactly; the columns that are sums over ranks
# (energies, torque, masses in the mill, centre of mass) or in contact-list order
# (elastic_energy) to 1e-12 of the column's largest value.
same_series() {
  local out
  if out=$("$py" - "$2/series.csv" "$3/series.csv" <<'EOF' 2>&1
import sys
import numpy as np
a = np.genfromtxt(sys.argv[1], delimiter=",", names=True, dtype=None, encoding="utf-8")
b = np.genfromtxt(sys.argv[2], delimiter=",", names=True, dtype=None, encoding="utf-8")
assert a.dtype.names == b.dtype.names, "columns differ"
assert len(a) == len(b), f"{len(a)} rows vs {len(b)}"
exact = ["time", "step", "particles", "contacts", "breakages", "fragments", "fed_count",
         "discharged_count", "fed_mass", "discharged_mass", "airborne_fraction",
         "corotating_fraction", "toe_angle", "shoulder_angle", "shell_arc"]
for n in a.dtype.names:
    if a[n].dtype.kind in "US":  # the regime
        assert (a[n] == b[n]).all(), f"{n} differs at {int((a[n] != b[n]).sum())} rows"
        continue
    both_nan = np.isnan(a[n]) & np.isnan(b[n])
    d = np.where(both_nan, 0.0, np.abs(a[n] - b[n]))
    if n in exact:
        assert (d == 0).all(), f"{n} differs at {int((d > 0).sum())} rows"
    else:
        scale = np.maximum(np.nanmax(np.abs(a[n])), 1e-300)
        assert d.max() <= 1e-12 * scale, f"{n}: {d.max() / scale:.3g} relative"
print(f"{len(a)} rows agree")
EOF
  ); then pass "$1: $out"; else fail "$1: $out"; fi
}

# --- The waterfall (velocity Verlet): 0.3 s stopped at 0.15 s --------------------------------
wf=("$src/inputs/waterfall.in" --quiet --set run.duration=0.3)
on 1 "${wf[@]}" --output "$tmp/wf_ref"
on 1 "${wf[@]}" --output "$tmp/wf_part1" --set run.duration=0.15
cp -r "$tmp/wf_part1" "$tmp/wf_part1b"
on 1 "${wf[@]}" --output "$tmp/wf_part1" --restart "$tmp/wf_part1/checkpoint.h5"
same_particles "waterfall 1 -> 1 particles" "$tmp/wf_ref" "$tmp/wf_part1"
if cmp -s "$tmp/wf_ref/series.csv" "$tmp/wf_part1/series.csv"; then pass "waterfall 1 -> 1 series.csv byte-identical"
else same_series "waterfall 1 -> 1 series.csv" "$tmp/wf_ref" "$tmp/wf_part1"; fi
on 2 "${wf[@]}" --output "$tmp/wf_part1b" --restart "$tmp/wf_part1b/checkpoint.h5"
same_particles "waterfall 1 -> 2 particles" "$tmp/wf_ref" "$tmp/wf_part1b"
same_series "waterfall 1 -> 2 series.csv" "$tmp/wf_ref" "$tmp/wf_part1b"
on 3 "${wf[@]}" --output "$tmp/wf_part3" --set run.duration=0.15
on 2 "${wf[@]}" --output "$tmp/wf_part3" --restart "$tmp/wf_part3/checkpoint.h5"
same_particles "waterfall 3 -> 2 particles" "$tmp/wf_ref" "$tmp/wf_part3"
same_series "waterfall 3 -> 2 series.csv" "$tmp/wf_ref" "$tmp/wf_part3"
if grep -q '"restarted_from": ".*checkpoint.h5"' "$tmp/wf_part3/run.json" && grep -q '"interrupted": false' "$tmp/wf_part3/run.json"
then pass "run.json names the checkpoint it continued"; else fail "run.json lacks restarted_from"; fi

# Checkpoints on the way (output.checkpoint_interval) change nothing in the run.
on 1 "${wf[@]}" --output "$tmp/wf_every" --set output.checkpoint_interval=0.05
same_particles "checkpoints every 0.05 s change nothing" "$tmp/wf_ref" "$tmp/wf_every"

# Checkpoints by the wall clock (output.checkpoint_minutes, here every 0.3 s of wall time): a
# run killed 2 s into its 10 simulated seconds (4 s or more of wall time) has one from on the way.
"$dem2d" "$src/inputs/waterfall.in" --quiet --set run.duration=10 --set output.checkpoint_minutes=0.005 \
  --output "$tmp/wf_minutes" &
pid=$!
sleep 2
kill -9 "$pid" 2>/dev/null
wait "$pid" 2>/dev/null
t_ck=$("$py" -c "import h5py, sys; print(h5py.File(sys.argv[1], 'r').attrs['time'])" "$tmp/wf_minutes/checkpoint.h5" 2>/dev/null)
if [ -n "$t_ck" ] && "$py" -c "import sys; t = float(sys.argv[1]); sys.exit(not 0 < t < 10)" "$t_ck"; then
  pass "checkpoint_minutes: a checkpoint on the way (t = $t_ck s)"
else fail "checkpoint_minutes: no checkpoint on the way (${t_ck:-none})"; fi

# --- The iterative integrator: the drop deck, 0.1 s stopped at 0.05 s --------------------------
it=("$src/inputs/drop.in" --quiet --set run.integrator=iterative --set run.duration=0.1 --set output.snapshot_interval=0.01)
on 1 "${it[@]}" --output "$tmp/it_ref"
on 2 "${it[@]}" --output "$tmp/it_part" --set run.duration=0.05
on 1 "${it[@]}" --output "$tmp/it_part" --restart "$tmp/it_part/checkpoint.h5"
same_particles "iterative 2 -> 1 particles" "$tmp/it_ref" "$tmp/it_part"
same_series "iterative 2 -> 1 series.csv (passes column included)" "$tmp/it_ref" "$tmp/it_part"

# --- Grinding: breakage, feed and sieve across the restart -------------------------------------
gr=("$src/inputs/grinding.in" --quiet --set run.duration=0.4 --set breakage.start=0.0
    --set breakage.minimum_energy=0.001 --set breakage.strength=20 --set feed.start=0.0
    --set feed.period=0.02 --set sieve.aperture=0.12 --set breakage.minimum_radius=0.06)
on 1 "${gr[@]}" --output "$tmp/gr_ref"
on 1 "${gr[@]}" --output "$tmp/gr_part" --set run.duration=0.25
on 2 "${gr[@]}" --output "$tmp/gr_part" --restart "$tmp/gr_part/checkpoint.h5"
same_particles "grinding 1 -> 2 particles" "$tmp/gr_ref" "$tmp/gr_part"
same_series "grinding 1 -> 2 series.csv (ore columns exact)" "$tmp/gr_ref" "$tmp/gr_part"
for log in breakages.csv fragments.csv product.csv sizes.csv; do
  rows=$(($(wc -l <"$tmp/gr_ref/$log") - 1))
  if cmp -s "$tmp/gr_ref/$log" "$tmp/gr_part/$log"; then pass "grinding 1 -> 2 $log identical ($rows rows)"
  else fail "grinding 1 -> 2 $log differs"; diff "$tmp/gr_ref/$log" "$tmp/gr_part/$log" | head -4; fi
done
after=$(awk -F, 'NR > 1 && $1 > 0.25' "$tmp/gr_ref/breakages.csv" | wc -l)
if [ "$after" -gt 0 ]; then pass "grinding: $after breakages after the restart time"
else fail "grinding: no breakage after the restart time (the test would not see them)"; fi

# --- The size-aware ore: Vogel-Peukert, t10 progeny and fines, the grate, across the restart ----
sa=("$src/inputs/grinding_grate.in" --quiet --set run.duration=0.5 --set breakage.start=0.0
    --set breakage.f_mat=20 --set feed.start=0.0 --set drum.ramp_time=0.1
    --set output.snapshot_interval=0.1)
on 1 "${sa[@]}" --output "$tmp/sa_ref"
on 2 "${sa[@]}" --output "$tmp/sa_part" --set run.duration=0.3
on 3 "${sa[@]}" --output "$tmp/sa_part" --restart "$tmp/sa_part/checkpoint.h5"
same_particles "size-aware ore 2 -> 3 particles" "$tmp/sa_ref" "$tmp/sa_part"
for log in breakages.csv fragments.csv product.csv sizes.csv; do
  rows=$(($(wc -l <"$tmp/sa_ref/$log") - 1))
  if cmp -s "$tmp/sa_ref/$log" "$tmp/sa_part/$log"; then pass "size-aware ore 2 -> 3 $log identical ($rows rows)"
  else fail "size-aware ore 2 -> 3 $log differs"; diff "$tmp/sa_ref/$log" "$tmp/sa_part/$log" | head -4; fi
done
if "$py" - "$tmp/sa_ref" <<'EOF'
import csv, sys
d = sys.argv[1]
b = [r for r in csv.DictReader(open(d + "/breakages.csv")) if float(r["time"]) > 0.3]
p = [r for r in csv.DictReader(open(d + "/product.csv")) if float(r["time"]) > 0.3]
fines = sum(float(r["fines_mass"]) for r in b)
sys.exit(0 if b and p and fines > 0 else 1)
EOF
then pass "size-aware ore: breaks with fines and grate discharge after the restart time"
else fail "size-aware ore: no break with fines or no discharge after the restart time"; fi

# --- Refusals: exit 2, on 1 and 2 ranks alike ---------------------------------------------------
# expect_joined: a message of several lines (the keys that differ) is matched as one.
ck="$tmp/wf_ref/checkpoint.h5"
for np in 1 2; do
  run=("$dem2d")
  [ "$np" -gt 1 ] && run=(mpirun -np "$np" --oversubscribe "$dem2d")
  expect_joined "np$np physics differs: every key listed" 2 \
    "waterfall\.in: error: --restart .*physics differs .*2 keys.* drum\.speed: checkpoint 1\.8, deck 1\.5 +material\[0\]\.restitution: checkpoint 0\.73, deck 0\.5" -- \
    "${run[@]}" "${wf[@]}" --set run.duration=1 --set drum.speed=1.5 --set material.steel.restitution=0.5 --output "$tmp/x$np" --restart "$ck"
  expect_joined "np$np checkpoint at the deck's end" 2 \
    "waterfall\.in: error: --restart .*at or past run\.duration = 0\.3" -- "${run[@]}" "${wf[@]}" --output "$tmp/y$np" --restart "$ck"
  expect_joined "np$np not a checkpoint" 2 "series\.csv: error: cannot restart from this checkpoint: not an HDF5 file" -- \
    "${run[@]}" "${wf[@]}" --set run.duration=1 --output "$tmp/z$np" --restart "$tmp/wf_ref/series.csv"
  expect_joined "np$np snapshots are not a checkpoint" 2 "snapshots\.h5: error: cannot restart from this checkpoint: no attribute format" -- \
    "${run[@]}" "${wf[@]}" --set run.duration=1 --output "$tmp/z$np" --restart "$tmp/wf_ref/snapshots.h5"
  expect_joined "np$np missing checkpoint" 2 "nope\.h5: error: cannot restart from this checkpoint: no such file" -- \
    "${run[@]}" "${wf[@]}" --set run.duration=1 --output "$tmp/z$np" --restart "$tmp/nope.h5"
  expect_joined "np$np --restart with --overwrite" 2 "--restart continues the output" -- \
    "${run[@]}" "${wf[@]}" --set run.duration=1 --output "$tmp/z$np" --restart "$ck" --overwrite
done
# The output keys, run.duration and the title may change: the run continues.
expect_joined "output keys, duration and title may change" 0 "continued from t = 0\.3 s" -- \
  "$dem2d" "$src/inputs/waterfall.in" --set run.duration=0.31 --set title=other \
  --set output.snapshot_interval=0.01 --output "$tmp/wf_ref" --restart "$ck"

if [ "$failures" -ne 0 ]; then
  echo "$failures restart test(s) failed"
  exit 1
fi
echo "all restart tests passed"
