#!/usr/bin/env bash
# run.sh NAME command... : output into $OUT/res/NAME.txt, wall time into _times.txt
name=$1; shift
s=$(date +%s%N)
timeout ${CMD_LIMIT:-590} "$@" > $OUT/res/$name.txt 2>&1
rc=$?
e=$(date +%s%N)
echo "$name rc=$rc $(( (e - s) / 1000000 )) ms" >> $OUT/res/_times.txt
