R=./.gpu/run.sh
N=./.gpu/texflow-A
$R reportall $N report all --runs 3 --out $OUT/report -q
$R table2b $N bench scenes --sizes 256,512,1024 --repeats 5 -q
