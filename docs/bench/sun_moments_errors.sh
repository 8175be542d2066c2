#!/bin/bash
# Reproduces the sun moment-shadow error figures of docs/benchmarks.md ("Sun: EVSM and moment
# shadow maps"): the bench of every sun preset on the pillars, field and thin scenes; the same
# on copies of pillars and field whose ground casts shadows (moment techniques want receivers
# in the map); and the sweep of the sun's angular diameter on pillars.
#
#   bash docs/bench/sun_moments_errors.sh [PENUMBRA] [OUT]
#
# PENUMBRA is the binary (default target/release/penumbra); OUT the folder for the reports
# (default out/sun-moments: main/, ground/ and sweep/). Run it from the repository root; the
# ground copies are written beside the scenes (they name no files) and removed at the end.
set -euo pipefail
BIN=${1:-target/release/penumbra}
OUT=${2:-out/sun-moments}
P=pcf1,pcss-low,pcss-medium,pcss-high,evsm-fp16,evsm-fp32,evsm4,msm-fp16,msm-fp32,evsm-fixed,msm-fixed
S=assets/scenes
trap 'rm -f "$S/pillars-ground.ron" "$S/field-ground.ron"' EXIT

"$BIN" bench --scenes $S/pillars.ron $S/field.ron $S/thin.ron --presets $P --out "$OUT/main"

sed 's/material: "ground", cast_shadows: false/material: "ground", cast_shadows: true/' \
  $S/pillars.ron > $S/pillars-ground.ron
sed 's/material: "grass", cast_shadows: false/material: "grass", cast_shadows: true/' \
  $S/field.ron > $S/field-ground.ron
grep -q "cast_shadows: true" $S/pillars-ground.ron $S/field-ground.ron
"$BIN" bench --scenes $S/pillars-ground.ron $S/field-ground.ron --presets $P --out "$OUT/ground"

"$BIN" bench --scenes $S/pillars.ron --presets pcss-low,pcss-high,evsm-fp16,msm-fp16,msm-fixed \
  --sun-diameters 0.25,0.5,1,2,3,5 --out "$OUT/sweep"
