R=./.gpu/run.sh
N=./.gpu/texflow-U
$N info > $OUT/res/info.txt 2>&1
$R table2 $N bench scenes --sizes 256,512,1024 --repeats 5 -q
$R sort4096 $N bench sort --sizes 4096 --variants blocked --blocked 4m,5cm,4cm,5c,3cm --repeats 5 -q
$R reportall $N report all --runs 3 --out $OUT/report -q
for s in collide fire fire-points snow fountain smoke smoke-unlit e1 e2 e3 gas mesh cloth hair fireworks flicker spin dem dam drop; do
  $R bs_$s $N bench scene $s --sizes 256,1024,2048 --repeats 5 --warmup 2 --json -q
done
