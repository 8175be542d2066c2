#!/bin/bash
# Reproduces the scale figures of docs/benchmarks.md ("A million casters"): the 100k field
# (`assets/scenes/field.ron`), the 101 760 boxes of 2 120 sizes (`assets/bench/many_boxes.ron`)
# and the million (`assets/bench/million.ron`) at 1920×1080, 30 frames: still, with every
# shadow map drawn each frame (`--no-shadow-cache`), with the camera stepping 0.37 m a frame,
# stepping so with cascade cells of at least a 16th of a box (`--snap-cells 16`; only with
# PENUMBRA), and stepping so over the sun's clipmap (`--layout clipmap`: 6 levels, the finest
# 32 m) in place of its cascades. With a second binary BASE, each run is repeated with it (the
# code before, in the same session).
#
#   bash docs/bench/scale.sh [PENUMBRA] [OUT] [BASE]
#
# PENUMBRA is the binary (default target/release/penumbra); OUT the folder for the outputs
# (default out/scale). Run it from the repository root.
set -euo pipefail
BIN=${1:-target/release/penumbra}
OUT=${2:-out/scale}
BASE=${3:-}
mkdir -p "$OUT"
render() {
  local bin=$1 name=$2 scene=$3
  shift 3
  "$bin" render "$scene" --width 1920 --height 1080 --frames 30 --json --out "$OUT/image.png" "$@" > "$OUT/$name.json"
}
for scene in assets/scenes/field.ron assets/bench/many_boxes.ron assets/bench/million.ron; do
  s=$(basename "$scene" .ron)
  for b in new ${BASE:+base}; do
    bin=$BIN
    [ "$b" = base ] && bin=$BASE
    render "$bin" "$s-$b-still" "$scene"
    render "$bin" "$s-$b-nocache" "$scene" --no-shadow-cache
    render "$bin" "$s-$b-moving" "$scene" --camera-step 0,0,-0.37
    [ "$b" = new ] && render "$bin" "$s-$b-moving-cells16" "$scene" --camera-step 0,0,-0.37 --snap-cells 16
    render "$bin" "$s-$b-clipmap-moving" "$scene" --camera-step 0,0,-0.37 --layout clipmap
  done
done
# One line per run: the shadow maps, the prepass and the lighting pass (medians of frames 2–30
# of each pass, ms; a pass absent from a frame, a shadow map held, is not counted in it), the
# whole GPU frame (each frame's passes summed: median and mean of frames 2–30, ms; from binaries
# before whole frames were reported, the sum of the pass medians twice), the draw commands and
# draws of the last frame, and the CPU time of the shadow systems (median of frames 2–30, ms;
# absent from binaries before it was reported).
python3 - "$OUT" <<'PY'
import json, pathlib, sys
out = pathlib.Path(sys.argv[1])
print(f"{'run':30} {'shadow':>8} {'prepass':>8} {'forward':>8} {'median':>8} {'mean':>8} {'commands':>9} {'draws':>7} {'cpu':>7}")
for f in sorted(out.glob("*.json")):
    j = json.loads(f.read_text())
    p = {x["pass"]: x["ms"] for x in j["gpu_ms"]["passes"]}
    shadow = sum(v for k, v in p.items() if k.startswith("shadow"))
    total = j["gpu_ms"]["total"] or 0
    frames = j["gpu_ms"].get("frames") or {"median": total, "mean": total}
    print(f"{f.stem:30} {shadow:8.3f} {p.get('depth prepass', 0):8.3f} {p.get('forward', 0):8.3f} "
          f"{frames['median']:8.3f} {frames['mean']:8.3f} "
          f"{j['draw_calls']:9} {j.get('draws', j['draw_calls']):7} {j['cpu_ms'].get('shadow_systems_median') or 0:7.3f}")
PY
