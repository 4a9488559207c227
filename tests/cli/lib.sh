# shellcheck shell=bash
# Helpers for the command-line tests, sourced by cli_tests.sh and restart_tests.sh: one line per
# check (pass/fail, counted in $failures), expect (a command's exit status and message) and a
# small pool of background jobs. They hold under `set -euo pipefail` as under the scripts' `set -u`.

failures=0

# pass NAME / fail WHY: one line per check; fail counts it.
pass() { echo "ok   $1"; }
fail() {
  echo "FAIL $1"
  failures=$((failures + 1))
}

# first_lines N: the first N lines of stdin. sed reads its input to the end, so the writer never
# gets SIGPIPE as it can with head (which pipefail would take for an error).
first_lines() { sed -n "1,$1p"; }

# expect NAME CODE PATTERN -- COMMAND...: COMMAND exits with CODE, its stdout+stderr has a line
# matching PATTERN (grep -E: ^ anchors at the start of a line) and no crash or abort trace.
expect() { expect_output lines "$@"; }

# expect_joined NAME CODE PATTERN -- COMMAND...: expect, with the output's lines joined by spaces
# first, so that PATTERN may span a message of several lines.
expect_joined() { expect_output joined "$@"; }

# expect_output lines|joined NAME CODE PATTERN -- COMMAND...: expect and expect_joined. On a
# failure the first lines of the output (as matched) follow the FAIL line.
expect_output() {
  local mode=$1 name=$2 code=$3 pattern=$4
  shift 5
  local out got=0 why=""
  out=$("$@" 2>&1) || got=$?
  if [ "$mode" = joined ]; then out=$(tr '\n' ' ' <<<"$out"); fi
  if [ "$got" -ne "$code" ]; then
    why="exit $got, expected $code"
  elif ! grep -qE -- "$pattern" <<<"$out"; then
    why="output lacks /$pattern/"
  elif grep -qE 'MPI_ABORT|Segmentation|core dumped|terminate called|Aborted' <<<"$out"; then
    why="crash or abort trace"
  fi
  if [ -z "$why" ]; then pass "$name"; return 0; fi
  fail "$name: $why"
  first_lines 5 <<<"$out"
}

# --- A pool of background jobs -------------------------------------------------------------------
# Most of a case's time is MPI start-up and shut-down, not work on the cores, so independent cases
# run side by side. A job is a command (usually a function) run in a subshell, in a folder of its
# own (a deck's default output folder is relative), with its own log and failure count. The logs
# are printed in the order the jobs were started, each once it and all before it have ended: the
# log reads the same however the jobs interleave, and a test killed midway (a timeout) still shows
# the jobs that ended. Cases that share a folder or read another's output must be one job.
job_max=${DEM2D_TEST_JOBS:-3}
job_dir=""
job_names=()
job_printed=0  # the jobs whose logs have been printed, the first ones

# job_init DIR: the jobs' folders, logs and results go under DIR (created).
job_init() {
  job_dir=$1
  mkdir -p "$job_dir"
}

# job_path INDEX: where the job started INDEX-th keeps its files (INDEX.d/, .log, .result, .done).
job_path() { printf '%s/%03d' "$job_dir" "$1"; }

# job NAME COMMAND...: start COMMAND as a job once fewer than $job_max jobs run. Its result file,
# "FAILURES SECONDS", is written only when COMMAND returns (a job that dies leaves none); its
# .done file when it ends.
job() {
  local name=$1 id
  shift
  while [ "$(jobs -pr | wc -l)" -ge "$job_max" ]; do
    wait -n || true
    job_print_ended
  done
  id=$(job_path "${#job_names[@]}")
  job_names+=("$name")
  mkdir -p "$id.d"
  (
    trap 'touch "$id.done"' EXIT
    cd "$id.d" || exit
    failures=0  # the job's own count, which job_print adds up
    start=$SECONDS
    "$@"
    echo "$failures $((SECONDS - start))" >"$id.result"
  ) >"$id.log" 2>&1 &
}

# job_print INDEX: the job's log under a line with its name and time; its failures are added to
# $failures, and a job without a result counts as one.
job_print() {
  local id n="" secs="?"
  id=$(job_path "$1")
  if [ -s "$id.result" ]; then read -r n secs <"$id.result"; fi
  echo "--- ${job_names[$1]} (${secs} s)"
  cat "$id.log"
  if [ -n "$n" ]; then
    failures=$((failures + n))
  else
    fail "${job_names[$1]}: the job stopped before its end"
  fi
}

# job_print_ended: print the jobs not printed yet, in order, up to the first one still running.
job_print_ended() {
  while [ "$job_printed" -lt "${#job_names[@]}" ] && [ -e "$(job_path "$job_printed").done" ]; do
    job_print "$job_printed"
    job_printed=$((job_printed + 1))
  done
}

# job_stop: stop the jobs still running, so that a script stopped midway starts no more cases (a
# run under way goes on to its end). For the script's EXIT trap.
job_stop() {
  local pids
  read -ra pids <<<"$(jobs -pr | tr '\n' ' ')"
  if [ "${#pids[@]}" -gt 0 ]; then kill "${pids[@]}" 2>/dev/null || true; fi
}

# job_results: wait for every job and print the logs not printed yet (a job killed outright has
# no .done file, but has ended now).
job_results() {
  wait || true
  while [ "$job_printed" -lt "${#job_names[@]}" ]; do
    job_print "$job_printed"
    job_printed=$((job_printed + 1))
  done
}
