tar xzf .gpu/binsN.tgz -C .gpu
R=./.gpu/run.sh
GX="--set collisions.detection=exact --set collisions.cell=0.016"
./.gpu/texflow-N info > $OUT/res/info.txt 2>&1
for round in 1 2 3; do
  for b in F M N; do
    $R dem_${b}_$round ./.gpu/texflow-$b bench scene dem --sizes 256,1024 --repeats 5 --warmup 2 --json -q
  done
done
for b in M N; do
  $R gasx_${b}_1 ./.gpu/texflow-$b bench scene gas --sizes 1024 --repeats 5 --warmup 2 --json $GX -q
  $R drop_${b}_1 ./.gpu/texflow-$b bench scene drop --sizes 256,1024 --repeats 5 --warmup 2 --json -q
done
