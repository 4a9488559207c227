#!/bin/bash
# Rotating-drum variant (flowing bed). usage: ./run_drum.sh [nsteps]   (env ONLY="sphere|sq22" to restrict)
set -e
cd "$(dirname "$0")"
LMP=${LMP:?set LMP to a LIGGGHTS 3.8 binary built with superquadrics (see README.md)}
NSTEPS=${1:-5000}; N=${N:-1000}; PERIOD=${PERIOD:-2.0}
[[ -f drum.stl ]] || python3 make_drum_stl.py drum.stl
source shapes.sh
for s in "${SHAPES[@]}"; do
  IFS='|' read -r tag astyle shape surf orient integ erot a b c n1 n2 <<< "$s"
  [[ -n $ONLY && ! $tag =~ ^($ONLY)$ ]] && continue
  rm -f cpustamp_drum_$tag.txt
  $LMP -in drum_run.in -screen screen.drum_$tag -var tag $tag -var astyle $astyle -var shape $shape \
      -var surf "$surf" -var orient "$orient" -var integrator "$integ" -var erot $erot \
      -var a $a -var b $b -var c $c -var n1 $n1 -var n2 $n2 -var N $N -var period $PERIOD -var nsteps $NSTEPS > /dev/null
done
/usr/bin/python3 parse.py > results.csv
