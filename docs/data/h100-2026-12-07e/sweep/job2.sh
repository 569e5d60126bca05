R=./.gpu/run.sh
N=./.gpu/texflow-L
GX="--set collisions.detection=exact --set collisions.cell=0.016"
$N info > $OUT/res/info.txt 2>&1
for b in O L O L; do
$R fire4096_$b ./.gpu/texflow-$b bench scene fire --sizes 4096 --repeats 5 --warmup 2 --json -q
done
for s in smoke fire spin flicker smoke-unlit dem fountain mesh gas snow collide fire-points e1 e2 e3 hair fireworks cloth dam drop; do
  $R bs_$s $N bench scene $s --sizes 256,1024,2048 --repeats 5 --warmup 2 --json -q
done
$R table2 $N bench scenes --sizes 256,512,1024 --repeats 5 -q
$R gasx $N bench scene gas --sizes 1024 --repeats 5 --warmup 2 --json $GX -q
$R sort4096 $N bench sort --sizes 4096 --variants blocked --blocked 4m,4cm --repeats 5
