R=./.gpu/run.sh
N=./.gpu/texflow-T
GX="--set collisions.detection=exact --set collisions.cell=0.016"
$N info > $OUT/res/info.txt 2>&1
$R bs_gasx_T $N bench scene gas --sizes 1024 --repeats 5 --warmup 2 --json -q $GX
$R bs_gasx_M ./.gpu/texflow-M bench scene gas --sizes 1024 --repeats 5 --warmup 2 --json -q $GX
