tar xzf .gpu/bins.tgz -C .gpu
R=./.gpu/run.sh
M=./.gpu/texflow-M
H=./.gpu/texflow-H
$M info > $OUT/res/info.txt 2>&1
mkdir -p $OUT/res/passes
$R reportall $M report all --runs 3 --out $OUT/res/report -q
rm -f $OUT/res/report/*.png $OUT/res/report/**/*.png 2>/dev/null
for s in spin dem drop; do
  $R passes/M_$s $M bench passes $s --particles 256 --repeats 5
  $R passes/H_$s $H bench passes $s --particles 256 --repeats 5
done
