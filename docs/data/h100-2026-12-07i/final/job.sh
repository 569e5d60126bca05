tar xzf .gpu/binsS.tgz -C .gpu
R=./.gpu/run.sh
N=./.gpu/texflow-N
GX="--set collisions.detection=exact --set collisions.cell=0.016"
$N info > $OUT/res/info.txt 2>&1
mkdir -p $OUT/res/sweep
for i in 1 2 3; do $R gasx_$i $N bench scene gas --sizes 1024 --repeats 5 --warmup 2 --json $GX -q; done
$R table2 $N bench scenes --sizes 256,512,1024 --repeats 5 -q
for s in smoke fire spin flicker smoke-unlit dem fountain mesh gas snow collide fire-points e1 e2 e3 hair fireworks cloth dam drop; do
  $R sweep/bs_$s $N bench scene $s --sizes 256,1024,2048 --repeats 5 --warmup 2 --json -q
done
