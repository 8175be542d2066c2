#!/bin/bash
# Reproduces the point- and spot-light GPU figures of docs/benchmarks.md ("Point lights, VSM
# and the lighting pass"): per-pass times of `penumbra render` at 1920×1080 over 30 frames,
# with every view drawn each frame ("moving", --no-shadow-cache) and with the cache ("still").
#
#   bash docs/bench/point_lights.sh [PENUMBRA] [BASELINE]
#
# PENUMBRA is the binary to measure (default target/release/penumbra, from
# `cargo build --release`); BASELINE, a binary built at another commit, adds the scene table
# that compares the two in the same run. Run it from the repository root.
set -euo pipefail
BIN=${1:-target/release/penumbra}
BASE=${2:-}
R="--width 1920 --height 1080 --frames 30 --out ${TMPDIR:-/tmp}/penumbra_point_lights.png"
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT

# One line per run: the sums of the shadow passes, the cube faces, the moments, the resolve,
# the lighting pass and the frame.
sum() {
  awk '/^gpu +shadow point/ {d+=$(NF-1)} /^gpu +shadow moments/ {m+=$(NF-1)}
       /^gpu +shadow/ && !/moments/ {s+=$(NF-1)} /^gpu +total/ {t=$(NF-1)}
       /^gpu +visibility resolve/ {r=$(NF-1)} /^gpu +forward/ {f=$(NF-1)}
       END {printf "shadow %.3f (point faces %.3f) moments %.3f resolve %.3f lighting %.3f total %.3f\n", s, d, m, r, f, t}'
}
both() {
  for cache in --no-shadow-cache ""; do
    printf "%-28s %-7s " "$1" "${cache:+moving}${cache:-still}"
    "$2" render "$3" $R $cache 2>&1 | sum
  done
}

if [ -n "$BASE" ]; then
  echo "## Lighting pass: baseline against this binary"
  for scene in assets/bench/boxes.ron assets/scenes/default.ron assets/scenes/lights.ron \
               assets/scenes/spot.ron assets/scenes/garden.ron; do
    both "$scene (baseline)" "$BASE" "$scene"
    both "$scene" "$BIN" "$scene"
  done
fi

echo "## One point light (assets/scenes/point.ron), per filter, face size and emitter radius"
while read -r name radius settings; do
  sed "s/shadows: (mode: Pcss, pcss_quality: High, resolution: 1024)/$settings/; s/radius: 0.2,/radius: $radius,/" \
    assets/scenes/point.ron > "$WORK/$name.ron"
  both "$name r=$radius" "$BIN" "$WORK/$name.ron"
done <<'LIST'
off 0.2 shadows_enabled: false, shadows: (resolution: 256)
hard-256 0.2 shadows: (mode: Pcf, pcf_radius: 0, resolution: 256)
pcf1-256 0.2 shadows: (mode: Pcf, pcf_radius: 1, resolution: 256)
pcsshigh-256 0.2 shadows: (mode: Pcss, pcss_quality: High, resolution: 256)
vsm0-256 0.2 shadows: (mode: Vsm, vsm_blur: 0, resolution: 256)
vsm4-256 0.2 shadows: (mode: Vsm, vsm_blur: 4, resolution: 256)
hard-1024 0.2 shadows: (mode: Pcf, pcf_radius: 0, resolution: 1024)
pcf1-1024 0.2 shadows: (mode: Pcf, pcf_radius: 1, resolution: 1024)
pcsshigh-1024 0.2 shadows: (mode: Pcss, pcss_quality: High, resolution: 1024)
vsm0-1024 0.2 shadows: (mode: Vsm, vsm_blur: 0, resolution: 1024)
vsm4-1024 0.2 shadows: (mode: Vsm, vsm_blur: 4, resolution: 1024)
vsm8-1024 0.2 shadows: (mode: Vsm, vsm_blur: 8, resolution: 1024)
pcsshigh-r05 0.05 shadows: (mode: Pcss, pcss_quality: High, resolution: 1024)
pcsshigh-r80 0.8 shadows: (mode: Pcss, pcss_quality: High, resolution: 1024)
vsm4-r05 0.05 shadows: (mode: Vsm, vsm_blur: 4, resolution: 1024)
vsm4-r80 0.8 shadows: (mode: Vsm, vsm_blur: 4, resolution: 1024)
LIST

echo "## Spot light (assets/scenes/spot.ron), VSM and PCF"
for mode in "mode: Vsm, vsm_blur: 0" "mode: Vsm, vsm_blur: 4" "mode: Pcf, pcf_radius: 1"; do
  sed "s/mode: Pcss, pcss_quality: High/$mode/" assets/scenes/spot.ron > "$WORK/spot.ron"
  both "spot $mode" "$BIN" "$WORK/spot.ron"
done

echo "## Night scene"
both assets/scenes/night.ron "$BIN" assets/scenes/night.ron
