#!/usr/bin/env bash
# Command-line contract (docs/architecture.md, "Command line and exit status"; README, "Using
# dem2d"): exit codes and messages for good and bad input, on one and on two ranks.
# Usage: cli_tests.sh PATH/TO/dem2d SOURCE_DIR
# The cases run as a few background jobs at once (DEM2D_TEST_JOBS, 3 by default; tests/cli/lib.sh):
# cases that share an output folder or read another case's output are one job, in order. The log
# gives each job's cases in the order the jobs start.
set -u
dem2d=$(realpath "$1")  # absolute: every job runs in a folder of its own
src=$(realpath "$2")
tmp=$(mktemp -d)
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
# The runs share the cores with other jobs: a rank that waits on another yields its core rather
# than spin on it. Open MPI spins unless a run has more ranks than cores; a 2-rank grinding run on
# a busy machine took 86 s spinning, 29 s yielding.
export OMPI_MCA_mpi_yield_when_idle=1
# shellcheck source=tests/cli/lib.sh
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"
trap 'job_stop; rm -rf "$tmp"' EXIT

# make_bad_decks: the decks the option cases read (written once, before any job starts).
make_bad_decks() {
  cp "$src/inputs/drop.in" "$tmp/typo.in"
  sed -i 's/^restitution = 0.73/restituion = 0.73/; s/^density = 7800.0/density = -7800.0/' "$tmp/typo.in"
  printf 'title = "x"\n[run\nduration = 1\n' > "$tmp/syntax.in"
  { cat "$src/inputs/waterfall.in"; printf '\n[[particle]]\nmaterial = "steel"\nradius = 0.1\nposition = [0.0, 3.0]\n'; } > "$tmp/outside.in"
  sed 's/^dt = .*/dt = 0.01/' "$src/inputs/drop.in" > "$tmp/unsafe_dt.in"
  grep -q '^dt = 0.01' "$tmp/unsafe_dt.in" || fail "drop.in has no 'dt =' line to make unsafe"
  cp "$src/inputs/drop.in" "$tmp/model.in"
  sed -i 's/^model = "hertz-mindlin"/model = "hertz"/' "$tmp/model.in"
}

# grinding_ranks: grinding: the ore deck on 1, 2 and 3 ranks, breakages, fragments,
# feed and sieve included: snapshots bit-identical by id, product.csv and breakages.csv
# identical, and the mass balance initial + fed = mill + discharged to round-off at every row.
grinding_ranks() {
  local np
  for np in 1 2 3; do grinding_run "$np"; done
  grinding_alike
}

# grinding_run NP: the ore deck on NP ranks, to $tmp/grNP.
grinding_run() {
  expect "grinding np$1" 0 'done: 1.6 s simulated' -- mpirun -np "$1" --oversubscribe "$dem2d" \
    "$src/inputs/grinding.in" --set run.duration=1.6 --set output.snapshot_interval=0.4 --output "$tmp/gr$1"
}

# same_logs A B: the ore logs and the size distributions of two runs, byte for byte.
same_logs() {
  local f
  for f in breakages.csv fragments.csv product.csv sizes.csv; do cmp -s "$1/$f" "$2/$f" || return 1; done
}

# size_aware_ranks: the size-aware ore (Vogel-Peukert, t10 progeny and fines, the grate) on 1 and
# 3 ranks: snapshots and logs identical; fines made and ore let out through the grate.
size_aware_ranks() {
  local np
  for np in 1 3; do
    expect "size-aware grinding np$np" 0 'done: 0.6 s simulated' -- mpirun -np "$np" --oversubscribe \
      "$dem2d" "$src/inputs/grinding_grate.in" --set run.duration=0.6 --set breakage.start=0.0 \
      --set breakage.f_mat=20 --set drum.ramp_time=0.1 --set output.snapshot_interval=0.2 \
      --output "$tmp/sa$np"
  done
  expect "size-aware grinding np3 snapshots identical to np1" 0 'bit-identical' -- /usr/bin/python3 \
    "$src/post/h5compare.py" "$tmp/sa1/snapshots.h5" "$tmp/sa3/snapshots.h5"
  same_logs "$tmp/sa1" "$tmp/sa3" && pass "size-aware grinding np3 logs identical" ||
    fail "size-aware grinding np3 logs differ"
  expect "size-aware grinding: fines and grate discharge" 0 'ok' -- /usr/bin/python3 -c "
import json
g = json.load(open('$tmp/sa3/run.json'))
o, r = g['ore'], g['grinding']
print('ok' if o['fines_mass_kg'] > 0 and o['discharged_count'] > 0 and r['p80_m'] < 0.06 else 'bad', o, r['p80_m'])"
}

