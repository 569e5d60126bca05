R=./.gpu/run.sh
N=./.gpu/texflow-C
GX="--set collisions.detection=exact --set collisions.cell=0.016"
$N info > $OUT/res/info.txt 2>&1
$R bs_gasx_C $N bench scene gas --sizes 1024,2048 --repeats 5 --warmup 2 --json -q $GX
$R bs_gasx_X ./.gpu/texflow-X bench scene gas --sizes 1024,2048 --repeats 5 --warmup 2 --json -q $GX
$R bs_fire4096 $N bench scene fire --sizes 4096 --repeats 5 --warmup 2 --json -q
$R sort4096 $N bench sort --sizes 4096 --variants blocked --blocked 4m,4cm --repeats 5 -q
for s in collide fire fire-points snow fountain smoke smoke-unlit e1 e2 e3 gas mesh cloth hair fireworks flicker spin dem dam drop; do
  $R bs_$s $N bench scene $s --sizes 256,1024,2048 --repeats 5 --warmup 2 --json -q
done
