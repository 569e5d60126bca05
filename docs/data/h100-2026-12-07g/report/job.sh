R=./.gpu/run.sh
D=./.gpu/texflow-D
$D info > $OUT/res/info.txt 2>&1
$R reportall $D report all --runs 3 --out $OUT/res/report -q
