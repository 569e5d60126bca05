#!/usr/bin/env bash
# gpu_job.sh F H OUT : the partner mask's A/B on a GPU, the same files as ab.sh for ab.py.
# F: a build of cccf91f (each partner worked as visited); H: a build of cfdf7fb (every walk
# deferred, the forces included) or of main (the count deferred, the forces as visited).
# `gas` exact at 1024² with a cell of 16 mm (radius 8 mm), two alternating rounds; then the
# collision and fluid scenes at 256² and 1024².
F=$1; H=$2; OUT=$3; mkdir -p "$OUT"
GX="--set collisions.detection=exact --set collisions.cell=0.016"
for round in 1 2; do
  for b in F H; do
    ${!b} bench scene gas --sizes 1024 --repeats 5 --warmup 2 --json $GX -q > "$OUT/gasx_${b}_$round.txt"
  done
done
for s in drop dem spin dam; do
  for b in F H; do
    ${!b} bench scene $s --sizes 256,1024 --repeats 5 --warmup 2 --json -q > "$OUT/${s}_${b}_1.txt"
  done
done
