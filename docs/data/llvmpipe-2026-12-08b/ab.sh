#!/bin/bash
# Every built-in at 32² and 64² (`bench scene NAME --sizes 32,64 --repeats 5 --json -q`), the
# binaries alternating scene by scene, ROUNDS rounds.
# Usage: BINS_DIR=/tmp/bins bash ab.sh OUT ROUNDS N F   (runs $BINS_DIR/texflow-N, texflow-F)
OUTD=$1; shift; ROUNDS=$1; shift; BINS="$@"
BINS_DIR=${BINS_DIR:-/tmp/bins}
mkdir -p "$OUTD"
for r in $(seq 1 "$ROUNDS"); do
for n in fire fire-points snow fountain smoke smoke-unlit e1 e2 e3 collide gas mesh cloth hair spin fireworks dem flicker dam drop; do
  for b in $BINS; do
    mkdir -p "$OUTD/$b/r$r"
    "$BINS_DIR/texflow-$b" bench scene $n --sizes 32,64 --repeats 5 --json -q \
      > "$OUTD/$b/r$r/$n.json" 2> "$OUTD/$b/r$r/$n.err"
    echo "$r $b $n rc=$?" >> "$OUTD/log"
  done
done
done
echo done >> "$OUTD/log"
