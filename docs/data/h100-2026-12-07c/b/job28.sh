R=./.gpu/run.sh
GX="--set collisions.detection=exact --set collisions.cell=0.016"
./.gpu/texflow-B1 info > $OUT/res/info.txt 2>&1
for r in 1 2; do
  for b in B1 B2; do
    $R bs_gasx_${b}_$r ./.gpu/texflow-$b bench scene gas --sizes 1024,2048 --repeats 5 --warmup 2 --json -q $GX
  done
done
$R p_gasx_B2 ./.gpu/texflow-B2 bench passes gas --particles 1024 --repeats 5 --warmup 2 $GX
$R bs_spin_B2 ./.gpu/texflow-B2 bench scene spin --sizes 256,1024,2048 --repeats 5 --warmup 2 --json -q
N=./.gpu/texflow-B1
for s in collide fire fire-points snow fountain smoke smoke-unlit e1 e2 e3 gas mesh cloth hair fireworks flicker spin dem dam drop; do
  $R bs_$s $N bench scene $s --sizes 256,1024,2048 --repeats 5 --warmup 2 --json -q
done
