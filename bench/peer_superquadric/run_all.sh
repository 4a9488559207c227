#!/bin/bash
# Re-run the LIGGGHTS superquadric-vs-sphere cost measurement.
# usage: ./run_all.sh [settle|measure|all] [nreps] [nsteps]
# LMP: binary built with superquadric support (Debian's /usr/bin/liggghts lacks atom_style superquadric)
set -e
cd "$(dirname "$0")"
LMP=${LMP:?set LMP to a LIGGGHTS 3.8 binary built with superquadrics (see README.md)}
WHAT=${1:-all}; NREP=${2:-3}; NSTEPS=${3:-3000}; N=${N:-1000}
source shapes.sh
run_settle() {
  IFS='|' read -r tag astyle shape surf orient integ erot a b c n1 n2 <<< "$1"
  $LMP -in settle.in -screen screen.settle_$tag -var tag $tag -var astyle $astyle -var shape $shape \
      -var surf "$surf" -var orient "$orient" -var integrator "$integ" -var erot $erot \
      -var a $a -var b $b -var c $c -var n1 $n1 -var n2 $n2 -var N $N -var extra 30000 > /dev/null
}
run_measure() {   # $1 shape line, $2 rep, $3 optional binary (default $LMP), $4 optional log tag
  IFS='|' read -r tag astyle shape surf orient integ erot a b c n1 n2 <<< "$1"
  # process CPU time (user+sys) is recorded too: the machine is shared, LIGGGHTS "Loop time" is wall-clock
  /usr/bin/time -f "%U %S %e" -o cputime_${4:-$tag}_r$2.txt \
  ${3:-$LMP} -in measure.in -screen none -var tag ${4:-$tag} -var rtag $tag -var surf "$surf" -var integrator "$integ" \
      -var nsteps ${5:-$NSTEPS} -var rep $2 > /dev/null
}
if [[ $WHAT == settle || $WHAT == all ]]; then
  for s in "${SHAPES[@]}"; do
    [[ -n $ONLY && ! ${s%%|*} =~ ^($ONLY)$ ]] && continue   # ONLY="sq22|ell2" restricts shapes
    run_settle "$s"; done
fi
if [[ $WHAT == measure || $WHAT == all ]]; then
  # rep 0 = zero-step run: process CPU overhead (startup, read_restart, contact dump) to subtract
  for i in 0 1 2 3; do run_measure "${SHAPES[$i]}" 0 "" "" 0; done
  run_measure "${SHAPES[0]}" 0 /usr/bin/liggghts sphere_debbin 0
  for r in $(seq 1 $NREP); do
    # alternate order each repetition
    if (( r % 2 )); then order=(0 1 2 3); else order=(3 2 1 0); fi
    for i in "${order[@]}"; do run_measure "${SHAPES[$i]}" $r; done
    # cross-check: same sphere restart with the Debian binary (no SQ support, different build flags)
    run_measure "${SHAPES[0]}" $r /usr/bin/liggghts sphere_debbin
  done
fi
/usr/bin/python3 parse.py > results.csv
cat results.csv
