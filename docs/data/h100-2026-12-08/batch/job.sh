tar xzf .gpu/bins.tgz -C .gpu
R=./.gpu/run.sh
N=./.gpu/texflow-N
P=./.gpu/texflow-P
GX="--set collisions.detection=exact --set collisions.cell=0.016"
$N info > $OUT/res/info.txt 2>&1
mkdir -p $OUT/res/ab $OUT/res/cell $OUT/res/passes
# A/B: main (N) against the batched walk (P) with 2, 4 and 8 positions fetched ahead, 2 rounds
for round in 1 2; do
  for v in N P2 P4 P8; do
    case $v in N) B=$N; unset TEXFLOW_WALK_BATCH;; P*) B=$P; export TEXFLOW_WALK_BATCH=${v#P};; esac
    for s in dem drop dam spin; do
      $R ab/${s}_${v}_$round $B bench scene $s --sizes 256,1024 --repeats 5 --warmup 2 --json -q
    done
    $R ab/gasx_${v}_$round $B bench scene gas --sizes 256,1024 --repeats 5 --warmup 2 --json -q $GX
  done
done
unset TEXFLOW_WALK_BATCH
# gas exact at 1024² on finer cells (radius 2 mm: 2r = 4 mm)
for c in 0.016 0.012 0.008 0.006 0.004; do
  $R cell/gasx_N_$c $N bench scene gas --sizes 1024 --repeats 5 --warmup 2 --json -q --set collisions.detection=exact --set collisions.cell=$c
  TEXFLOW_WALK_BATCH=4 $R cell/gasx_P4_$c $P bench scene gas --sizes 1024 --repeats 5 --warmup 2 --json -q --set collisions.detection=exact --set collisions.cell=$c
done
for s in drop dem; do
  $R passes/N_$s $N bench passes $s --particles 256 --repeats 5
  TEXFLOW_WALK_BATCH=4 $R passes/P4_$s $P bench passes $s --particles 256 --repeats 5
done
