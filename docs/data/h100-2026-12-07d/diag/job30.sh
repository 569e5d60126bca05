R=./.gpu/run.sh
N=./.gpu/texflow-H
$N info > $OUT/res/info.txt 2>&1
nvidia-smi --query-gpu=timestamp,clocks.sm,clocks.mem,power.draw,pstate --format=csv -lms 50 > $OUT/res/_clocks.txt 2>&1 &
SMI=$!
$R d_smoke5 $N bench scene smoke --sizes 256,256,256,256,256 --repeats 5 --warmup 2 --json -q
$R d_unlit3 $N bench scene smoke-unlit --sizes 256,256,256 --repeats 5 --warmup 2 --json -q
$R d_smokew $N bench scene smoke --sizes 256,256 --repeats 5 --warmup 300 --json -q
$R d_smoke4s $N bench scene smoke --sizes 256,256,256 --repeats 5 --warmup 2 --json -q --set render.slices=4
$R d_smokerep $N bench scene smoke --sizes 256,256,256 --repeats 20 --warmup 2 --json -q
kill $SMI
