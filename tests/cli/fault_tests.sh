#!/usr/bin/env bash
# Fault tests (issue "nothing lost"): a run killed at any moment, stopped by a signal or by a
# full disk loses nothing that --restart cannot bring back, bit for bit.
# Usage: fault_tests.sh PATH/TO/dem2d SOURCE_DIR
#        (DEM2D_FAULT_SEED=N: other kill moments; DEM2D_KEEP_FAULT_OUTPUT=1 keeps the files)
#
#  1. kill -9 at random moments. The waterfall deck for 0.4 s simulated with a checkpoint every
#     0.01 s; runs killed with SIGKILL (every rank at once) at moments drawn from a seeded
#     generator and logged: some series rows further on, at the start of a checkpoint write
#     (the kill follows the appearance of checkpoint.h5.tmp), or a time after the start
#     (start-up, the resume's own rewriting of the output, or the run). Each is followed by
#     --restart from checkpoint.h5 (a fresh --overwrite run when there is none yet), on 1 or 2
#     ranks in turn, until a run completes. Then: every checkpoint.h5 a kill left is a whole
#     dem2d checkpoint; every snapshots.h5 a kill left holds only complete snapshots; the final
#     snapshots equal an uninterrupted run's bit for bit, paired by step; series.csv has the
#     uninterrupted run's steps, each once, and no torn row; lifters.csv is the uninterrupted
#     run's, byte for byte.
#  2. SIGTERM to mpirun -np 2: every rank stops, exit 1 (mpirun's), run.json says
#     "interrupted": true, the message says where it stopped and how to resume, no
#     checkpoint.h5.tmp or lock is left; resumed on 1 rank, the result equals an uninterrupted
#     run's.
#  3. SIGINT to one process: exit 5, the same checks; resumed on 2 ranks.
#  4. A full disk (a small tmpfs: needs root and mount, else skipped), on 1 and 2 ranks, full
#     at a checkpoint's datasets, at its close, or at a snapshot: exit 4 (not hung: its files
#     unchanged for 5 s while it runs), a message naming the file, no crash trace, the folder
#     released; checkpoint.h5 is whole and snapshots.h5 holds complete snapshots only; once
#     there is room, --restart finishes the run equal to the uninterrupted one.
#  5. What a kill -9 inside a file open leaves behind: Open MPI's default MPI-IO component
#     (OMPIO) keeps a named semaphore per file name, /dev/shm/sem.OMPIO_<name>, that a run
#     killed inside MPI_File_open leaves locked; every later open of that name then waits for
#     ever. With the semaphores of checkpoint.h5.tmp and snapshots.h5 planted locked, runs on 1
#     and 2 ranks finish (exit 0, not hung, the reference's result) and leave them untouched.
#     A control run that asks for OMPIO (OMPI_MCA_io=ompio) shows the trap is real here: it
#     hangs (noted, not a failure: another MPI library may have no such semaphore).
# One line per check (ok / FAIL); exit status 1 if any failed. About 25 s of CPU time.
set -u
dem2d=$(realpath "$1")
src=$(realpath "$2")
py=/usr/bin/python3
deck=$src/inputs/waterfall.in
seed=${DEM2D_FAULT_SEED:-4242}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
tmp=$(mktemp -d)
disk=""     # the tmpfs mount point while one is mounted
planted=()  # the semaphores section 5 created (removed at the end)
started=()  # the pids of the run under way (mpirun, dem2d ranks): ended if the test is cut short
failures=0
pass() { echo "ok   $1"; }
fail() { echo "FAIL $1"; failures=$((failures + 1)); }
note() { echo "     $1"; }
show() { grep -v '^ *$' "$1" | head -"${2:-8}" | sed 's/^/       | /'; }

# A pid of ours still running dem2d or mpirun (not a zombie, not a reused pid).
ours_alive() {
  local state
  state=$(awk '{print $3}' "/proc/$1/stat" 2> /dev/null) || return 1
  [ -n "$state" ] && [ "$state" != Z ] && tr '\0' ' ' < "/proc/$1/cmdline" 2> /dev/null | grep -qE 'dem2d|mpirun'
}
# bash reports each job that a signal ended ("line N: PID Killed ..."), on its own stderr:
# that goes to a file, from which anything else is shown at the end.
exec 3>&2 2> "$tmp/shell.err"
cleanup() {
  local p
  for p in "${started[@]}"; do ours_alive "$p" && kill -9 "$p" 2> /dev/null; done
  if [ -n "$disk" ]; then umount "$disk" 2> /dev/null || umount -l "$disk" 2> /dev/null; fi
  for p in "${planted[@]}"; do rm -f "/dev/shm/sem.${p#/}"; done
  grep -vE ': line [0-9]+: +[0-9]+ [A-Z][a-z]+' "$tmp/shell.err" >&3
  if [ -n "${DEM2D_KEEP_FAULT_OUTPUT:-}" ]; then echo "kept: $tmp"; else rm -rf "$tmp"; fi
}
trap cleanup EXIT
trap 'exit 130' INT TERM

