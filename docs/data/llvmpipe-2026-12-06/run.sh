#!/usr/bin/env bash
# llvmpipe: Table 2 at 64^2: a6632bd (constants as program state) / head (cache on) / head (cache off); 5 interleaved rounds.
cd "$(git rev-parse --show-toplevel)"
O=${OLD:?release binary of a6632bd}; N=${NEW:-target/release/texflow}
for r in 1 2 3 4 5; do
  for v in old new nocache; do bin=$N; extra=""; [ $v = old ] && bin=$O; [ $v = nocache ] && extra="--uniform-cache off"
    $bin bench scenes --sizes 64 --repeats 5 --json -q $extra > docs/data/llvmpipe-2026-12-06/t2_${v}_$r.json 2>docs/data/llvmpipe-2026-12-06/t2_${v}_$r.err; echo "t2 $v $r rc=$?"
  done
done
