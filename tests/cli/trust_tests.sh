#!/usr/bin/env bash
# What a run trusts before it writes (docs/output.md): the lock of its output folder, the
# checkpoint it continues and the folder a restart continues into.
#  1. Locks. A lock file left by a killed run names a pid that an unrelated live process may
#     hold (here a `sleep` of this shell): a fresh run, --overwrite and --restart take it over
#     with a notice. A folder whose lock a running dem2d holds is refused (exit 2, the message
#     names the lock file and that run's pid); once that run is killed (-9), its lock is taken
#     over by --restart.
#  2. Damaged checkpoints, on 1 and 2 ranks: a duplicated particle id, a particle moved out of
#     the drum, a NaN velocity, a bit of a velocity's exponent flipped in the raw file (only the
#     checksum sees it): exit 2 before any step, naming the file, the dataset, the particle and
#     the value, the folder untouched. A checkpoint without checksums (an older one) still loads.
#  3. Folders: --restart into another run's folder (other columns, or a checkpoint of other
#     physics) is refused (exit 2) at --output, naming that run; a fresh run refused a folder
#     with a checkpoint is offered --restart first.
# Usage: trust_tests.sh PATH/TO/dem2d SOURCE_DIR
set -u
dem2d=$(realpath "$1")
src=$(realpath "$2")
py=/usr/bin/python3
tmp=$(mktemp -d)
sleeper=""
cleanup() {
  [ -n "$sleeper" ] && kill "$sleeper" 2> /dev/null
  rm -rf "$tmp"
}
trap cleanup EXIT
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_mpi_yield_when_idle=1
# shellcheck source=tests/cli/lib.sh
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"

on() {
  local np=$1
  shift
  if [ "$np" -eq 1 ]; then "$dem2d" "$@"; else mpirun -np "$np" --oversubscribe "$dem2d" "$@"; fi
}
# sums DIR: the checksums of every file in DIR (hidden ones too).
sums() { (cd "$1" && md5sum .[!.]* * 2> /dev/null); }

wf=("$src/inputs/waterfall.in" --quiet)
on 1 "${wf[@]}" --set run.duration=0.02 --output "$tmp/wf" > /dev/null 2>&1
[ -s "$tmp/wf/checkpoint.h5" ] && pass "a checkpoint to work on" || fail "no checkpoint written"

# --- 1. Locks --------------------------------------------------------------------------------
sleep 300 &
sleeper=$!
host=$(hostname)
for how in fresh overwrite restart; do
  dir=$tmp/lock_$how
  args=(--set run.duration=0.04 --output "$dir")
  case $how in
    fresh) mkdir -p "$dir" ;;
    overwrite) cp -r "$tmp/wf" "$dir"; args+=(--overwrite) ;;
    restart) cp -r "$tmp/wf" "$dir"; args+=(--restart "$dir/checkpoint.h5") ;;
  esac
  echo "$host $sleeper" > "$dir/.dem2d.lock"
  expect "lock naming a live unrelated process ($how): taken over" 0 \
    "^$dir/\.dem2d\.lock: note: took over the lock file of a dem2d run that did not end \(pid $sleeper on host" -- \
    "$dem2d" "${wf[@]}" "${args[@]}"
  [ -e "$dir/.dem2d.lock" ] && fail "$how: the run left its lock" || pass "$how: the run released the lock"
done
# The lock of this format, naming the sleeper with another start time: the same.
cp -r "$tmp/wf" "$tmp/lock_started"
echo "$host $sleeper 1" > "$tmp/lock_started/.dem2d.lock"
expect "lock naming a live process started at another time: taken over" 0 "took over the lock file" -- \
  "$dem2d" "${wf[@]}" --set run.duration=0.04 --output "$tmp/lock_started" --restart "$tmp/lock_started/checkpoint.h5"

