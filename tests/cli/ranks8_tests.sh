#!/usr/bin/env bash
# The whole program on 8 ranks against 1 rank (correctness past this machine's 2 cores;
# 8 ranks here are oversubscribed 4 to 1, so this checks bits, not speed). The centrifuge deck
# with the drum at full speed from t = 0, 0.04 s: on 1 rank in one go; on 8 ranks to 0.02 s (the
# snapshots and the checkpoint written collectively by 8 ranks), continued from that checkpoint
# on 1 rank. Checked: every snapshot of the second run (8 ranks, then 1) equals the 1-rank
# run's bit for bit (post/h5compare.py, particles by id); the 8-rank run's run.json says 8
# ranks, and every one of the 8 owned particles (rank_work) and held ghosts (rank_ghosts) at the
# last rebuild. 8 ranks cost ~7 s to start and end and ~6 ms per step here when loaded, so
# the run is short: 12-25 s in all. Usage: ranks8_tests.sh PATH/TO/dem2d SOURCE_DIR
set -u
dem2d=$(realpath "$1")
src=$(realpath "$2")
py=/usr/bin/python3
tmp=$(mktemp -d)
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
# Ranks waiting for each other yield the core instead of spinning (8 ranks on 2 cores).
export OMPI_MCA_mpi_yield_when_idle=1
# shellcheck source=tests/cli/lib.sh
source "$(dirname "${BASH_SOURCE[0]}")/lib.sh"
trap 'rm -rf "$tmp"' EXIT

deck=("$src/inputs/centrifuge.in" --set drum.ramp_time=0 --set run.duration=0.04
      --set output.snapshot_interval=0.005)

expect "np1 0.04 s" 0 'done: 0.04 s simulated' -- "$dem2d" "${deck[@]}" --output "$tmp/np1"
expect "np8 to 0.02 s" 0 'done: 0.02 s simulated' -- mpirun -np 8 --oversubscribe "$dem2d" \
  "${deck[@]}" --set run.duration=0.02 --output "$tmp/np8"
cp "$tmp/np8/run.json" "$tmp/np8_run.json" || fail "np8 wrote no run.json"  # the restart rewrites it
expect "np8's checkpoint continued on 1 rank" 0 'continued from t = 0\.02 s' -- "$dem2d" \
  "${deck[@]}" --output "$tmp/np8" --restart "$tmp/np8/checkpoint.h5"

if out=$("$py" "$src/post/h5compare.py" "$tmp/np1/snapshots.h5" "$tmp/np8/snapshots.h5" \
           --by-step 2>&1); then
  pass "np8 snapshots identical to np1: $(tail -1 <<<"$out")"
else
  fail "np8 snapshots differ from np1"
  first_lines 8 <<<"$out"
fi

if out=$("$py" - "$tmp/np8_run.json" <<'EOF' 2>&1
import json
import sys
run = json.load(open(sys.argv[1]))
assert run["ranks"] == 8, f"ranks {run['ranks']}"
work, ghosts = run["rank_work"], run["rank_ghosts"]
assert len(work) == 8 and min(work) > 0, f"rank_work {work}: a rank owned nothing"
assert len(ghosts) == 8 and min(ghosts) > 0, f"rank_ghosts {ghosts}: a rank held no ghost"
print(f"8 ranks, work {min(work):g}-{max(work):g}, ghosts {min(ghosts):g}-{max(ghosts):g}, "
      f"{run['partitions']} partitions")
EOF
); then
  pass "np8 run.json: $out"
else
  fail "np8 run.json: $out"
fi

echo "ranks8: $failures failure(s)"
[ "$failures" -eq 0 ]
