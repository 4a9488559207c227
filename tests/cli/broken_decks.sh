#!/usr/bin/env bash
# The broken-deck catalogue (tests/cli/broken/*.in): every deck is bad input of one kind, and
# dem2d must say so on 1 and on 3 ranks alike. Usage: broken_decks.sh PATH/TO/dem2d SOURCE_DIR
# [NAME_PATTERN]  (a pattern runs only the decks whose name matches, e.g. 'csv_*').
#
# A deck's first line is "# expect: REGEX", the message it must give (grep -E). Optional
# header lines that follow: "# args: OPTIONS" (command-line options given before the deck,
# split at spaces) and "# location: file" (the message is about the deck as a whole, so it
# has no line). For every deck, at 1 rank and at 3 ranks (mpirun -np 3 --oversubscribe):
#   - the exit status is 2, within 60 s;
#   - stdout+stderr has a line matching REGEX, and that line starts with where the error is:
#     FILE:LINE: or FILE:LINE:COL: (the deck or a CSV file), "--set ...:" or "--output ...:"
#     for an option, or FILE: with "# location: file"; and, unless an option is the location,
#     its message names a key: a dotted path (run.duration, fill[0].file), an element
#     (particle[1]), a quoted key or column ('titel'), a table ([[fill]]), a top-level key
#     (title = 5), or for a TOML syntax error the line and its table ("(in [run]: ...)");
#   - no crash or abort: no 'MPI_ABORT', 'Segmentation', 'core dumped', 'terminate called',
#     'Aborted', 'internal error', and none of Open MPI's abort banners;
#   - stdout+stderr on 3 ranks is the same as on 1 rank, once mpirun's own notice that a rank
#     exited with a non-zero status (its normal report of exit status 2) is taken out.
set -u
dem2d=$(realpath "$1")
src=$(realpath "$2")
pattern=${3:-*}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
# mpirun waits this long between SIGTERM and SIGKILL once a rank has exited non-zero (1 s by
# default): every rank has exited by then, so the wait only slows the catalogue down.
export OMPI_MCA_odls_base_sigkill_timeout=0
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
export dem2d tmp

# mpirun's report that a rank exited non-zero: the blocks between dashed lines that say so.
strip_mpirun_notice() {
  awk '/^-+$/ && length($0) >= 20 { if (inblock) { if (block !~ /terminated normally, but|exited with non-zero status/) printf "%s%s\n", block, $0; inblock = 0; block = "" } else { inblock = 1; block = $0 "\n" } next }
       inblock { block = block $0 "\n"; next }
       { print }
       END { if (inblock) printf "%s", block }'
}
export -f strip_mpirun_notice

# check_deck DECK: writes "ok NAME" or "FAIL NAME: why" (and the output) to $tmp/result/NAME.
check_deck() {
  local deck=$1 name
  name=$(basename "$deck" .in)
  local work=$tmp/work/$name result=$tmp/result/$name
  mkdir -p "$work"
  local expect args location=line
  expect=$(sed -n '1s/^# expect: //p' "$deck")
  args=$(sed -n '2,3s/^# args: //p' "$deck")
  grep -q '^# location: file$' "$deck" && location=file
  local -a argv=()
  [ -n "$args" ] && read -ra argv <<< "$args"
  [[ " $args " == *" --output "* ]] || argv+=(--output "$work/out")
  if [ -z "$expect" ]; then echo "FAIL $name: no '# expect: REGEX' first line" > "$result"; return; fi
  local where='^(.*\.(in|csv):[0-9]+(:[0-9]+)?|--set .*|--output .*): error: '
  local key="([a-z_]+(\\[[0-9]+\\])?\\.[a-z_]+|[a-z_]+\\[[0-9]+\\]|'[a-z_]+'|\\[\\[?[a-z_.]+\\]\\]?|^[a-z_]+ = |\\((in \\[|the line: ))"
  [ "$location" = file ] && where='^.*\.in: error: '
  local np code out why=""
  for np in 1 3; do
    if [ "$np" = 1 ]; then
      (cd "$work" && timeout 60 "$dem2d" --quiet "${argv[@]}" "$deck") > "$work/raw$np" 2>&1
    else
      (cd "$work" && timeout 60 mpirun -np 3 --oversubscribe "$dem2d" --quiet "${argv[@]}" "$deck") \
        > "$work/raw$np" 2>&1
    fi
    code=$?
    out=$(strip_mpirun_notice < "$work/raw$np")
    printf '%s\n' "$out" > "$work/out$np"
    if [ "$code" -ne 2 ]; then why="np$np: exit $code, expected 2"; break; fi
    if grep -qE 'MPI_ABORT|Segmentation|core dumped|terminate called|Aborted|internal error|mpirun has exited due to process rank|prterun has exited|MPI_ABORT was invoked' "$work/raw$np"; then
      why="np$np: crash or abort trace"; break
    fi
    local line
    line=$(grep -E -m1 -- "$expect" "$work/out$np")
    if [ -z "$line" ]; then why="np$np: no line matches /$expect/"; break; fi
    if ! grep -qE -- "$where" <<< "$line"; then why="np$np: the message does not start with its location: $line"; break; fi
    if [[ "$line" != --* ]] && ! grep -qE -- "$key" <<< "${line#*: error: }"; then
      why="np$np: the message names no key: $line"; break
    fi
  done
  if [ -z "$why" ] && ! cmp -s "$work/out1" "$work/out3"; then why="the output on 3 ranks differs from 1 rank"; fi
  if [ -z "$why" ]; then
    echo "ok   $name" > "$result"
  else
    { echo "FAIL $name: $why"; sed 's/^/       | /' "$work/raw${np:-1}" | head -12; } > "$result"
  fi
}
export -f check_deck

mkdir -p "$tmp/result"
shopt -s nullglob
decks=("$src"/tests/cli/broken/$pattern.in)
if [ "${#decks[@]}" -eq 0 ]; then echo "no deck matches $pattern"; exit 1; fi
# Sixteen at a time: a run mostly waits on MPI start-up and shut-down, not on the cores.
printf '%s\0' "${decks[@]}" | xargs -0 -n 1 -P 16 bash -c 'check_deck "$0"'
failures=0
for deck in "${decks[@]}"; do
  name=$(basename "$deck" .in)
  if [ -f "$tmp/result/$name" ]; then cat "$tmp/result/$name"; else echo "FAIL $name: not run"; fi
  grep -q '^ok ' "$tmp/result/$name" 2> /dev/null || failures=$((failures + 1))
done
echo "broken decks: ${#decks[@]} decks, $failures failure(s)"
[ "$failures" -eq 0 ]
