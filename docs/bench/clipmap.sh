#!/bin/bash
# Reproduces the clipmap figures of docs/benchmarks.md ("A sun's clipmap against four
# cascades"): the long field and the default scene at 1920×1080 with four 2048² cascades and a
# 6-level clipmap of 1672² levels (the same texels), still, translating 1 m a frame, turning
# 2° a frame, with every map drawn every frame, and with PCF, PCSS and EVSM2; the 100k field
# translating (five runs each, for the CPU's culling time); and the bench's errors for both
# layouts.
#
#   bash docs/bench/clipmap.sh [PENUMBRA] [OUT]
#
# PENUMBRA is the binary (default target/release/penumbra); OUT the folder for the outputs
# (default out/clipmap). Run it from the repository root.
set -euo pipefail
BIN=${1:-target/release/penumbra}
OUT=${2:-out/clipmap}
mkdir -p "$OUT"
CLIP="--layout clipmap --clipmap-levels 6 --clipmap-extent 32 --resolution 1672"
CASC="--layout cascades --resolution 2048"
render() { "$BIN" render "$@" --width 1920 --height 1080 --out "$OUT/image.png" --frames 30; }
for scene in assets/bench/long_field.ron assets/scenes/default.ron; do
  s=$(basename "$scene" .ron)
  for layout in casc clip; do
    if [ $layout = casc ]; then L=$CASC; else L=$CLIP; fi
    render "$scene" $L > "$OUT/$s-$layout-still.txt"
    render "$scene" $L --camera-step 0,0,-1 > "$OUT/$s-$layout-move.txt"
    render "$scene" $L --camera-turn 2 > "$OUT/$s-$layout-turn.txt"
    render "$scene" $L --no-shadow-cache > "$OUT/$s-$layout-all.txt"
    for m in pcf pcss evsm; do
      render "$scene" $L --mode $m > "$OUT/$s-$layout-$m.txt"
    done
  done
done
for layout in casc clip; do
  if [ $layout = casc ]; then L=$CASC; else L=$CLIP; fi
  for i in 1 2 3 4 5; do
    render assets/scenes/field.ron $L --camera-step 0,0,-1 > "$OUT/field-$layout-move-$i.txt"
  done
done
S="assets/bench/long_field.ron assets/scenes/default.ron"
"$BIN" bench --scenes $S --presets pcf2,pcss-medium,evsm-fp32 --resolution 2048 --out "$OUT/bench-casc"
"$BIN" bench --scenes $S --presets clipmap-pcf,clipmap-pcss,clipmap-evsm --resolution 1672 --out "$OUT/bench-clip"
