tar xzf .gpu/bins.tgz -C .gpu
R=./.gpu/run.sh
M=./.gpu/texflow-M
GX="--set collisions.detection=exact --set collisions.cell=0.016"
$M info > $OUT/res/info.txt 2>&1
nvidia-smi > $OUT/res/smi0.txt 2>&1
mkdir -p $OUT/res/sweep $OUT/res/ab
$R gasx $M bench scene gas --sizes 1024 --repeats 5 --warmup 2 --json $GX -q
$R table2 $M bench scenes --sizes 256,512,1024 --repeats 5 -q
$R sort4096 $M bench sort --sizes 4096 --variants blocked --blocked 4m,4cm --repeats 5
$R fire4096 $M bench scene fire --sizes 4096 --repeats 5 --warmup 2 --json -q
for s in smoke fire spin flicker smoke-unlit dem fountain mesh gas snow collide fire-points e1 e2 e3 hair fireworks cloth dam drop; do
  $R sweep/bs_$s $M bench scene $s --sizes 256,1024,2048 --repeats 5 --warmup 2 --json -q
done
s=$(date +%s)
bash docs/data/llvmpipe-2026-12-07h/gpu_job.sh ./.gpu/texflow-F ./.gpu/texflow-H $OUT/res/ab > $OUT/res/ab/_log.txt 2>&1
echo "ab rc=$? $(( $(date +%s) - s )) s" >> $OUT/res/_times.txt
