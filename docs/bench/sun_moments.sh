#!/bin/bash
# Reproduces the sun moment-shadow figures of docs/benchmarks.md ("Sun: EVSM and moment shadow
# maps"): per-pass times of `penumbra render` at 1920×1080 over 30 frames for every filter of
# the default scene (4 × 2048² cascades), with every cascade drawn and baked each frame
# ("moving", --no-shadow-cache) and with the cache ("still"); then the lighting cost against
# the sun's angular diameter.
#
#   bash docs/bench/sun_moments.sh [PENUMBRA] [BASELINE]
#
# PENUMBRA is the binary to measure (default target/release/penumbra, from
# `cargo build --release`); BASELINE, a binary built at another commit, adds its PCF and PCSS
# rows in the same run. Run it from the repository root. The error figures come from
# `penumbra bench` (see docs/benchmarks.md for its command lines).
set -euo pipefail
BIN=${1:-target/release/penumbra}
BASE=${2:-}
R="--width 1920 --height 1080 --frames 30 --out ${TMPDIR:-/tmp}/penumbra_sun_moments.png"

# One line per run: each cascade's bake (moments and blur), the cascades' depth, the resolve,
# the lighting pass and the frame.
sum() {
  awk '/^gpu +shadow moments sun/ {b[n++]=$(NF-1); m+=$(NF-1)}
       /^gpu +shadow cascade/ {s+=$(NF-1)} /^gpu +total/ {t=$(NF-1)}
       /^gpu +visibility resolve/ {r=$(NF-1)} /^gpu +forward/ {f=$(NF-1)}
       END {printf "depth %.3f bake %.3f (", s, m;
            for (i = 0; i < n; i++) printf "%s%.3f", (i ? " " : ""), b[i];
            printf ") resolve %.3f lighting %.3f total %.3f\n", r, f, t}'
}
both() {
  local name=$1 bin=$2 scene=$3
  shift 3
  for cache in --no-shadow-cache ""; do
    printf "%-24s %-7s " "$name" "${cache:+moving}${cache:-still}"
    "$bin" render "$scene" $R $cache "$@" 2>&1 | sum
  done
}

MODES=(
  "pcf1|--mode pcf --pcf-radius 1"
  "pcss-low|--mode pcss --quality low"
  "pcss-high|--mode pcss --quality high"
  "evsm-fp16|--mode evsm --moment-precision fp16"
  "evsm-fp32|--mode evsm --moment-precision fp32"
  "evsm4|--mode evsm4 --moment-precision fp32"
  "msm-fp16|--mode msm --moment-precision fp16"
  "msm-fp32|--mode msm --moment-precision fp32"
  "evsm-fixed|--mode evsm --moment-precision fp32 --moment-contact-hardening false"
  "msm-fixed|--mode msm --moment-precision fp16 --moment-contact-hardening false"
)

echo "## Default scene (assets/scenes/default.ron), per filter"
for entry in "${MODES[@]}"; do
  name=${entry%%|*}
  # shellcheck disable=SC2086
  both "$name" "$BIN" assets/scenes/default.ron ${entry#*|}
done
if [ -n "$BASE" ]; then
  for entry in "${MODES[@]:0:3}"; do
    name=${entry%%|*}
    # shellcheck disable=SC2086
    both "$name (baseline)" "$BASE" assets/scenes/default.ron ${entry#*|}
  done
fi

echo "## Lighting cost against the sun's angular diameter (pillars.ron, still)"
for d in 0.25 0.5 1 2 3 5; do
  for entry in "pcss-low|--mode pcss --quality low" "pcss-high|--mode pcss --quality high" \
               "evsm-fp16|--mode evsm --moment-precision fp16" "msm-fp16|--mode msm --moment-precision fp16" \
               "msm-fixed|--mode msm --moment-precision fp16 --moment-contact-hardening false"; do
    printf "%-5s %-10s " "$d°" "${entry%%|*}"
    # shellcheck disable=SC2086
    "$BIN" render assets/scenes/pillars.ron $R --sun-diameter "$d" ${entry#*|} 2>&1 | sum
  done
done