# grinding_alike: the runs on 2 and 3 ranks against the run on 1, and the mass balance.
grinding_alike() {
  local np
  for np in 2 3; do
    expect "grinding np$np snapshots identical to np1" 0 'bit-identical' -- /usr/bin/python3 \
      "$src/post/h5compare.py" "$tmp/gr1/snapshots.h5" "$tmp/gr$np/snapshots.h5"
    same_logs "$tmp/gr1" "$tmp/gr$np" && pass "grinding np$np logs identical" || fail "grinding np$np logs differ"
  done
  expect "grinding breaks, feeds and sieves" 0 'ok' -- /usr/bin/python3 -c "
import csv, sys
rows = list(csv.DictReader(open('$tmp/gr3/series.csv')))
m0 = float(rows[0]['mill_mass']); last = rows[-1]
worst = max(abs(m0 + float(r['fed_mass']) - float(r['mill_mass']) - float(r['discharged_mass'])) for r in rows)
ok = int(last['breakages']) > 20 and int(last['fed_count']) >= 3 and int(last['discharged_count']) > 0 and worst < 1e-11 * m0
print('ok' if ok else 'bad', last['breakages'], last['fed_count'], last['discharged_count'], worst)"
  # run.json counts what the run held: the particles born by breakage and feed, the charge's
  # mass and the product rate as the series has them, the same particle-steps on any rank count.
  expect "grinding run.json counts" 0 'ok' -- /usr/bin/python3 -c "
import csv, json
runs = [json.load(open(f'$tmp/gr{np}/run.json')) for np in (1, 2, 3)]
rows = list(csv.DictReader(open('$tmp/gr1/series.csv')))
first, last, j = rows[0], rows[-1], runs[0]
ps = [r['particle_steps'] for r in runs]
steps, t = j['steps'], float(last['time'])
ore = j['ore']
ok = (j['particles'] == int(last['particles']) > j['particles_at_start'] == int(first['particles'])
      and ps[0] == ps[1] == ps[2] and j['particles_at_start'] * steps < ps[0] < j['particles'] * steps
      and abs(j['particle_steps_per_second'] * j['wall_time_s'] - ps[0]) < 1e-6 * ps[0]
      and abs(j['charge_mass_kg'] - float(last['mill_mass'])) < 1e-9 * j['charge_mass_kg']
      and ore['sieve'] and float(last['discharged_mass']) > 0
      and abs(ore['discharged_mass_kg'] - float(last['discharged_mass'])) < 1e-9 * ore['discharged_mass_kg']
      and abs(ore['product_rate_kg_s'] - ore['discharged_mass_kg'] / t) < 1e-9 * ore['product_rate_kg_s']
      and abs(ore['product_rate_t_h'] - 3.6 * ore['product_rate_kg_s']) < 1e-9 * ore['product_rate_t_h'])
print('ok' if ok else 'bad', j['particles_at_start'], j['particles'], ps, ore)"
}

# bad_input NP: bad options and bad decks on NP ranks: exit 2 and the message.
bad_input() {
  local np=$1 run=("$dem2d")
  [ "$np" -gt 1 ] && run=(mpirun -np "$np" --oversubscribe "$dem2d")
  expect "np$np version" 0 '^dem2d [0-9]+\.[0-9]+\.[0-9]+' -- "${run[@]}" --version
  expect "np$np no deck" 2 'no input deck' -- "${run[@]}"
  expect "np$np unknown option" 2 'not expected' -- "${run[@]}" --bogus
  expect "np$np missing deck" 2 'nope\.in: error: cannot open deck' -- "${run[@]}" "$tmp/nope.in"
  expect "np$np misspelt key suggests" 2 "typo\.in:[0-9]+:[0-9]+: error: unknown key 'restituion'.*did you mean 'restitution'" -- "${run[@]}" "$tmp/typo.in"
  expect "np$np all errors reported" 2 'material\[0\]\.density = -7800.*must be > 0' -- "${run[@]}" "$tmp/typo.in"
  expect "np$np syntax error located" 2 'syntax\.in:2:[0-9]+: error' -- "${run[@]}" "$tmp/syntax.in"
  expect "np$np bad choice lists allowed" 2 'model\.in:[0-9]+:[0-9]+: error: .*"hertz-mindlin"' -- "${run[@]}" "$tmp/model.in"
  expect "np$np bad --set" 2 'did you mean' -- "${run[@]}" "$src/inputs/drop.in" --set run.durration=1
  expect "np$np unsafe dt names the option and the safe dt" 2 '^--set run\.dt=0\.01: error: run\.dt = 0\.01 s is unsafe.*safe dt is' -- "${run[@]}" "$src/inputs/drop.in" --set run.dt=0.01
  expect "np$np unsafe dt in the deck names its line" 2 'unsafe_dt\.in:[0-9]+:[0-9]+: error: run\.dt = 0\.01 s is unsafe' -- "${run[@]}" "$tmp/unsafe_dt.in"
  expect "np$np particle outside the drum" 2 "outside\.in:[0-9]+:[0-9]+: error: particle\[0\]\.position = \[0\.0, 3\.0\]: the particle \(radius 0\.1 m\) lies outside the drum" -- "${run[@]}" "$tmp/outside.in"
  expect "np$np --set before the deck" 2 '^--set run\.durration=1: error: unknown key' -- "${run[@]}" --set run.durration=1 "$src/inputs/drop.in"
  expect "np$np unwritable output" 2 "output/x.*cannot write|--output .*error" -- "${run[@]}" "$src/inputs/drop.in" --quiet --output /proc/output/x
}

