#!/bin/sh
# Renders the pictures of docs/img/ from the built-in scenes (llvmpipe: about a minute).
#   sh docs/img/make.sh            (from the repository root, after cargo build --release)
set -eu
bin=target/release/texflow
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# The fire as the README shows it: frame 120 (steady state) of the default render, in soft
# sprites and in the thesis's points; and the README's animation, a seamless loop (--loop)
"$bin" render fire --start 120 --frames 121 --out "$tmp/fire" --quiet
cp "$tmp/fire/frame_00120.png" docs/img/fire.png
"$bin" render fire-points --start 120 --frames 121 --out "$tmp/fire-points" --quiet
cp "$tmp/fire-points/frame_00120.png" docs/img/fire-points.png
"$bin" render fire --start 120 --frames 264 --every 2 --resolution 320x240 \
    --set render.point_size=7 --set render.intensity=0.07 --video docs/img/fire.gif --loop 12 --quiet
echo docs/img/fire.png docs/img/fire-points.png docs/img/fire.gif
# UberFlow Fig. 4 right: the same scene with collisions between particles on and off
"$bin" render collide --frames 300 --every 299 --out "$tmp/collide" --quiet
cp "$tmp/collide/frame_00299.png" docs/img/collide.png
"$bin" render collide --frames 300 --every 299 --no-collisions --out "$tmp/collide_off" --quiet
cp "$tmp/collide_off/frame_00299.png" docs/img/collide_off.png
echo docs/img/collide.png docs/img/collide_off.png
# 3 s of the collide scene at 64x64 particles without collisions, with UberFlow's
# detection, and with the exact detection (4 iterations)
"$bin" render collide --particles 64 --frames 301 --every 300 --resolution 384 --no-collisions --out "$tmp/c0" --quiet
cp "$tmp/c0/frame_00300.png" docs/img/collide_none_3s.png
"$bin" render collide --particles 64 --frames 301 --every 300 --resolution 384 --out "$tmp/c1" --quiet
cp "$tmp/c1/frame_00300.png" docs/img/collide_uberflow_3s.png
sed 's/^staggered = true/staggered = true\ndetection = "exact"\niterations = 4/' examples/scenes/collide.toml > "$tmp/collide_exact.toml"
"$bin" render "$tmp/collide_exact.toml" --particles 64 --frames 301 --every 300 --resolution 384 --out "$tmp/c2" --quiet
cp "$tmp/c2/frame_00300.png" docs/img/collide_exact_3s.png
echo docs/img/collide_none_3s.png docs/img/collide_uberflow_3s.png docs/img/collide_exact_3s.png
for spec in snow:360 fountain:150 mesh:150 smoke:300 smoke-unlit:300 e1:90 e2:150 e3:90 gas:90 cloth:150 hair:150 spin:90 fireworks:61 dem:21 flicker:121 dam:16 drop:16; do
    name=${spec%%:*}
    frames=${spec##*:}
    last=$((frames - 1))
    "$bin" render "$name" --frames "$frames" --every "$last" --out "$tmp/$name" --quiet
    cp "$tmp/$name/frame_$(printf %05d "$last").png" "docs/img/$name.png"
    echo "docs/img/$name.png"
done
# texflow trace: Latta's odd-even merge sort of 16x16 random keys, four of its 37 pictures
# A user state: the heat example's temperature, colouring its flame (examples/heat/).
"$bin" render examples/heat/heat.toml --frames 81 --every 80 --out "$tmp/heat" --quiet
cp "$tmp/heat/frame_00080.png" docs/img/heat.png
# A user state exchanged with the neighbours: heat spreading through a pile (examples/heat-exchange/).
"$bin" render examples/heat-exchange/heat_exchange.toml --frames 151 --every 150 --out "$tmp/hx" --quiet
cp "$tmp/hx/frame_00150.png" docs/img/heat-exchange.png
# A user state in a fluid: the dam break carrying a temperature (examples/heat-fluid/).
"$bin" render examples/heat-fluid/heat_fluid.toml --frames 21 --every 20 --out "$tmp/hf" --quiet
cp "$tmp/hf/frame_00020.png" docs/img/heat-fluid.png
# Trail ribbons: fireworks with render.trails = "ribbon" (examples/ribbons/).
"$bin" render examples/ribbons/ribbons.toml --frames 24 --every 23 --out "$tmp/ribbons" --quiet
cp "$tmp/ribbons/frame_00023.png" docs/img/ribbons.png
"$bin" trace sort --variant oddeven --size 16 --seed 1 --out "$tmp/trace" --quiet
for i in 000 010 021 036; do
    cp "$tmp/trace/pass_$i.png" "docs/img/trace_oddeven_16_pass_$i.png"
done
echo docs/img/trace_oddeven_16_pass_*.png
