R=./.gpu/run.sh
N=./.gpu/texflow-A
GX="--set collisions.detection=exact --set collisions.cell=0.016"
$N info > $OUT/res/info.txt 2>&1
$R table2 $N bench scenes --sizes 256,512,1024 --repeats 5 -q
for r in 1 2 3; do
  $R bs_gasx_A_$r $N bench scene gas --sizes 1024,2048 --repeats 5 --warmup 2 --json -q $GX
done
$R bs_gasx_Y_1 ./.gpu/texflow-Y bench scene gas --sizes 1024,2048 --repeats 5 --warmup 2 --json -q $GX
$R bs_gasx_X_1 ./.gpu/texflow-X bench scene gas --sizes 1024 --repeats 5 --warmup 2 --json -q $GX
$R p_gasx_A $N bench passes gas --particles 1024 --repeats 5 --warmup 2 $GX
$R bs_gasx8_A $N bench scene gas --sizes 1024 --repeats 5 --warmup 2 --json -q --set collisions.detection=exact --set collisions.cell=0.008
for s in smoke mesh e1 collide; do
  $R order_$s $N bench scene $s --sizes 1024,256,256 --repeats 5 --warmup 2 --json -q
done
for s in collide fire fire-points snow fountain smoke smoke-unlit e1 e2 e3 gas mesh cloth hair fireworks flicker spin dem dam drop; do
  $R bs_$s $N bench scene $s --sizes 256,1024,2048 --repeats 5 --warmup 2 --json -q
done
