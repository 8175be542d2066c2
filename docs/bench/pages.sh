#!/bin/bash
# Reproduces the virtual clipmap figures of docs/benchmarks.md ("A sun's virtual clipmap"):
# the long field and the default scene at 1920×1080 with four 2048² cascades, a 6-level
# clipmap of 1672² levels (the same texels) and a 6-level virtual clipmap of 16384² levels
# (128² pages, a pool of 2048), the finest level 32 m wide; still, translating 1 m a frame and
# turning 2° a frame, with PCF, PCSS and EVSM2; and the bench's errors for the three layouts.
#
#   bash docs/bench/pages.sh [PENUMBRA] [OUT] [PART]
#
# PENUMBRA is the binary (default target/release/penumbra); OUT the folder for the outputs
# (default out/pages); PART `renders`, `bench` or `all` (the default). Run it from the
# repository root.
set -euo pipefail
BIN=${1:-target/release/penumbra}
OUT=${2:-out/pages}
PART=${3:-all}
mkdir -p "$OUT"
CASC="--layout cascades --resolution 2048"
CLIP="--layout clipmap --clipmap-levels 6 --clipmap-extent 32 --resolution 1672"
PAGE="--layout virtual-clipmap --clipmap-levels 6 --clipmap-extent 32 --virtual-resolution 16384 --page-size 128 --pool-pages 2048"
render() { "$BIN" render "$@" --width 1920 --height 1080 --out "$OUT/image.png" --frames 30; }
[ "$PART" = bench ] || for scene in assets/bench/long_field.ron assets/scenes/default.ron; do
  s=$(basename "$scene" .ron)
  for layout in casc clip page; do
    case $layout in casc) L=$CASC ;; clip) L=$CLIP ;; page) L=$PAGE ;; esac
    for m in pcf pcss evsm; do
      render "$scene" $L --mode $m > "$OUT/$s-$layout-$m-still.txt"
      render "$scene" $L --mode $m --camera-step 0,0,-1 > "$OUT/$s-$layout-$m-move.txt"
      render "$scene" $L --mode $m --camera-turn 2 > "$OUT/$s-$layout-$m-turn.txt"
    done
  done
  render "$scene" $PAGE --debug-cascades > /dev/null && cp "$OUT/image.png" "$OUT/$s-page-levels.png"
done
[ "$PART" = renders ] && exit 0
S="assets/bench/long_field.ron assets/scenes/default.ron"
"$BIN" bench --scenes $S --presets pcf2,pcss-medium --resolution 2048 --out "$OUT/bench-casc"
"$BIN" bench --scenes $S --presets clipmap-pcf,clipmap-pcss --resolution 1672 --out "$OUT/bench-clip"
"$BIN" bench --scenes $S --presets pages-pcf,pages-pcss,pages-evsm --out "$OUT/bench-page"
"$BIN" bench --scenes $S --presets clipmap-evsm --resolution 1672 --out "$OUT/bench-clip-evsm"
