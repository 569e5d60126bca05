R=./.gpu/run.sh
N=./.gpu/texflow-V
$N info > $OUT/res/info.txt 2>&1
$R warm $N bench sort --sizes 2048 --variants blocked --blocked 4m --repeats 5 --no-cpu -q
$R bs_collide $N bench scene collide --sizes 256,1024,2048 --repeats 5 --warmup 2 --json -q
for i in 1 2 3; do
  $R sort4096_$i $N bench sort --sizes 4096 --variants blocked --blocked 4m,4cm,5cm --repeats 5 -q
done
$R sort12 $N bench sort --sizes 1024,2048 --variants blocked --blocked 4m,4cm,5cm --repeats 5 -q
for s in smoke mesh e1 fireworks; do
  $R order_$s $N bench scene $s --sizes 256,1024,256,256 --repeats 5 --warmup 2 --json -q
done
$R bs_collide2 $N bench scene collide --sizes 256,1024,2048 --repeats 5 --warmup 2 --json -q
$R spin_default $N bench scene spin --sizes 1024 --repeats 5 --warmup 2 --json -q
$R spin_i0 $N bench scene spin --sizes 1024 --repeats 5 --warmup 2 --json -q --set render.intensity=0.0
$R spin_ps4 $N bench scene spin --sizes 1024 --repeats 5 --warmup 2 --json -q --set render.point_size=4.0
