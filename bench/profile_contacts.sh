#!/usr/bin/env bash
# profile_contacts.sh: where the time per contact goes, counted by valgrind's cachegrind
# (instructions, simulated D1 and LL misses, branch mispredictions) for
#   block   the dense sliding block of bench/throughput (inputs/waterfall_polygon.in, 240 balls,
#           in a circular shell), after 2 s untimed;
#   drum30k the settled 30 000-sphere drum of bench/throughput (cached packing
#           bench/results/cache/settled_drum_30000.csv: run build/bench/throughput --sections drum
#           --particles 30000 once), after 500 untimed steps.
# `perf stat` has no hardware counters on this VM, hence the simulation; valgrind 3.19 cannot
# decode AVX-512, hence an AVX2 build with line tables:
#   cmake -S . -B build-v3 -DCMAKE_BUILD_TYPE=Release -DDEM2D_NATIVE=OFF \
#         -DCMAKE_CXX_FLAGS="-march=x86-64-v3 -g" && cmake --build build-v3 -j2 --target throughput
#
# Each scene runs twice under `valgrind --tool=cachegrind --cache-sim=yes --branch-sim=yes`,
# `throughput --profile-block STEPS` / `--profile-drum 30000 STEPS` with two step counts
# (block: 5 000 and 205 000 steps, i.e. 2 s of the block, whose contacts swing with its rocking
# (1.17 contacts per particle over its first 0.25 s, 1.79 over 5 s); drum: 20 and 120); the
# difference of the two runs is the cost
# of the extra steps alone (set-up, reading the packing and warm-up cancel, as both runs are the
# same deterministic run up to the shorter one's end). The program prints the particle-steps and
# contact-steps (particle-particle plus wall contacts summed over the steps) of its profiled
# steps, so the differences give events per particle-step and per contact. Functions: the
# per-function difference (cg_diff of the two runs, read by post/profile_contacts.py).
#
# Output: a printed table, bench/results/profile_contacts.csv (--csv FILE) and the raw
# cachegrind files, the programs' lines, cg_diff and cg_annotate listings in OUT
# (--out DIR, default /tmp/profile_contacts). Takes about 15 minutes.
#
#   bench/profile_contacts.sh [--build DIR] [--out DIR] [--csv FILE] [--scenes block,drum30k]
#                             [--block-steps S1,S2] [--drum-steps S1,S2] [--ll SIZE,WAYS,LINE]
set -euo pipefail
cd "$(dirname "$0")/.."
build=build-v3
out=/tmp/profile_contacts
csv=bench/results/profile_contacts.csv
scenes=block,drum30k
block_steps=5000,205000
drum_steps=20,120
# cachegrind takes I1 and D1 from cpuid (here 32 KiB 8-way and 48 KiB 12-way) but guessed the
# last level as 512 MiB 2-way on this VM (no LL miss at all): the LL is set to the 32 MiB
# 16-way L3 of the machine (the 1 MiB L2 between them is not simulated).
ll=33554432,16,64
while [ $# -gt 0 ]; do
  case "$1" in
    --build) build=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    --csv) csv=$2; shift 2 ;;
    --scenes) scenes=$2; shift 2 ;;
    --block-steps) block_steps=$2; shift 2 ;;
    --drum-steps) drum_steps=$2; shift 2 ;;
    --ll) ll=$2; shift 2 ;;
    -h|--help) sed -n '2,36p' "$0"; exit 0 ;;
    *) echo "profile_contacts.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
bin=$build/bench/throughput
if [ ! -x "$bin" ]; then
  echo "profile_contacts.sh: $bin missing (build it as the header says)" >&2
  exit 1
fi
mkdir -p "$out"
valgrind --version > "$out/valgrind_version.txt"
args=()
for scene in ${scenes//,/ }; do
  case "$scene" in
    block) steps=$block_steps; mode=(--profile-block) ;;
    drum30k) steps=$drum_steps; mode=(--profile-drum 30000) ;;
    *) echo "profile_contacts.sh: unknown scene $scene" >&2; exit 2 ;;
  esac
  for s in ${steps//,/ }; do
    base=$out/${scene}_$s
    echo "== $scene, $s profiled steps: valgrind --tool=cachegrind ... $bin ${mode[*]} $s"
    valgrind --tool=cachegrind --cache-sim=yes --branch-sim=yes --LL="$ll" \
      --cachegrind-out-file="$base.cg.out" "$bin" "${mode[@]}" "$s" > "$base.txt" 2> "$base.log"
    cat "$base.txt"
  done
  lo=${steps%%,*}
  hi=${steps##*,}
  cg_diff "$out/${scene}_$lo.cg.out" "$out/${scene}_$hi.cg.out" > "$out/${scene}.diff.cg.out"
  cg_annotate --auto=no "$out/${scene}.diff.cg.out" > "$out/${scene}.annotate.txt"
  args+=("$scene" "$out/${scene}_$lo" "$out/${scene}_$hi")
done
/usr/bin/python3 post/profile_contacts.py --csv "$csv" "${args[@]}" | tee "$out/table.txt"
