R=./.gpu/run.sh
E=./.gpu/texflow-E
$E info > $OUT/res/info.txt 2>&1
mkdir -p $OUT/res/sweep
for s in smoke fire spin flicker smoke-unlit dem fountain mesh gas snow collide fire-points e1 e2 e3 hair fireworks cloth dam drop; do
  $R sweep/bs_$s $E bench scene $s --sizes 256,1024,2048 --repeats 5 --warmup 2 --json -q
done
$R table2 $E bench scenes --sizes 256,512,1024 --repeats 5 -q
