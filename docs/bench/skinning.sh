#!/bin/bash
# Reproduces the skinning figures of docs/benchmarks.md ("Skinned casters"): the walkers
# bench (1 000 walkers, 2 000 skinned meshes) at 1920×1080, 30 frames, moving (every walker
# posed and skinned each frame, the views it touches redrawn) and held still
# (`--animation-speed 0`: nothing skinned after the first frame, the cached shadow maps kept),
# each with and without the shadow cache; and the same crowd four times as large (4 000
# walkers, the grid doubled both ways, in a scene written next to the bench and removed after).
#
#   bash docs/bench/skinning.sh [PENUMBRA] [OUT]
#
# PENUMBRA is the binary (default target/release/penumbra); OUT the folder for the outputs
# (default out/skinning). Run it from the repository root.
set -euo pipefail
BIN=${1:-target/release/penumbra}
OUT=${2:-out/skinning}
mkdir -p "$OUT"
BIG=assets/bench/walkers_4000.tmp.ron
trap 'rm -f "$BIG"' EXIT
sed 's/count: (40, 1, 25)/count: (80, 1, 50)/' assets/bench/walkers.ron > "$BIG"
render() {
  local name=$1 scene=$2
  shift 2
  "$BIN" render "$scene" --width 1920 --height 1080 --frames 30 --json --out "$OUT/image.png" "$@" > "$OUT/$name.json"
}
for crowd in 1000 4000; do
  scene=assets/bench/walkers.ron
  [ "$crowd" = 4000 ] && scene=$BIG
  render "walkers-$crowd-moving" "$scene"
  render "walkers-$crowd-still" "$scene" --animation-speed 0
  render "walkers-$crowd-moving-nocache" "$scene" --no-shadow-cache
  render "walkers-$crowd-still-nocache" "$scene" --animation-speed 0 --no-shadow-cache
done
# One line per run: the skinning pass, the shadow passes, the prepass and lighting, the total
# (medians over frames 2–30, ms), and the shadow views drawn in the last frame.
python3 - "$OUT" <<'PY'
import json, pathlib, sys
out = pathlib.Path(sys.argv[1])
print(f"{'run':32} {'skin':>7} {'shadow':>7} {'prepass':>7} {'forward':>7} {'total':>7} views posed")
for f in sorted(out.glob("walkers-*.json")):
    j = json.loads(f.read_text())
    p = {x["pass"]: x["ms"] for x in j["gpu_ms"]["passes"]}
    shadow = sum(v for k, v in p.items() if k.startswith("shadow"))
    views = j["shadow_views_drawn_per_frame"][-1]
    posed = j["skinned_meshes_posed_per_frame"][-1]
    print(f"{f.stem:32} {p.get('skinning', 0):7.3f} {shadow:7.3f} {p.get('depth prepass', 0):7.3f} "
          f"{p.get('forward', 0):7.3f} {j['gpu_ms']['total']:7.3f} {views:5} {posed:5}")
PY