# check_decks: --check prints the derived quantities; --set reaches them.
check_decks() {
  expect "check waterfall" 0 'fill fraction: +0\.3840' -- "$dem2d" --check "$src/inputs/waterfall.in"
  expect "check critical speed" 0 'critical speed: +1\.98' -- "$dem2d" --check "$src/inputs/waterfall.in"
  expect "check --set speed" 0 'drum speed: +1\.5000 rad/s' -- "$dem2d" --check "$src/inputs/waterfall.in" --set drum.speed=1.5
  expect "check --set before the deck" 0 'drum speed: +1\.5000 rad/s' -- "$dem2d" --check --set drum.speed=1.5 --set run.duration=2 "$src/inputs/waterfall.in"
  local deck
  for deck in "$src"/inputs/*.in; do
    expect "check $(basename "$deck")" 0 'the deck is valid' -- "$dem2d" --check "$deck"
  done
}

# short_run: a short run writes every output, and series.csv's energies add up.
short_run() {
  expect "short run np2" 0 'done: 0.5 s simulated' -- mpirun -np 2 --oversubscribe "$dem2d" "$src/inputs/drop.in" \
    --set run.duration=0.5 --output "$tmp/drop"
  local f
  for f in series.csv snapshots.h5 snapshots.xmf run.json; do
    [ -s "$tmp/drop/$f" ] && pass "output $f written" || fail "output $f missing"
  done
  head -1 "$tmp/drop/series.csv" | grep -q '^time,step,particles,contacts,kinetic_energy,rotational_energy,potential_energy,elastic_energy,dissipated_energy,drum_torque,drum_power' \
    && pass "series.csv columns" || fail "series.csv columns"
  grep -q '"ranks": 2' "$tmp/drop/run.json" && pass "run.json records 2 ranks" || fail "run.json ranks"
  [ -e "$tmp/drop/.dem2d.lock" ] && fail "the run left its lock" || pass "the run released its lock"
}

# one_folder_one_run: a second run into short_run's folder is refused (exit 2, on every rank, the
# first run's output untouched) unless --overwrite.
one_folder_one_run() {
  local sum_before np
  sum_before=$(md5sum "$tmp/drop/series.csv" "$tmp/drop/snapshots.h5" "$tmp/drop/run.json")
  for np in 1 2; do
    expect "np$np second run into one folder refused" 2 "^--output $tmp/drop: error: output directory '$tmp/drop' holds another run's output \(run\.json, series\.csv, snapshots\.h5, snapshots\.xmf, checkpoint\.h5\), which can be continued: resume it with --restart $tmp/drop/checkpoint\.h5, or give this run a new folder with --output DIR; --overwrite replaces that output and discards its checkpoint" -- \
      mpirun -np "$np" --oversubscribe "$dem2d" "$src/inputs/drop.in" --set run.duration=0.05 --output "$tmp/drop"
  done
  [ "$(md5sum "$tmp/drop/series.csv" "$tmp/drop/snapshots.h5" "$tmp/drop/run.json")" = "$sum_before" ] \
    && pass "refused runs left the first run's output as it was" || fail "a refused run touched the first run's output"
  expect "deck's folder refused names the key" 2 "^--set output\.directory=.*: error: output\.directory = '.*': output directory .* holds another run's output" -- \
    "$dem2d" --quiet "$src/inputs/drop.in" --set run.duration=0.05 --set "output.directory=$tmp/drop"
  expect "--overwrite replaces the output" 0 'done: 0.05 s simulated' -- "$dem2d" "$src/inputs/drop.in" \
    --set run.duration=0.05 --output "$tmp/drop" --overwrite
  grep -q '^0.05' <(tail -1 "$tmp/drop/series.csv" | cut -c1-4) && [ "$(grep -c '^' "$tmp/drop/series.csv")" -lt 100 ] \
    && pass "series.csv holds the new run only" || fail "series.csv mixes two runs"
}

# output_folder: short_run, then one_folder_one_run in its folder.
output_folder() {
  short_run
  one_folder_one_run
}

# folder_in_use: a folder a running dem2d holds is refused even with --overwrite.
folder_in_use() {
  "$dem2d" --quiet "$src/inputs/waterfall.in" --set run.duration=20 --output "$tmp/busy" > /dev/null 2>&1 &
  local busy=$!
  # Up to 30 s for the lock to appear (it takes well under 1 s alone, longer beside other jobs).
  for _ in $(seq 300); do [ -e "$tmp/busy/.dem2d.lock" ] && break; sleep 0.1; done
  expect "folder in use refused even with --overwrite" 2 "output directory '$tmp/busy' is in use by a dem2d run that is still running \(pid $busy on host" -- \
    "$dem2d" "$src/inputs/drop.in" --output "$tmp/busy" --overwrite
  kill "$busy"; wait "$busy" 2> /dev/null
}

# unstable_run: a run that blows up: exit 3, the step and particle ids named, a last snapshot, no
# NaN written.
unstable_run() {
  expect "unstable run exits 3" 3 'unstable at step [0-9]+.*particle [0-9]+ (and particle [0-9]+|moves [0-9.e+-]+ times its radius).*safe dt is' -- "$dem2d" \
    "$src/inputs/centrifuge.in" --quiet --set run.dt=5e-4 --set run.allow_unsafe_dt=true --set run.duration=0.3 \
    --output "$tmp/boom"
  [ -s "$tmp/boom/snapshots.h5" ] && pass "unstable run left a snapshot" || fail "no snapshot after blow-up"
  # The charge's angles are `nan` by definition when undefined (no arc); nothing else may be.
  if /usr/bin/python3 - "$tmp/boom/series.csv" <<'EOF_PY'
import csv, math, sys
undefined = {"toe_angle", "shoulder_angle", "surface_angle", "regime"}
for row in csv.DictReader(open(sys.argv[1])):
    for k, v in row.items():
        if k not in undefined and not math.isfinite(float(v)):
            sys.exit(f"{k} = {v} at t = {row['time']}")
EOF_PY
  then pass "no NaN in series.csv"; else fail "NaN/inf in series.csv"; fi
}

# waterfall_ranks: the same deck on 1, 2 and 3 ranks: snapshots bit-identical by id,
# through the executable and the collective HDF5 writer; run.json gives each rank's work.
waterfall_ranks() {
  local np
  for np in 1 2 3; do
    expect "waterfall np$np" 0 'done: 0.3 s simulated' -- mpirun -np "$np" --oversubscribe "$dem2d" \
      "$src/inputs/waterfall.in" --set run.duration=0.3 --set output.snapshot_interval=0.05 --output "$tmp/wf$np"
  done
  for np in 2 3; do
    expect "np$np snapshots identical to np1" 0 'bit-identical' -- /usr/bin/python3 "$src/post/h5compare.py" \
      "$tmp/wf1/snapshots.h5" "$tmp/wf$np/snapshots.h5"
  done
  grep -q '"rank_work": \[[0-9]*, [0-9]*, [0-9]*\]' "$tmp/wf3/run.json" && pass "run.json per-rank work" || fail "run.json per-rank work"
}

# 20 000 balls on one and on two ranks: the same bits in the snapshots, and the last line's
# figures.
large_charge() {
  local args=(--set fill.0.count=20000 --set fill.0.radius=0.006 --set run.dt=auto
    --set run.duration=0.002 --set output.snapshot_interval=0.0005)
  expect "20 000 balls np1" 0 'done: 0\.002 s simulated .*particle-steps/s\)$' -- \
    "$dem2d" "$src/inputs/waterfall.in" "${args[@]}" --output "$tmp/sw1"
  expect "20 000 balls np2" 0 'done: 0\.002 s simulated .*particle-steps/s\)$' -- \
    mpirun -np 2 --oversubscribe "$dem2d" "$src/inputs/waterfall.in" "${args[@]}" --output "$tmp/sw2"
  expect "20 000 balls: np2 snapshots identical to np1" 0 'bit-identical' -- /usr/bin/python3 \
    "$src/post/h5compare.py" "$tmp/sw1/snapshots.h5" "$tmp/sw2/snapshots.h5"
}

# burst_deck FILE: 300 ore particles in one row at one height, falling onto the floor.
burst_deck() {
  cat > "$1" <<'DECK'
title = "300 ore particles breaking in one step"
[run]
duration = 0.02
dt = "auto"
gravity = [0.0, 0.0]
[contact]
model = "hertz-mindlin"
rolling = "none"
[[material]]
name = "ore"
density = 4800.0
youngs_modulus = 6.0e10
shear_modulus = 2.4e10
restitution = 0.73
sliding_friction = 0.1
[[wall]]
from = [-17.0, 0.0]
to = [17.0, 0.0]
material = "ore"
[breakage]
material = "ore"
strength = 1.0e6
minimum_radius = 0.04
[output]
series_interval = 1.0e-3
DECK
  local k
  for k in $(seq 0 299); do  # one row, one height: every particle meets the floor in the same step
    printf '[[particle]]\nmaterial = "ore"\nradius = 0.05\nposition = [%s, 0.0501]\nvelocity = [0.0, -5.0]\n' \
      "$(awk "BEGIN{print -15.7 + 0.105 * $k}")" >> "$1"
  done
}

# burst_ranks: a burst: 300 ore particles strike the floor at once and all break in the same
# step, on 1, 2 and 4 ranks alike (fragments born across sector boundaries and at the scene centre).
burst_ranks() {
  burst_deck "$tmp/burst.in"
  local np
  for np in 1 2 4; do burst_run "$np"; done
  burst_alike
}

# burst_run NP: the burst on NP ranks, to $tmp/burstNP.
burst_run() {
  expect "burst np$1" 0 'done: 0.02 s simulated' -- mpirun -np "$1" --oversubscribe "$dem2d" \
    "$tmp/burst.in" --output "$tmp/burst$1"
}

# burst_alike: the runs on 2 and 4 ranks against the run on 1; 300 breakages in one step.
burst_alike() {
  local np
  for np in 2 4; do
    expect "burst np$np identical to np1" 0 'bit-identical' -- /usr/bin/python3 \
      "$src/post/h5compare.py" "$tmp/burst1/snapshots.h5" "$tmp/burst$np/snapshots.h5"
  done
  local n_burst n_steps
  n_burst=$(($(wc -l < "$tmp/burst1/breakages.csv") - 1))
  n_steps=$(tail -n +2 "$tmp/burst1/breakages.csv" | cut -d, -f1 | sort -u | wc -l)
  [ "$n_burst" -eq 300 ] && [ "$n_steps" -eq 1 ] && pass "burst: $n_burst breakages in $n_steps step" ||
    fail "burst: $n_burst breakages in $n_steps steps"
}

# unstable_run_np2: a blow-up on 2 ranks: exit 3 and the same message (rank 0 prints it).
unstable_run_np2() {
  expect "unstable run np2 exits 3" 3 'unstable at step [0-9]+.*particle [0-9]+ (and particle [0-9]+|moves [0-9.e+-]+ times its radius).*safe dt is' -- \
    mpirun -np 2 --oversubscribe "$dem2d" "$src/inputs/centrifuge.in" --quiet --set run.dt=5e-4 \
    --set run.allow_unsafe_dt=true --set run.duration=0.3 --output "$tmp/boom2"
}

# guards_warn NP: run.guards = "warn": a head-on impact at 8 x the safe dt creates energy; the
# guard is told as it fires, the run goes to its end (last row and run.json written) and still
# exits 3.
guards_warn() {
  local np=$1
  expect "guards warn np$np runs to the end, exits 3" 3 'error: the energy guard fired 1 time \(first: the run became unstable at step [0-9]+ .*energy was created' -- \
    mpirun -np "$np" --oversubscribe "$dem2d" "$src/inputs/impact.in" --quiet --set run.dt=1.56e-4 \
    --set run.allow_unsafe_dt=true --set run.guards=warn --output "$tmp/warn$np"
  grep -q '"guards_fired": {"energy": 1}' "$tmp/warn$np/run.json" && pass "np$np run.json guards_fired" || fail "np$np run.json guards_fired"
  awk -F, 'END { exit !($1 > 0.0099) }' "$tmp/warn$np/series.csv" && pass "np$np warn run wrote its last row" || fail "np$np warn run last row"
}

# motion_guard_stops: with run.guards = "warn" the motion guard (bodies passing through each
# other) still stops the run.
motion_guard_stops() {
  expect "guards warn: the motion guard still stops" 3 'error: the run became unstable at step 140 .*moves [0-9.e+-]+ times its radius' -- \
    "$dem2d" "$src/inputs/centrifuge.in" --quiet --set run.dt=5e-4 --set run.allow_unsafe_dt=true \
    --set run.duration=0.3 --set run.guards=warn --output "$tmp/warn_motion"
}

# particle_escapes: a particle that leaves the drum during the run (a soft ball sinking through
# the shell, the overlap guard only warning) stops it with exit 3 naming the particle, alike on
# 1 and 3 ranks.
particle_escapes() {
  printf '%s\n' 'title = "a soft ball sinks through the shell"' '[run]' 'duration = 3.0' 'dt = 1.0e-4' \
    'guards = "warn"' '[[material]]' 'name = "soft"' 'density = 1000.0' 'youngs_modulus = 1.0e3' \
    'poisson_ratio = 0.3' 'restitution = 0.5' 'sliding_friction = 0.3' '[drum]' 'radius = 1.0' \
    'speed = 0.0' 'material = "soft"' '[[particle]]' 'material = "soft"' 'radius = 0.1' \
    'position = [0.0, -0.85]' >"$tmp/escape.in"
  local np
  for np in 1 3; do
    expect "np$np particle leaving the drum exits 3 with its id" 3 \
      'escape\.in: error: the run became unstable at step 1858 \(t = 0\.1858 s\): particle 0 left the drum: its centre is 1\.01[0-9]* m from the drum.s centre, beyond the shell at 1 m' -- \
      mpirun -np "$np" --oversubscribe "$dem2d" "$tmp/escape.in" --quiet --output "$tmp/escape$np"
  done
}

# intervals_below_dt: output intervals shorter than a step are written every step, and the run
# says so for each key the deck (here --set) gave, at its location.
intervals_below_dt() {
  local out code=0 key rows
  out=$("$dem2d" "$src/inputs/drop.in" --quiet --set run.dt=1e-5 --set run.duration=1e-4 \
    --set output.snapshot_interval=1e-6 --set output.series_interval=2e-6 \
    --output "$tmp/every_step" 2>&1) || code=$?
  [ "$code" = 0 ] && pass "intervals below dt: exit 0" || fail "intervals below dt: exit $code"
  for key in snapshot_interval=1e-6 series_interval=2e-6; do
    grep -qE "^--set output\.$key: note: output\.${key%%=*} = [0-9e.-]+ s is shorter than one step, dt = 1e-05 s \(run\.dt\): written every step" <<<"$out" &&
      pass "intervals below dt: a note at --set output.$key" ||
      { fail "intervals below dt: no note for output.$key"; first_lines 5 <<<"$out"; }
  done
  rows=$(($(wc -l <"$tmp/every_step/series.csv") - 1))
  [ "$rows" = 11 ] && pass "intervals below dt: series.csv has a row every step (11)" ||
    fail "intervals below dt: series.csv has $rows rows, expected 11 (steps 0 to 10)"
}

make_bad_decks
job_init "$tmp/jobs"
# Grinding first: it is the longest job by far (its 2- and 3-rank runs most of all) and the
# others together fit beside it. The rest in the order of this file.
job "grinding on 1, 2, 3 ranks" grinding_ranks
job "size-aware grinding on 1, 3 ranks" size_aware_ranks
job "bad input, 1 rank" bad_input 1
job "bad input, 2 ranks" bad_input 2
job "--check" check_decks
job "one folder, one run" output_folder
job "folder in use" folder_in_use
job "unstable run" unstable_run
job "waterfall on 1, 2, 3 ranks" waterfall_ranks
job "20 000 balls, 1 and 2 ranks" large_charge
job "burst on 1, 2, 4 ranks" burst_ranks
job "unstable run, 2 ranks" unstable_run_np2
job "guards warn, 1 rank" guards_warn 1
job "guards warn, 2 ranks" guards_warn 2
job "motion guard" motion_guard_stops
job "particle leaving the drum" particle_escapes
job "output intervals below dt" intervals_below_dt
job_results

echo "cli: $failures failure(s)"
[ "$failures" -eq 0 ]
