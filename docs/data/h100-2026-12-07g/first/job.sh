R=./.gpu/run.sh
C=./.gpu/texflow-C
$C info > $OUT/res/info.txt 2>&1
for b in C V1 V2 C V1 V2; do
$R smoke_$b ./.gpu/texflow-$b bench scene smoke --sizes 256,1024 --repeats 5 --warmup 2 --json -q
done
mkdir -p $OUT/res/sweep
for s in smoke fire spin flicker smoke-unlit dem fountain mesh gas snow collide fire-points e1 e2 e3 hair fireworks cloth dam drop; do
  $R sweep/bs_$s $C bench scene $s --sizes 256,1024,2048 --repeats 5 --warmup 2 --json -q
done
$R table2 $C bench scenes --sizes 256,512,1024 --repeats 5 -q
