R=./.gpu/run.sh
D=./.gpu/texflow-D
for s in drop dam dem spin; do
  $R passes_$s $D bench passes $s --particles 256 --repeats 5 -q
  $R passes1024_$s $D bench passes $s --particles 1024 --repeats 5 -q
done
