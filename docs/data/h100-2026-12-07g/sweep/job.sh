R=./.gpu/run.sh
D=./.gpu/texflow-D
GX="--set collisions.detection=exact --set collisions.cell=0.016"
$D info > $OUT/res/info.txt 2>&1
mkdir -p $OUT/res/sweep
for s in smoke fire spin flicker smoke-unlit dem fountain mesh gas snow collide fire-points e1 e2 e3 hair fireworks cloth dam drop; do
  $R sweep/bs_$s $D bench scene $s --sizes 256,1024,2048 --repeats 5 --warmup 2 --json -q
done
$R table2 $D bench scenes --sizes 256,512,1024 --repeats 5 -q
$R gasx $D bench scene gas --sizes 1024 --repeats 5 --warmup 2 --json $GX -q
$R sort4096 $D bench sort --sizes 4096 --variants blocked --blocked 4m,4cm --repeats 5
$R fire4096 $D bench scene fire --sizes 4096 --repeats 5 --warmup 2 --json -q
