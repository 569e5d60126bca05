#!/bin/bash
# The sorted scenes only (their sort keys and gather), as ab.sh: bash ab_sorted.sh OUT ROUNDS F G
OUTD=$1; shift; ROUNDS=$1; shift; BINS="$@"
mkdir -p $OUTD
for r in $(seq 1 $ROUNDS); do
for n in smoke smoke-unlit e3 dem dam drop; do
  for b in $BINS; do
    mkdir -p $OUTD/$b/r$r
    ${BINS_DIR:-/tmp/bins}/texflow-$b bench scene $n --sizes 32,64 --repeats 5 --json -q > $OUTD/$b/r$r/$n.json 2> $OUTD/$b/r$r/$n.err
    echo "$r $b $n rc=$?" >> $OUTD/log
  done
done
done
echo done >> $OUTD/log
