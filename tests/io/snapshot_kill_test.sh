#!/usr/bin/env bash
# Snapshots survive kill -9: runs of the waterfall deck writing a snapshot every 20 steps are
# killed with SIGKILL at moments drawn from a seeded generator (DEM2D_KILL_SEED), each in its
# own folder. Then snapshots.xmf must be valid XML, and every HDF5 dataset it names must open
# with h5py and read back with the Dimensions the sidecar states; every snapshot it lists is
# under /snapshots; nothing under /snapshots is missing one of the datasets the first snapshot
# has. One line per kill (ok / FAIL); exit status 1 if any failed. A kill inside HDF5's close
# at the end of a snapshot can leave a file whose end HDF5 had not written yet, which h5py
# refuses as "truncated file" (docs/output.md, "Crash safety"): at this rate of snapshots about
# one kill in 30 lands there. That outcome is told apart ("window") and does not fail the test;
# any other damage does.
#
#   tests/io/snapshot_kill_test.sh PATH/TO/dem2d SOURCE_DIR
set -u
dem2d=$(realpath "$1")
src=$(realpath "$2")
seed=${DEM2D_KILL_SEED:-37}
work=$(mktemp -d "${TMPDIR:-/tmp}/dem2d_kill.XXXXXX")
trap 'rm -rf "$work"' EXIT
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
RANDOM=$seed
failed=0
for k in 1 2 3 4 5 6; do
  out=$work/run$k
  delay=$(printf '0.%03d' $((300 + RANDOM % 700)))  # 0.3-1.0 s: start-up done, snapshots going
  "$dem2d" --quiet --output "$out" "$src/inputs/waterfall.in" --set run.duration=5 \
    --set output.snapshot_interval=2e-4 --set output.checkpoint_interval=0 \
    --set output.checkpoint_minutes=0 > "$out.log" 2>&1 &
  pid=$!
  sleep "$delay"
  kill -9 "$pid" 2> /dev/null
  wait "$pid" 2> /dev/null
  result=$(/usr/bin/python3 - "$out" <<'PY' 2>&1
import os, sys
import xml.etree.ElementTree as ET
import h5py
out = sys.argv[1]
xmf = os.path.join(out, "snapshots.xmf")
if not os.path.exists(xmf):
    print("no snapshots.xmf (killed before the first snapshot)")
    sys.exit(0)
root = ET.parse(xmf).getroot()  # raises on a torn document
items = [d for d in root.iter("DataItem") if d.get("Format") == "HDF"]
listed = {g.get("Name").split("_", 1)[1] for g in root.iter("Grid")
          if g.get("Name", "").startswith("snapshot_")}
try:
    f = h5py.File(os.path.join(out, "snapshots.h5"), "r")
except OSError as e:
    if "truncated file" in str(e):
        print(f"killed inside HDF5's close (the documented window): {e}")
        sys.exit(3)
    raise
with f:
    for d in items:
        name, path = d.text.strip().split(":", 1)
        dims = tuple(int(x) for x in d.get("Dimensions").split())
        data = f[path][()]
        if data.shape != dims:
            sys.exit(f"{path}: shape {data.shape}, the sidecar says {dims}")
    kept = set(f["snapshots"])
    if not listed <= kept:
        sys.exit(f"listed but not in /snapshots: {sorted(listed - kept)[:5]}")
    first = set(f["snapshots"][min(kept)])
    for n in kept:
        if set(f["snapshots"][n]) != first:
            sys.exit(f"/snapshots/{n} holds {sorted(f['snapshots'][n])}")
print(f"{len(listed)} snapshots listed, {len(items)} datasets read")
PY
  )
  case $? in
    0) echo "ok   kill -9 after $delay s: $result" ;;
    3) echo "note kill -9 after $delay s: $result" ;;
    *) echo "FAIL kill -9 after $delay s: $result"
       failed=1 ;;
  esac
done
exit $failed
