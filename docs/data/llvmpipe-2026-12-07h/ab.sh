#!/usr/bin/env bash
# ab.sh F H OUT : the partner mask's A/B on llvmpipe, binaries F (each partner worked as visited)
# and H (PARTNER_MASK) alternating, three rounds; one JSON file per run.
F=$1; H=$2; OUT=$3; mkdir -p $OUT
GX="--set collisions.detection=exact --set collisions.radius=0.02 --set collisions.cell=0.04"
for round in 1 2 3; do
  for b in F H; do
    bin=${!b}
    $bin bench scene gas --sizes 256 --repeats 3 --warmup 1 --json $GX -q > $OUT/gasx_${b}_$round.txt
    for s in drop dam dem spin; do
      $bin bench scene $s --sizes 64,128 --repeats 5 --warmup 2 --json -q > $OUT/${s}_${b}_$round.txt
    done
  done
done
