R=./.gpu/run.sh
GX="--set collisions.detection=exact --set collisions.cell=0.016"
./.gpu/texflow-Y info > $OUT/res/info.txt 2>&1
for r in 1 2; do
  for b in X Y Z; do
    N=./.gpu/texflow-$b
    $R bs_gasx_${b}_$r $N bench scene gas --sizes 1024,2048 --repeats 5 --warmup 2 --json -q $GX
  done
done
for b in Y Z; do
  N=./.gpu/texflow-$b
  $R p_gasx_$b ./.gpu/texflow-$b bench passes gas --particles 1024 --repeats 5 --warmup 2 $GX
  $R p_gasx8_$b ./.gpu/texflow-$b bench passes gas --particles 1024 --repeats 5 --warmup 2 --set collisions.detection=exact --set collisions.cell=0.008
done
for b in X Y Z; do
  $R bs_spin_$b ./.gpu/texflow-$b bench scene spin --sizes 256,1024 --repeats 5 --warmup 2 --json -q
done
for b in X Y; do
  $R bs_gasx8_$b ./.gpu/texflow-$b bench scene gas --sizes 1024 --repeats 5 --warmup 2 --json -q --set collisions.detection=exact --set collisions.cell=0.008
  $R cs_gasx_$b ./.gpu/texflow-$b collide-stats gas --steps 20 --particles 256 --detection exact --set collisions.cell=0.016 --json
done
