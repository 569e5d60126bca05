R=./.gpu/run.sh
N=./.gpu/texflow-T
GX="--set collisions.detection=exact --set collisions.cell=0.016"
$N info > $OUT/res/info.txt 2>&1
$R p_gas_M ./.gpu/texflow-M bench passes gas --particles 1024 --repeats 5 --warmup 2
$R p_gas_T $N bench passes gas --particles 1024 --repeats 5 --warmup 2
for s in smoke spin fire flicker smoke-unlit dem fountain mesh gas snow collide fire-points e1 e2 e3 hair fireworks cloth; do
  $R bs_$s $N bench scene $s --sizes 256,1024,2048 --repeats 5 --warmup 2 --json -q
done
$R table2 $N bench scenes --sizes 256,512,1024 --repeats 5 -q
$R bs_fire4096 $N bench scene fire --sizes 4096 --repeats 5 --warmup 2 --json -q
for s in dam drop; do
  $R bs_$s $N bench scene $s --sizes 256,1024,2048 --repeats 5 --warmup 2 --json -q
done
