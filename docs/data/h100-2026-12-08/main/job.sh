tar xzf .gpu/bins.tgz -C .gpu
R=./.gpu/run.sh
N=./.gpu/texflow-N
Q=./.gpu/texflow-Q
F=./.gpu/texflow-R
GX="--set collisions.detection=exact --set collisions.cell=0.016"
$F info > $OUT/res/info.txt 2>&1
mkdir -p $OUT/res/sweep $OUT/res/ab $OUT/res/passes $OUT/res/fire
for round in 1 2; do
  for b in Q R; do
    $R fire/fire_${b}_$round ./.gpu/texflow-$b bench scene fire --sizes 1024,4096 --repeats 5 --warmup 2 --json -q
    $R fire/points_${b}_$round ./.gpu/texflow-$b bench scene fire-points --sizes 1024,4096 --repeats 5 --warmup 2 --json -q
  done
done
for i in 1 2 3; do $R gasx_$i $F bench scene gas --sizes 1024 --repeats 5 --warmup 2 --json -q $GX; done
$R passes/gasx_1024 $F bench passes gas --particles 1024 --repeats 5 $GX
for round in 3 4; do
  for b in N Q; do
    for s in dem spin; do
      $R ab/${s}_${b}_$round ./.gpu/texflow-$b bench scene $s --sizes 256,1024 --repeats 5 --warmup 2 --json -q
    done
  done
done
$R table2 $F bench scenes --sizes 256,512,1024 --repeats 5 -q
for s in dem spin gas collide dam drop smoke fire flicker smoke-unlit fountain mesh snow fire-points e1 e2 e3 hair fireworks cloth; do
  $R sweep/bs_$s $F bench scene $s --sizes 256,1024,2048 --repeats 5 --warmup 2 --json -q
done
