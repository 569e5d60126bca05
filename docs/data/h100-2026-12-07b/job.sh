R=./.gpu/run.sh
N=./.gpu/texflow-T
$N info > $OUT/res/info.txt 2>&1
for c in 0.016 0.008; do
  $R gasx_$c $N bench scene gas --sizes 1024 --repeats 5 --warmup 2 --set collisions.detection=exact --set collisions.cell=$c -q
done
$R e4_1 $N bench scenes --sizes 1024 --experiments E4 --repeats 5 -q
for s in cloth hair snow fountain mesh collide; do
  $R bs_$s $N bench scene $s --sizes 256,1024,2048 --repeats 5 --warmup 2 --json -q
done
$R pgasx_0.008 $N bench passes gas --particles 1024 --repeats 5 --warmup 2 --set collisions.detection=exact --set collisions.cell=0.008 -q
