#!/usr/bin/env bash
# JOB_LIMIT=N bash .gpu/all.sh JOB : unpacks NVIDIA's GL loaders, runs JOB under a limit, packs res/
for f in .gl/*.deb; do dpkg -x $f / ; done; ldconfig
export __EGL_VENDOR_LIBRARY_FILENAMES=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
mkdir -p $OUT/res
chmod +x .gpu/run.sh .gpu/texflow-* 2>/dev/null
(nvidia-smi --query-gpu=timestamp,clocks.sm,clocks.mem,temperature.gpu,utilization.gpu --format=csv -lms 1000 > $OUT/res/_smi.txt 2>&1 &)
export OUT
timeout ${JOB_LIMIT:-540} bash "$1"
echo "job rc=$?" >> $OUT/res/_times.txt
pkill nvidia-smi
tar czf $OUT/results.tgz -C $OUT res
cat $OUT/res/_times.txt
