#!/usr/bin/env bash
# Same physics, bit for bit: run every shipped deck with two dem2d binaries side by side and
# compare their snapshots with post/h5compare.py (particles matched by id; exact equality of
# every dataset both write; a dataset only the new binary writes is listed, not a difference).
#
#   bench/same_physics.sh OLD_DEM2D NEW_DEM2D [RANKS] [OUT_DIR]
#
# Use it for every change that must not change physics (a refactor, a speed-up): build the old
# commit in a second work tree (git worktree add ../old <commit>), then run this script with
# both binaries. RANKS (default 1) is the rank count of both runs; the new binary at another
# rank count must agree too (the decomposition is bit-identical at any rank count). Prints one
# line per deck and exits 1 when any deck's snapshots differ; a series.csv that differs is
# reported with its largest difference (the column, relative to the column's largest value).
# NEW_ARGS (environment) is added to the new binary's command line, e.g.
# NEW_ARGS="--set run.spatial_sort=always" to compare a store sorted at every rebuild with the
# old binary's id order.
set -u
old=$1
new=$2
np=${3:-1}
out=${4:-$(mktemp -d)}
src=$(cd "$(dirname "$0")/.." && pwd)
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
run() {
  local bin=$1 deck=$2 dir=$3
  local -a extra=()
  [ "$bin" = "$new" ] && read -r -a extra <<< "${NEW_ARGS:-}"
  rm -rf "$dir"  # one folder, one run: a rerun into the same OUT_DIR starts afresh
  if [ "$np" -gt 1 ]; then
    mpirun -np "$np" --oversubscribe "$bin" --quiet --output "$dir" "${extra[@]}" "$deck" \
      > "$dir.log" 2>&1
  else
    "$bin" --quiet --output "$dir" "${extra[@]}" "$deck" > "$dir.log" 2>&1
  fi
}
# The column of series.csv that differs most, relative to that column's largest magnitude.
series_difference() {
  /usr/bin/python3 - "$1" "$2" <<'PY'
import csv, math, sys
a, b = (list(csv.DictReader(open(f))) for f in sys.argv[1:3])
if len(a) != len(b):
    print(f"{len(a)} rows against {len(b)}")
    sys.exit()
worst, where = 0.0, "none"
for col in a[0]:
    try:
        x = [float(r[col]) for r in a]
        y = [float(r[col]) for r in b]
    except ValueError:
        continue
    scale = max((abs(v) for v in x if math.isfinite(v)), default=0.0) or 1.0
    d = max((abs(u - v) for u, v in zip(x, y) if math.isfinite(u) and math.isfinite(v)),
            default=0.0) / scale
    if d > worst:
        worst, where = d, col
print(f"largest {worst:.1e} of the column's scale in {where}")
PY
}
mkdir -p "$out"
differ=0
printf '%-22s %8s %8s  %s\n' deck old_s new_s result
for deck in "$src"/inputs/*.in; do
  name=$(basename "$deck" .in)
  t0=$(date +%s.%N)
  run "$old" "$deck" "$out/old_$name"
  t1=$(date +%s.%N)
  run "$new" "$deck" "$out/new_$name"
  t2=$(date +%s.%N)
  if /usr/bin/python3 "$src/post/h5compare.py" --allow-added "$out/old_$name/snapshots.h5" \
       "$out/new_$name/snapshots.h5" > "$out/$name.compare" 2>&1; then
    result="snapshots bit-identical"
    grep -q "only in the second" "$out/$name.compare" && result="$result (new datasets: $(sed 's/.*second file: //' "$out/$name.compare"))"
  else
    result="DIFFERENT (see $out/$name.compare)"
    differ=1
  fi
  if cmp -s "$out/old_$name/series.csv" "$out/new_$name/series.csv"; then
    result="$result, series.csv identical"
  else
    result="$result, series.csv differs: $(series_difference "$out/old_$name/series.csv" \
      "$out/new_$name/series.csv")"
  fi
  printf '%-22s %8.2f %8.2f  %s\n' "$name" "$(echo "$t1 - $t0" | bc)" "$(echo "$t2 - $t1" | bc)" "$result"
done
exit $differ
