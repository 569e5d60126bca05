R=./.gpu/run.sh
N=./.gpu/texflow-X
$N info > $OUT/res/info.txt 2>&1
GX="--set collisions.detection=exact"
$R p_gasx16 $N bench passes gas --particles 1024 --repeats 5 --warmup 2 $GX --set collisions.cell=0.016
$R p_gasx8 $N bench passes gas --particles 1024 --repeats 5 --warmup 2 $GX --set collisions.cell=0.008
$R bs_gasx16 $N bench scene gas --sizes 1024 --repeats 5 --warmup 2 --json -q $GX --set collisions.cell=0.016
$R bs_gasx8 $N bench scene gas --sizes 1024 --repeats 5 --warmup 2 --json -q $GX --set collisions.cell=0.008
$R bs_gasx11 $N bench scene gas --sizes 1024 --repeats 5 --warmup 2 --json -q $GX --set collisions.cell=0.0107
for s in collide fire fire-points snow fountain smoke smoke-unlit e1 e2 e3 gas mesh cloth hair fireworks flicker spin dem dam drop; do
  $R bs_$s $N bench scene $s --sizes 256,1024,2048 --repeats 5 --warmup 2 --json -q
done
for s in smoke mesh e1 fireworks collide; do
  $R order_$s $N bench scene $s --sizes 1024,256,256 --repeats 5 --warmup 2 --json -q
done
