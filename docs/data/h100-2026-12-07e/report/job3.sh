R=./.gpu/run.sh
N=./.gpu/texflow-L
$N info > $OUT/res/info.txt 2>&1
$R reportall $N report all --runs 3 --out $OUT/res/report -q