common=(--quiet --set run.duration=0.4 --set output.checkpoint_interval=0.01
        --set output.snapshot_interval=0.05)
row_bytes=420  # a series.csv row of this deck, about

# start NP LOG ARGS...: dem2d on NP ranks in the background (NP 1: the process itself, else
# under mpirun). Sets run_pid (dem2d or mpirun) and ranks (the dem2d pids).
start() {
  local np=$1 log=$2 _
  shift 2
  if [ "$np" -eq 1 ]; then
    "$dem2d" "$@" > "$log" 2>&1 &
    run_pid=$!
    ranks=$run_pid
  else
    mpirun -np "$np" --oversubscribe "$dem2d" "$@" > "$log" 2>&1 &
    run_pid=$!
    ranks=""
    for _ in $(seq 1000); do  # up to 10 s for mpirun to start its ranks
      ranks=$(pgrep -P "$run_pid" | tr '\n' ' ')
      [ "$(wc -w <<< "$ranks")" -ge "$np" ] && break
      kill -0 "$run_pid" 2> /dev/null || break
      sleep 0.01
    done
  fi
  # shellcheck disable=SC2206
  started+=("$run_pid" $ranks)
}

# finish LIMIT [DIR]: waits for the started run at most LIMIT seconds, or, given DIR, until the
# files in DIR have not changed for 5 s (then it is hung: its ranks and mpirun are killed and
# hung=1); rc is its exit status.
finish() {
  local ticks=$(($1 * 20)) dir=${2:-} files="" last="" still=0
  hung=0
  while kill -0 "$run_pid" 2> /dev/null; do
    if [ -n "$dir" ] && [ $((ticks % 10)) -eq 0 ]; then  # every 0.5 s
      files=$(stat -c '%n %s %Y' "$dir"/* "$dir"/.dem2d.lock 2> /dev/null)
      if [ "$files" = "$last" ]; then still=$((still + 1)); else still=0; fi
      last=$files
    fi
    if [ "$ticks" -le 0 ] || [ "$still" -ge 10 ]; then
      hung=1
      # shellcheck disable=SC2086
      kill -9 $ranks "$run_pid" 2> /dev/null
      break
    fi
    ticks=$((ticks - 1))
    sleep 0.05
  done
  wait "$run_pid"
  rc=$?
  started=()  # ended (mpirun ends its ranks)
}

# run NP LOG ARGS...: a run to its end (at most 60 s).
run() {
  start "$@"
  finish 60
}

# Until the killed ranks are gone (reaped: a zombie still holds its pid, which the folder's
# lock names), at most 10 s.
reaped() {
  local p _
  for p in $ranks; do
    for _ in $(seq 200); do [ -e "/proc/$p" ] || break; sleep 0.05; done
  done
}

# Waits until FILE has at least BYTES bytes; false if the run ended first.
wait_size() {
  local size
  while kill -0 "$run_pid" 2> /dev/null; do
    size=$(stat -c %s "$1" 2> /dev/null || echo 0)
    [ "$size" -ge "$2" ] && return 0
    sleep 0.005
  done
  return 1
}

# A file's identity (inode, modification time to the ns, size); empty when absent.
identity() { stat -c '%i %y %s' "$1" 2> /dev/null; }

crash_pattern='MPI_ABORT|Segmentation|core dumped|terminate called|Aborted|internal error|received signal|exited on signal'

# ---------------------------------------------------------------------------------------------
# The file checks, in Python (h5py): queued as they come up, run in one process per section.
cat > "$tmp/check.py" << 'PY'
"""Runs the checks listed in a file (one per line: NAME, CHECK, ARGS..., tab-separated); prints
"ok   NAME (summary)" or "FAIL NAME" and the details, one check after the other; the exit
status is the number of failures."""
import contextlib
import importlib.util
import io
import os
import json
import re
import sys

import h5py
import numpy as np

FIELDS = {"id", "material", "position", "velocity", "angle", "spin", "radius"}


def text(value):
    return value.decode() if isinstance(value, (bytes, np.bytes_)) else str(value)


def checkpoints(*paths):
    """Each file is a whole dem2d checkpoint: its format, state, particle fields and contacts."""
    bad = []
    for path in paths:
        try:
            with h5py.File(path, "r") as f:
                if text(f.attrs["format"]) != "dem2d checkpoint 1":
                    raise ValueError(f"format {text(f.attrs['format'])!r}")
                n = f["particles/id"].shape[0]
                if n == 0 or any(f["particles"][k].shape[0] != n for k in f["particles"]):
                    raise ValueError("particle fields of different lengths")
                for k in f["particles"]:
                    f["particles"][k][()]
                for k in ("time", "step", "dt"):
                    f.attrs[k]
                for k in ("contacts/a", "contacts/b", "deck"):
                    f[k][()]
        except Exception as e:  # noqa: BLE001 - a file that cannot be read is the finding
            bad.append(f"{path}: {type(e).__name__}: {e}")
    for b in bad:
        print(b)
    return not bad, f"{len(paths)} checkpoint(s), each whole, format 'dem2d checkpoint 1'"


def snapshots(*paths, xmf=None):
    """Only complete snapshots under /snapshots: every dataset, time and step, N rows each;
    snapshots.xmf (when given and present) points at snapshots that exist."""
    bad, counts = [], []
    for path in paths:
        try:
            with h5py.File(path, "r") as f:
                names = sorted(f["snapshots"]) if "snapshots" in f else []
                for name in names:
                    g = f["snapshots"][name]
                    missing = FIELDS - set(g)
                    if missing or "time" not in g.attrs or "step" not in g.attrs:
                        bad.append(f"{path}: /snapshots/{name} lacks {sorted(missing)} or time/step")
                        continue
                    n = g["id"].shape[0]
                    if any(g[k].shape[0] != n for k in g):
                        bad.append(f"{path}: /snapshots/{name}: datasets of different lengths")
                    for k in g:
                        g[k][()]
                counts.append(len(names))
                if xmf:
                    try:
                        refs = set(re.findall(r"snapshots\.h5:/snapshots/(\d+)/", open(xmf).read()))
                    except FileNotFoundError:
                        refs = set()
                    if refs - set(names):
                        bad.append(f"{xmf} points at missing snapshots {sorted(refs - set(names))[:3]}")
        except Exception as e:  # noqa: BLE001
            bad.append(f"{path}: cannot be read: {type(e).__name__}: {e}")
    for b in bad:
        print(b)
    what = f"{counts[0]} snapshots" if len(paths) == 1 and counts else f"{len(paths)} file(s)"
    return not bad, f"{what}, every one complete"


REGIMES = ["-", "slumping", "rolling", "cascading", "cascading-cataracting", "cataracting",
           "centrifuging"]


def series(ref_path, path):
    """The reference's steps, each once, every row whole; the values agree (time, step,
    particles and contacts exactly; the sums within 1e-9 of the column's largest value; the
    regime, a word, as its index: exactly; nan where the reference has it)."""
    def read(p):
        raw = open(p).read()
        problems = [] if raw.endswith("\n") else ["the last row has no newline (torn)"]
        lines = raw.split("\n")
        header, rows = lines[0].split(","), []
        for i, line in enumerate(lines[1:], 2):
            if not line:
                continue
            cells = line.split(",")
            try:  # the regime column as its index among the regimes (docs/models.md)
                values = [REGIMES.index(c) if name == "regime" else float(c)
                          for name, c in zip(header, cells)]
            except ValueError:
                values = None
            if len(cells) != len(header) or values is None:
                problems.append(f"line {i} torn: {line[:60]!r}")
            else:
                rows.append(values)
        return header, np.array(rows), problems

    hr, ref, _ = read(ref_path)
    h, got, problems = read(path)
    worst = (0.0, "")
    if h != hr:
        problems.append("its header differs from the reference's")
    else:
        s, sr = got[:, h.index("step")], ref[:, h.index("step")]
        if len(np.unique(s)) != len(s):
            problems.append(f"{len(s) - len(np.unique(s))} duplicated steps")
        if np.any(np.diff(s) <= 0):
            problems.append("steps not increasing")
        if len(s) != len(sr) or np.any(s != sr):
            problems.append(f"{len(s)} rows against the reference's {len(sr)}; the steps differ")
        else:
            for k, name in enumerate(h):
                a, b = got[:, k], ref[:, k]
                if name in ("time", "step", "particles", "contacts"):
                    if np.any(a != b):
                        problems.append(f"{name} differs")
                    continue
                if np.any(np.isnan(a) != np.isnan(b)):  # the charge's angles may be nan
                    problems.append(f"{name} is nan in other rows")
                    continue
                a, b = np.nan_to_num(a), np.nan_to_num(b)
                rel = np.abs(a - b).max() / max(np.abs(b).max(), 1e-300)
                worst = max(worst, (rel, name))
                if rel > 1e-9:
                    problems.append(f"{name} differs by {rel:.2g} of its largest value")
    for p in problems[:6]:
        print(p)
    most = f", largest difference {worst[0]:.1g} ({worst[1]})" if worst[0] > 0 else ", identical"
    return not problems, f"{len(got)} rows, the reference's steps{most}"


def runjson(path, key, expected):
    value = json.load(open(path)).get(key)
    return json.dumps(value) == expected, f"{key}: {json.dumps(value)}"


def compare(first, second):
    """post/h5compare.py FIRST SECOND --by-step --allow-added."""
    post = os.path.dirname(os.path.abspath(sys.argv[2]))
    if post not in sys.path:  # h5compare imports its neighbours in post/
        sys.path.insert(0, post)
    spec = importlib.util.spec_from_file_location("h5compare", sys.argv[2])
    h5compare = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(h5compare)
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        code = h5compare.main([first, second, "--by-step", "--allow-added"])
    lines = out.getvalue().strip().splitlines()
    if code != 0:
        print("\n".join(lines[:8]))
    return code == 0, (lines[-1] if lines else "")[:110]


def same_bytes(first, second):
    """The two files hold the same bytes (lifters.csv: the same on any rank count and across
    restarts)."""
    a, b = open(first, "rb").read(), open(second, "rb").read()
    if a != b:
        lines_a, lines_b = a.split(b"\n"), b.split(b"\n")
        first_diff = next((i for i, (x, y) in enumerate(zip(lines_a, lines_b)) if x != y),
                          min(len(lines_a), len(lines_b)))
        print(f"{len(lines_b)} lines against the reference's {len(lines_a)}; the first "
              f"difference at line {first_diff + 1}")
    return a == b, f"{len(b)} bytes"


CHECKS = {"checkpoints": checkpoints, "snapshots": snapshots, "series": series,
          "same_bytes": same_bytes, "runjson": runjson, "compare": compare,
          "snapshots_xmf": lambda h5, xmf: snapshots(h5, xmf=xmf)}


def main():
    failed = 0
    for line in open(sys.argv[1]).read().splitlines():
        name, check, *args = line.split("\t")
        details = io.StringIO()
        try:
            with contextlib.redirect_stdout(details):
                ok, summary = CHECKS[check](*args)
        except Exception as e:  # noqa: BLE001
            ok, summary = False, ""
            details.write(f"{type(e).__name__}: {e}\n")
        print(f"ok   {name} ({summary})" if ok else f"FAIL {name}")
        if not ok:
            failed += 1
            for d in details.getvalue().strip().splitlines()[:8]:
                print(f"       | {d}")
    return min(failed, 100)


sys.exit(main())
PY
# queue NAME CHECK ARGS...: a check for the next run_checks.
queue() { (IFS=$'\t'; echo "$*") >> "$tmp/queue"; }
run_checks() {
  [ -s "$tmp/queue" ] || return 0
  "$py" "$tmp/check.py" "$tmp/queue" "$src/post/h5compare.py" 2>&1
  failures=$((failures + $?))
  : > "$tmp/queue"
}
: > "$tmp/queue"
same_as_reference() {  # NAME DIR [REFERENCE]: snapshots by step, series.csv and lifters.csv against it
  local against=${3:-$ref}
  queue "$1: snapshots bit-identical to the uninterrupted run's, by step" compare "$against/snapshots.h5" "$2/snapshots.h5"
  queue "$1: series.csv has the uninterrupted run's rows" series "$against/series.csv" "$2/series.csv"
  queue "$1: lifters.csv is the uninterrupted run's, byte for byte" same_bytes "$against/lifters.csv" "$2/lifters.csv"
}

# ---------------------------------------------------------------------------------------------
# The reference: the deck uninterrupted, on one rank.
ref=$tmp/ref
run 1 "$tmp/ref.log" "$deck" "${common[@]}" --output "$ref"
if [ "$rc" -ne 0 ]; then
  fail "uninterrupted reference run: exit $rc"
  show "$tmp/ref.log"
  exit 1
fi
pass "uninterrupted reference run (waterfall, 0.4 s, a checkpoint every 0.01 s)"

# ---------------------------------------------------------------------------------------------
# 1. kill -9 at random moments, then --restart, until a run completes.
RANDOM=$seed
out=$tmp/kill
mkdir -p "$tmp/left"
rounds=0 kills=0 in_write=0 restarts=0 rank_changes=0 last_np=0 broken=0 at_end=0
nps=(1 2 1 1 2 1 2 1 1)    # ranks of each run in turn
modes=(0 1 2 1 0 1 2 1)    # how each run is killed (below); the 9th is left to complete
note "kill -9 rounds (seed $seed):"
while :; do
  np=${nps[$((rounds % ${#nps[@]}))]}
  rounds=$((rounds + 1))
  if [ -e "$out/checkpoint.h5" ]; then
    how=(--restart "$out/checkpoint.h5")
    restarts=$((restarts + 1))
    [ "$np" -ne "$last_np" ] && rank_changes=$((rank_changes + 1))
  elif [ -d "$out" ]; then
    how=(--overwrite)
  else
    how=()
  fi
  last_np=$np
  shown=${how[*]:-fresh}
  shown=${shown//"$tmp/"/}
  tmp_before=$(identity "$out/checkpoint.h5.tmp")
  rows_before=$(($(stat -c %s "$out/series.csv" 2> /dev/null || echo 0) / row_bytes))
  mode=${modes[$((rounds - 1))]:-none}
  rows=$((5 + RANDOM % 146))
  extra_ms=$((RANDOM % 31))
  delay_ms=$((RANDOM % 601))
  start "$np" "$tmp/kill.$rounds.log" "$deck" "${common[@]}" --output "$out" "${how[@]}"
  case $mode in
    0)  # some series rows further on, then a few ms
      what="$rows rows on + $extra_ms ms"
      wait_size "$out/series.csv" $(((rows_before + rows) * row_bytes)) && sleep "0.0$(printf %02d "$extra_ms")" ;;
    1)  # some rows further on, then as soon as a checkpoint write begins
      what="$rows rows on, at the next checkpoint write"
      if wait_size "$out/series.csv" $(((rows_before + rows) * row_bytes)); then
        if [ -n "$tmp_before" ]; then  # a killed write's leftover: wait until this run moves it
          while kill -0 "$run_pid" 2> /dev/null && [ -e "$out/checkpoint.h5.tmp" ]; do :; done
        fi
        while kill -0 "$run_pid" 2> /dev/null && [ ! -e "$out/checkpoint.h5.tmp" ]; do :; done
      fi ;;
    2)  # a time after the start: start-up, the resume's rewriting of the output, or the run
      what="$delay_ms ms after the start"
      sleep "$(printf '%d.%03d' $((delay_ms / 1000)) $((delay_ms % 1000)))" ;;
    none) what="not killed" ;;
  esac
  if [ "$mode" != none ] && kill -0 "$run_pid" 2> /dev/null; then
    # shellcheck disable=SC2086
    kill -9 $ranks 2> /dev/null
    finish 30
    reaped
    kills=$((kills + 1))
    state="killed"
    tmp_after=$(identity "$out/checkpoint.h5.tmp")
    if [ -n "$tmp_after" ] && [ "$tmp_after" != "$tmp_before" ]; then
      in_write=$((in_write + 1))
      state="killed during a checkpoint write"
    fi
    [ -e "$out/checkpoint.h5" ] && cp "$out/checkpoint.h5" "$tmp/left/checkpoint.$rounds.h5"
    [ -e "$out/snapshots.h5" ] && cp "$out/snapshots.h5" "$tmp/left/snapshots.$rounds.h5"
    note "  run $rounds, np $np, $shown: $what: $state"
    continue
  fi
  finish 60
  note "  run $rounds, np $np, $shown: $what: ended, exit $rc"
  if [ "$rc" -eq 2 ] && grep -q 'nothing to run' "$tmp/kill.$rounds.log"; then
    # Killed after its last checkpoint (at run.duration) but before run.json: nothing to resume.
    note "  the last kill came after the final checkpoint: --restart has nothing to run, no run.json"
    at_end=1
  elif [ "$rc" -ne 0 ]; then
    fail "kill -9: run $rounds (np $np, $shown) exit $rc"
    show "$tmp/kill.$rounds.log"
    broken=1
  fi
  break
done
note "  $kills kills, $in_write of them during a checkpoint write (this run's checkpoint.h5.tmp there after the kill); $restarts restarts, $rank_changes on another rank count"
if [ "$broken" -eq 0 ]; then
  pass "kill -9: $kills runs killed, $restarts restarts, the last run completed"
  [ "$rank_changes" -ge 1 ] && pass "kill -9: $rank_changes restart(s) on another rank count" ||
    note "kill -9: no restart changed the rank count this time (sections 2 and 3 do)"
  if [ "$at_end" -eq 0 ]; then
    [ ! -e "$out/.dem2d.lock" ] && pass "kill -9: the completed run released the folder" || fail "kill -9: the lock is left"
    queue "kill -9: run.json of the last run" runjson "$out/run.json" interrupted false
  fi
  mapfile -t left < <(ls "$tmp"/left/checkpoint.*.h5 2> /dev/null)
  [ "${#left[@]}" -gt 0 ] && queue "kill -9: every checkpoint.h5 a kill left is whole" checkpoints "${left[@]}"
  mapfile -t left < <(ls "$tmp"/left/snapshots.*.h5 2> /dev/null)
  [ "${#left[@]}" -gt 0 ] && queue "kill -9: every snapshots.h5 a kill left holds complete snapshots only" snapshots "${left[@]}"
  same_as_reference "kill -9" "$out"
  queue "kill -9: the final snapshots.h5 is complete, snapshots.xmf points into it" snapshots_xmf "$out/snapshots.h5" "$out/snapshots.xmf"
fi
run_checks

# ---------------------------------------------------------------------------------------------
# 2. and 3. A signal: every rank stops after the same step and writes its checkpoint, a last
# snapshot and run.json, and says how to resume; the resumed run equals an uninterrupted one.
# Open MPI 4.1's mpirun, given SIGTERM, sends the ranks SIGCONT, waits odls_base_sigkill_timeout
# (1 s by default), sends SIGTERM, waits as long again, sends SIGKILL and exits 1: the ranks run
# on for that time, then have as long to stop. Here it is 2 s, so that a loaded machine still
# stops in time (the kill -9 section covers a stop cut short), and the run under mpirun is given
# a long run.duration: it stops where it is when the signal reaches it, and is resumed to a
# duration just past that point, which an uninterrupted run then simulates too.
signal_test() {  # NAME SIGNAL NP EXPECTED_EXIT RESUME_NP [ARGS...]: ARGS for the first run
  local name=$1 sig=$2 np=$3 expected=$4 resume_np=$5 dir=$tmp/$1 p gone=1 stop until against=$ref _
  shift 5
  start "$np" "$tmp/$name.log" "$deck" "${common[@]}" "$@" --output "$dir"
  if ! wait_size "$dir/series.csv" $((30 * row_bytes)); then
    finish 60
    fail "$name: the run ended (exit $rc) before the signal was sent"
    show "$tmp/$name.log"
    return
  fi
  kill -"$sig" "$run_pid"
  finish 60
  if [ "$hung" -eq 1 ]; then
    fail "$name: still running 60 s after the signal (killed)"
  elif [ "$rc" -eq "$expected" ]; then
    pass "$name: exit status $rc"
  else
    fail "$name: exit $rc, expected $expected"
    show "$tmp/$name.log"
  fi
  for p in $ranks; do
    for _ in $(seq 100); do ours_alive "$p" || break; sleep 0.05; done
    ours_alive "$p" && gone=0
  done
  [ "$gone" -eq 1 ] && pass "$name: every rank stopped ($np of $np)" || fail "$name: a dem2d rank is still running"
  stop=$(sed -n "s/.*SIG$sig: the run stopped at t = \([0-9.e+-]*\) s (step [0-9]*); .*resume with:.*/\1/p" "$tmp/$name.log")
  if [ -n "$stop" ] && grep -qF -- "--restart $dir/checkpoint.h5" "$tmp/$name.log"; then
    pass "$name: the message says where the run stopped (t = $stop s) and how to resume"
  else
    fail "$name: no 'SIG$sig: the run stopped at t = ...; ... resume with: ... --restart $dir/checkpoint.h5'"
    show "$tmp/$name.log"
  fi
  if grep -qE "$crash_pattern" "$tmp/$name.log"; then fail "$name: crash or abort trace"; show "$tmp/$name.log"; fi
  [ ! -e "$dir/checkpoint.h5.tmp" ] && [ ! -e "$dir/.dem2d.lock" ] && pass "$name: no checkpoint.h5.tmp left, the folder released" ||
    fail "$name: checkpoint.h5.tmp or the lock left"
  mkdir -p "$tmp/kept/$name"  # as the signal left them: the resume rewrites run.json
  cp "$dir/run.json" "$dir/checkpoint.h5" "$tmp/kept/$name/" 2> /dev/null
  queue "$name: run.json says the run was interrupted" runjson "$tmp/kept/$name/run.json" interrupted true
  queue "$name: checkpoint.h5 is whole" checkpoints "$tmp/kept/$name/checkpoint.h5"
  [ -n "$stop" ] && [ -e "$dir/checkpoint.h5" ] || return
  until=(--set run.duration=0.4)
  if [ "$#" -gt 0 ]; then  # a long first run: resumed to just past its stop, as is the reference
    until=(--set "run.duration=$(awk -v t="$stop" 'BEGIN { printf "%.2f", (int(t / 0.05) + 2) * 0.05 }')")
    against=$tmp/ref_$name
    run 1 "$tmp/ref_$name.log" "$deck" "${common[@]}" "${until[@]}" --output "$against"
    [ "$rc" -eq 0 ] || { fail "$name: the uninterrupted run to ${until[1]} exit $rc"; return; }
  fi
  run "$resume_np" "$tmp/$name.resume.log" --restart "$dir/checkpoint.h5" "$deck" "${common[@]}" "${until[@]}" --output "$dir"
  if [ "$rc" -eq 0 ]; then
    pass "$name: resumed on $resume_np rank(s) to ${until[1]#run.}"
    same_as_reference "$name" "$dir" "$against"
  else
    fail "$name: the resume exit $rc"
    show "$tmp/$name.resume.log"
  fi
}
OMPI_MCA_odls_base_sigkill_timeout=2 signal_test sigterm_mpirun TERM 2 1 1 --set run.duration=100
signal_test sigint_single INT 1 5 2
run_checks

# ---------------------------------------------------------------------------------------------
# 4. A full disk: a small tmpfs that fills during the run, then room made.
disk_test() {  # NAME NP SIZE ARGS...: a run into a SIZE tmpfs, with ARGS after the common ones
  local name=$1 np=$2 size=$3 dir message kept
  shift 3
  disk=$tmp/disk
  dir=$disk/out
  kept=$tmp/kept/disk$((++disk_cases))  # what is checked, copied off the tmpfs
  mkdir -p "$kept"
  mount -t tmpfs -o "size=$size" tmpfs "$disk" || { fail "$name: cannot mount a $size tmpfs"; disk=""; return; }
  start "$np" "$tmp/$name.log" "$deck" "${common[@]}" "$@" --output "$dir"
  finish 60 "$dir"
  if [ "$hung" -eq 1 ]; then
    fail "$name: hung (its files unchanged for 5 s, still running; killed)"
  elif [ "$rc" -eq 4 ]; then
    pass "$name: exit status 4"
  else
    fail "$name: exit $rc, expected 4"
  fi
  message=$(grep -m1 'error: ' "$tmp/$name.log")
  if grep -qE "error: (cannot write )?$dir/(checkpoint\.h5(\.tmp)?|snapshots\.(h5|xmf)|series\.csv|lifters\.csv|run\.json)[: ].*(No space left|write failed|disk full)" <<< "$message"; then
    message=${message//"$dir/"/}
    pass "$name: the message names the file: ${message:0:110}"
  else
    fail "$name: no message naming the file and the full disk"
    show "$tmp/$name.log"
  fi
  if grep -qE "$crash_pattern" "$tmp/$name.log"; then
    fail "$name: crash or abort trace"
    grep -m4 -E "error: |$crash_pattern|H5" "$tmp/$name.log" | sed 's/^/       | /'
  else
    pass "$name: no crash or abort trace"
  fi
  if [ "$hung" -eq 0 ]; then
    [ ! -e "$dir/.dem2d.lock" ] && pass "$name: the folder released" || fail "$name: the lock is left"
  fi
  if [ -e "$dir/checkpoint.h5" ]; then
    cp "$dir/checkpoint.h5" "$kept/"
    queue "$name: checkpoint.h5 is whole" checkpoints "$kept/checkpoint.h5"
  fi
  if [ -e "$dir/snapshots.h5" ]; then
    cp "$dir/snapshots.h5" "$kept/"
    queue "$name: snapshots.h5 holds complete snapshots only" snapshots "$kept/snapshots.h5"
  fi
  # Room made: the run goes on from its checkpoint (on one rank) to the reference's result.
  if ! mount -o remount,size=16m "$disk"; then
    fail "$name: cannot grow the tmpfs"
  elif [ ! -e "$dir/checkpoint.h5" ]; then
    note "$name: the disk filled before the first checkpoint: nothing to resume"
  else
    reaped
    run 1 "$tmp/$name.resume.log" --restart "$dir/checkpoint.h5" "$deck" "${common[@]}" "$@" --output "$dir"
    if [ "$rc" -eq 0 ]; then
      pass "$name: with room made, --restart on 1 rank finishes the run"
      mkdir -p "$kept/resumed"
      cp "$dir/snapshots.h5" "$dir/series.csv" "$dir/lifters.csv" "$kept/resumed/"
      same_as_reference "$name" "$kept/resumed"
    else
      fail "$name: with room made, --restart exit $rc"
      show "$tmp/$name.resume.log"
    fi
  fi
  umount "$disk" || umount -l "$disk"
  disk=""
}
mkdir -p "$tmp/disk"
disk_cases=0
if [ "$(id -u)" -ne 0 ]; then
  echo "skipped: full disk: not root"
elif ! mount -t tmpfs -o size=1m tmpfs "$tmp/disk" 2> /dev/null; then
  echo "skipped: full disk: cannot mount a tmpfs"
else
  umount "$tmp/disk"
  # The size decides what meets the full disk first (a run writes the same bytes every time;
  # dem2d refuses a collective write when less than twice its size is free): with today's
  # output a snapshot or a checkpoint, after some checkpoints were written.
  dense=(--set output.snapshot_interval=0.01)
  sparse=(--set output.snapshot_interval=0.005 --set output.checkpoint_interval=0.02)
  disk_test "full disk np1 500k" 1 500k "${dense[@]}"
  disk_test "full disk np1 700k" 1 700k "${dense[@]}"
  disk_test "full disk np1 600k" 1 600k "${sparse[@]}"
  disk_test "full disk np2 700k" 2 700k "${dense[@]}"
  disk_test "full disk np2 600k" 2 600k "${sparse[@]}"
  run_checks
fi

# ---------------------------------------------------------------------------------------------
# 5. The semaphores of OMPIO's shared file pointer, left locked by a killed run.
# semaphore lock|value NAME: creates the named semaphore NAME locked (value 0) or only reads
# it; prints its value.
semaphore() {
  "$py" - "$1" "$2" << 'PY'
import ctypes, os, sys
libc = ctypes.CDLL(None, use_errno=True)
libc.sem_open.restype = ctypes.c_void_p
mode, name = sys.argv[1], sys.argv[2].encode()
sem = libc.sem_open(name, os.O_CREAT, 0o644, 1) if mode == "lock" else libc.sem_open(name, 0)
if sem in (None, ctypes.c_void_p(-1).value):
    sys.exit(f"sem_open {sys.argv[2]}: {os.strerror(ctypes.get_errno())}")
if mode == "lock":
    libc.sem_trywait(ctypes.c_void_p(sem))
value = ctypes.c_int(-1)
libc.sem_getvalue(ctypes.c_void_p(sem), ctypes.byref(value))
print(value.value)
PY
}
semaphores_locked=1
for name in /OMPIO_checkpoint.h5.tmp /OMPIO_snapshots.h5; do
  [ -e "/dev/shm/sem.${name#/}" ] || planted+=("$name")
  value=$(semaphore lock "$name" 2>&1)
  [ "$value" = 0 ] || { semaphores_locked=0; note "cannot plant $name locked: $value"; }
done
if [ "$semaphores_locked" -eq 0 ]; then
  echo "skipped: locked MPI-IO semaphores: no POSIX named semaphores here"
else
  for np in 1 2; do
    name="locked semaphores np$np"
    dir=$tmp/semaphores$np
    start "$np" "$tmp/semaphores$np.log" "$deck" "${common[@]}" --output "$dir"
    finish 60 "$dir"
    if [ "$hung" -eq 1 ]; then
      fail "$name: hung (its files unchanged for 5 s; killed)"
      show "$tmp/semaphores$np.log"
    elif [ "$rc" -eq 0 ]; then
      pass "$name: exit status 0 with checkpoint.h5.tmp's and snapshots.h5's semaphores locked"
      same_as_reference "$name" "$dir"
    else
      fail "$name: exit $rc, expected 0"
      show "$tmp/semaphores$np.log"
    fi
  done
  still=$(for name in /OMPIO_checkpoint.h5.tmp /OMPIO_snapshots.h5; do semaphore value "$name" 2>&1; done | tr '\n' ' ')
  [ "$still" = "0 0 " ] && pass "locked semaphores: left as they were (values $still)" ||
    fail "locked semaphores: the runs touched them (values $still)"
  export OMPI_MCA_io=ompio
  start 2 "$tmp/semaphores_ompio.log" "$deck" "${common[@]}" --output "$tmp/semaphores_ompio"
  unset OMPI_MCA_io
  finish 60 "$tmp/semaphores_ompio"
  if [ "$hung" -eq 1 ]; then
    note "control: the same run with OMPI_MCA_io=ompio hangs on the locked semaphore (killed)"
  else
    note "control: the same run with OMPI_MCA_io=ompio did not hang (exit $rc): no such trap here"
  fi
  run_checks
fi

echo "faults: $failures failure(s)"
[ "$failures" -eq 0 ]