# A running dem2d holds its folder: refused however asked; killed, its lock is taken over.
busy_dir=$tmp/busy
cp -r "$tmp/wf" "$busy_dir"
"$dem2d" "${wf[@]}" --set run.duration=30 --output "$busy_dir" --restart "$busy_dir/checkpoint.h5" > /dev/null 2>&1 &
busy=$!
for _ in $(seq 300); do grep -q " $busy " "$busy_dir/.dem2d.lock" 2> /dev/null && break; sleep 0.1; done
for np in 1 2; do
  for how in fresh overwrite restart; do
    case $how in
      fresh) extra=() ;;
      overwrite) extra=(--overwrite) ;;
      restart) extra=(--restart "$tmp/wf/checkpoint.h5") ;;
    esac
    expect "np$np folder of a running dem2d refused ($how)" 2 \
      "^--output $busy_dir: error: output directory '$busy_dir' is in use by a dem2d run that is still running \(pid $busy on host [^,]+, which holds the lock file $busy_dir/\.dem2d\.lock\)" -- \
      on "$np" "${wf[@]}" --set run.duration=31 --output "$busy_dir" "${extra[@]}"
  done
done
kill -9 "$busy" 2> /dev/null
wait "$busy" 2> /dev/null
[ -e "$busy_dir/.dem2d.lock" ] && pass "kill -9 left the lock" || fail "no lock left to take over"
expect "the killed run's lock taken over by --restart" 0 "took over the lock file of a dem2d run that did not end \(pid $busy " -- \
  "$dem2d" "${wf[@]}" --set run.duration=0.04 --output "$busy_dir" --restart "$busy_dir/checkpoint.h5"
kill "$sleeper" 2> /dev/null
sleeper=""

# --- 2. Damaged checkpoints ------------------------------------------------------------------
# damage KIND FILE: changes the checkpoint FILE.
damage() {
  "$py" - "$1" "$2" << 'EOF'
import sys
import h5py
import numpy as np
kind, path = sys.argv[1], sys.argv[2]
with h5py.File(path, "r+") as f:
    ids = f["particles/id"][:]
    row = {int(i): k for k, i in enumerate(ids)}  # the rows are in no particular order
    if kind == "duplicate":
        ids[row[5]] = 3
        f["particles/id"][:] = ids
    elif kind == "outside":
        p = f["particles/position"][:]
        p[row[7]] = [3.0, 0.25]
        f["particles/position"][:] = p
    elif kind == "nan":
        v = f["particles/velocity"][:]
        v[row[9], 1] = np.nan
        f["particles/velocity"][:] = v
    elif kind == "old":
        for name in list(f["particles"]):
            del f["particles"][name].attrs["checksum"]
        del f["contacts"].attrs["checksum"]
        del f["particles"].attrs["count"]
        if "analysis/shell" in f:  # older checkpoints have no shell profile of the window
            del f["analysis/shell"]
    elif kind == "flip":
        d = f["particles/velocity"]
        offset = d.id.get_offset()  # contiguous: row k, column c at offset + 8 (2 k + c)
        where = offset + 8 * (2 * 11 + 0) + 6  # the byte holding the exponent's low bits
if kind == "flip":
    with open(path, "r+b") as raw:
        raw.seek(where)
        byte = raw.read(1)[0]
        raw.seek(where)
        raw.write(bytes([byte ^ 0x10]))  # the exponent's lowest bit: the value halves or doubles
EOF
}

ck_error="checkpoint\.h5: error: cannot restart from this checkpoint: "
declare -A expected=(
  [duplicate]="${ck_error}/particles/id: particle id 3 appears twice \(rows [0-9]+ and [0-9]+\)"
  [outside]="${ck_error}/particles/position: particle 7 \(radius 0\.1 m\) at \[3, 0\.25\] lies outside the drum \(radius 2\.5 m about \[0, 0\]\) at t = 0\.02 s"
  [nan]="${ck_error}/particles/velocity: particle 9 has velocity y = nan"
  [flip]="${ck_error}/particles/velocity: its values do not match the checksum written with them \(0x[0-9a-f]{16}, read 0x[0-9a-f]{16}\): the file was changed or damaged after it was written"
)
for kind in duplicate outside nan flip; do
  dir=$tmp/damaged_$kind
  cp -r "$tmp/wf" "$dir"
  damage "$kind" "$dir/checkpoint.h5"
  before=$(sums "$dir")
  for np in 1 2; do
    expect "np$np damaged checkpoint ($kind) refused before any step" 2 "^$dir/${expected[$kind]}" -- \
      on "$np" "${wf[@]}" --set run.duration=0.04 --output "$dir" --restart "$dir/checkpoint.h5"
  done
  [ "$(sums "$dir")" = "$before" ] && pass "$kind: the folder untouched" || fail "$kind: the refused runs changed the folder"
