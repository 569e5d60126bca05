#!/usr/bin/env bash
# llvmpipe A/B: N (ef0784a) against Q (eeccc45), the collision stage, alternating rounds
cd /tmp/lp
GX="--set collisions.detection=exact --set collisions.cell=0.016"
for round in 1 2; do
  for b in N Q; do
    B=/tmp/lp/texflow-$b
    for s in dem drop spin; do
      $B bench scene $s --sizes 64,128 --repeats 3 --warmup 1 --json -q > ${s}_${b}_$round.txt 2>&1
    done
    $B bench scene gas --sizes 64,128 --repeats 3 --warmup 1 --json -q $GX > gasx_${b}_$round.txt 2>&1
  done
done
echo DONE
