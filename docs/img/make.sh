#!/bin/sh
# Renders the pictures of docs/img/ from the built-in scenes (llvmpipe: about a minute).
#   sh docs/img/make.sh            (from the repository root, after cargo build --release)
set -eu
bin=target/release/texflow
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# scene:frames to simulate (the picture is the last frame); the fire as the README shows it
"$bin" render fire --frames 121 --every 120 --particles 512x512 --out "$tmp/fire" --quiet
cp "$tmp/fire/frame_00120.png" docs/img/fire.png
echo docs/img/fire.png
for spec in snow:360 fountain:150 smoke:300 e1:90 e2:150 e3:90; do
    name=${spec%%:*}
    frames=${spec##*:}
    last=$((frames - 1))
    "$bin" render "$name" --frames "$frames" --every "$last" --out "$tmp/$name" --quiet
    cp "$tmp/$name/frame_$(printf %05d "$last").png" "docs/img/$name.png"
    echo "docs/img/$name.png"
done
