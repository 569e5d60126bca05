#!/usr/bin/env bash
# llvmpipe: bench scene of every built-in at 32^2, a6632bd against the head, 7 interleaved rounds.
cd "$(git rev-parse --show-toplevel)"
O=${OLD:?release binary of a6632bd}; N=${NEW:-target/release/texflow}; D=${DIR:-/tmp/bench_scene_32}; mkdir -p $D
for r in 1 2 3 4 5 6 7; do
  for s in $($N scene list | awk '{print $1}'); do
    for v in old new; do bin=$N; [ $v = old ] && bin=$O
      timeout 120 $bin bench scene $s --sizes 32 --repeats 5 --warmup 2 --json -q > $D/${s}_${v}_$r.json 2>$D/${s}_${v}_$r.err || echo "$s $v $r failed"
    done
  done
done
echo ALLDONE