done
for np in 1 2; do
  dir=$tmp/damaged_old_$np
  cp -r "$tmp/wf" "$dir"
  damage old "$dir/checkpoint.h5"
  expect "np$np checkpoint without checksums or shell profile still loads" 0 "" -- \
    on "$np" "${wf[@]}" --set run.duration=0.03 --output "$dir" --restart "$dir/checkpoint.h5"
done
# The checksums do not depend on the rank count: a checkpoint 2 ranks wrote loads on 1 and 3.
on 2 "${wf[@]}" --set run.duration=0.02 --output "$tmp/wf2" > /dev/null 2>&1
for np in 1 3; do
  cp -r "$tmp/wf2" "$tmp/wf2_$np"
  expect "np$np a checkpoint of 2 ranks passes its checksums" 0 "" -- \
    on "$np" "${wf[@]}" --set run.duration=0.03 --output "$tmp/wf2_$np" --restart "$tmp/wf2_$np/checkpoint.h5"
done

# --- 3. Folders ------------------------------------------------------------------------------
on 1 "$src/inputs/drop.in" --quiet --set run.duration=0.01 --output "$tmp/other" > /dev/null 2>&1
on 1 "${wf[@]}" --set run.duration=0.01 --set drum.speed=1.5 --output "$tmp/other_physics" > /dev/null 2>&1
for np in 1 2; do
  before=$(sums "$tmp/other")
  expect "np$np --restart into another deck's folder refused" 2 \
    "^--output $tmp/other: error: output directory '$tmp/other' holds the output of another run, the run 'Drop test[^']*' of the deck [^ ]*drop\.in \(its run\.json\): its series\.csv has other columns than this run's; --restart $tmp/wf/checkpoint\.h5 continues the run of [^ ]*waterfall\.in: give it that run's folder with --output $tmp/wf" -- \
    on "$np" "${wf[@]}" --set run.duration=0.04 --output "$tmp/other" --restart "$tmp/wf/checkpoint.h5"
  [ "$(sums "$tmp/other")" = "$before" ] && pass "np$np the other run's folder untouched" || fail "np$np the other run's folder changed"
  expect "np$np --restart into a folder of other physics refused" 2 \
    "^--output $tmp/other_physics: error: output directory '$tmp/other_physics' holds the output of another run, the run '[^']*' of the deck [^ ]*waterfall\.in \(its run\.json\): its checkpoint\.h5 holds a deck whose physics differs from this one's \(1 key\)" -- \
    on "$np" "${wf[@]}" --set run.duration=0.04 --output "$tmp/other_physics" --restart "$tmp/wf/checkpoint.h5"
  expect "np$np a fresh run into a folder with a checkpoint is offered --restart first" 2 \
    "^--output $tmp/wf: error: output directory '$tmp/wf' holds another run's output \(run\.json, series\.csv, snapshots\.h5, snapshots\.xmf, checkpoint\.h5, lifters\.csv\), which can be continued: resume it with --restart $tmp/wf/checkpoint\.h5, or give this run a new folder with --output DIR; --overwrite replaces that output and discards its checkpoint" -- \
    on "$np" "${wf[@]}" --set run.duration=0.04 --output "$tmp/wf"
done

if [ "$failures" -ne 0 ]; then
  echo "$failures trust test(s) failed"
  exit 1
fi
echo "all trust tests passed"
