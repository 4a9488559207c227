#!/bin/sh
# usage (from a LIGGGHTS input): shell ./cpustamp.sh LABEL FILE
# appends "LABEL utime_ticks stime_ticks ticks_per_s" of the nearest ancestor process named liggghts
p=$$
while [ "$p" -gt 1 ]; do
  c=$(cat /proc/$p/comm 2>/dev/null)
  if [ "$c" = "liggghts" ]; then
    echo "$1 $(awk '{print $14, $15}' /proc/$p/stat) $(getconf CLK_TCK)" >> "$2"; exit 0
  fi
  p=$(awk '{print $4}' /proc/$p/stat)
done
echo "$1 nan nan nan" >> "$2"
