#!/bin/bash
# Run the QDYN RSF spring-block tutorial (RNS_LAW=2, TMAX=300) for several solvers/accuracies.
# Each case is run twice: with the stock build (qdyn/src/qdyn: CPU time, stock 8-digit output)
# and with the output-format-only build (qdyn_hp/src/qdyn: 17-digit output_ot_0, used for events).
# usage: run_all.sh   (from anywhere)
set -u
R=/work/qdyn_ref
MKIN=$R/scripts/mkin_qdyn.sh
CASES="2:1e-6 2:1e-7 2:1e-8 2:1e-9 2:1e-10 2:1e-11 2:2e-12 2:1.001e-12 2:1e-12
1:1e-6 1:1e-8 1:1e-10 1:1e-11 1:1e-12 1:1e-13 1:1e-14
3:1e-8 3:1e-10 3:1e-12"
for c in $CASES; do
  s=${c%%:*}; a=${c#*:}
  for build in stock hp; do
    if [ $build = stock ]; then exe=$R/qdyn/src/qdyn; else exe=$R/qdyn_hp/src/qdyn; fi
    d=$R/runs/$build/s${s}_acc$a
    rm -rf $d; $MKIN $d 2 $a $s 300
    ( cd $d && /usr/bin/time -v $exe > stdout.txt 2> time.txt; echo $? > rc )
    rm -f $d/output_ox   # snapshot file, not used
    ut=$(awk -F': ' '/User time/{print $2}' $d/time.txt); st=$(awk -F': ' '/System time/{print $2}' $d/time.txt)
    echo "$build solver=$s acc=$a rc=$(cat $d/rc) user=$ut sys=$st rows=$(grep -vc '^#' $d/output_ot_0 2>/dev/null)"
  done
done
