#!/bin/bash
# Reproduces the contact-shadow figures of docs/benchmarks.md ("Contact shadows"): the cost of
# the march per light at 1920×1080 (the compute resolve's time with and without contact
# shadows on the contact scene's sun, the default scene's sun, a spot and a point light; and
# the contact term alone when the filters are not resolved), then the bench's errors over the
# whole frame and the contact band, with 2048² and 1024² maps, at the default thickness and
# at 2 cm.
#
#   bash docs/bench/contact.sh [PENUMBRA] [OUT]
#
# PENUMBRA is the binary (default target/release/penumbra); OUT the folder for the outputs
# (default out/contact). Run it from the repository root.
set -euo pipefail
BIN=${1:-target/release/penumbra}
OUT=${2:-out/contact}
mkdir -p "$OUT"
render() {
  local name=$1 scene=$2
  shift 2
  "$BIN" render "$scene" --width 1920 --height 1080 --frames 30 --json --out "$OUT/image.png" "$@" > "$OUT/$name.json"
}
for c in off on thin; do
  case $c in
    off) C=() ;;
    on) C=(--contact-shadows) ;;
    thin) C=(--contact-shadows 0.3,16,0.02,1) ;;
  esac
  render "contact-$c-still" assets/bench/contact.ron "${C[@]}"
  render "contact-$c-moving" assets/bench/contact.ron "${C[@]}" --no-shadow-cache
  render "contact-$c-still-direct" assets/bench/contact.ron "${C[@]}" --no-visibility-resolve
  for s in spot point default; do
    render "$s-$c-still" "assets/scenes/$s.ron" "${C[@]}"
  done
done
B=(--scenes assets/bench/contact.ron --width 1920 --height 1080 --analysis-width 1920 --frames 2)
"$BIN" bench "${B[@]}" --presets pcf1,pcf1-contact,pcss-medium,pcss-medium-contact,evsm-fp32,evsm-fp32-contact --out "$OUT/bench-default"
"$BIN" bench "${B[@]}" --presets pcf1-contact,pcss-medium-contact,evsm-fp32-contact --contact-shadows 0.3,16,0.02,1 --out "$OUT/bench-thin"
"$BIN" bench "${B[@]}" --resolution 1024 --presets pcf1,pcf1-contact,pcss-medium,pcss-medium-contact --out "$OUT/bench-1024"
