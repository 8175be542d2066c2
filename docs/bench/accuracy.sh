#!/bin/bash
# Reproduces the accuracy figures of docs/benchmarks.md ("Accuracy on scenes the product was
# not tuned on"): the bench's default scenes with every preset; the same scenes under a
# 0.53° and a 3° sun; the city (tuned on) and the town (held out) at 1280×720 under both
# suns; and the city in a 10:1 and a 1:10 image.
#
#   bash docs/bench/accuracy.sh [PENUMBRA] [OUT]
#
# PENUMBRA is the binary (default target/release/penumbra); OUT the folder for the reports
# (default out/accuracy). Run it from the repository root.
set -euo pipefail
BIN=${1:-target/release/penumbra}
OUT=${2:-out/accuracy}
SUN=hard,pcf1,pcss-low,pcss-high,evsm-fp16,evsm-fp32,evsm4,msm-fp16,msm-fp32,evsm-fixed,msm-fixed
CITY="assets/bench/city.ron assets/bench/town.ron"

"$BIN" bench --out "$OUT/bench"
for d in 0.53 3; do
  "$BIN" bench --presets $SUN --sun-diameter $d --out "$OUT/sun-$d"
  "$BIN" bench --scenes $CITY --presets $SUN --sun-diameter $d --width 1280 --height 720 \
    --analysis-width 640 --out "$OUT/city-$d"
done
"$BIN" bench --scenes assets/bench/city.ron --presets pcf1,pcss-high --width 2000 --height 200 \
  --analysis-width 1000 --out "$OUT/city-10x1"
"$BIN" bench --scenes assets/bench/city.ron --presets pcf1,pcss-high --width 200 --height 2000 \
  --analysis-width 200 --out "$OUT/city-1x10"
