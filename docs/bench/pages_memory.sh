#!/bin/bash
# Reproduces the error-against-memory figures of docs/benchmarks.md ("A sun's virtual
# clipmap"): the bench on the long field (PCF 5×5 and PCSS Medium, errors scored at 960×540)
# for four cascades of 1024², 2048² and 4096², a 6-level clipmap of 836², 1672² and 3344²
# levels, and a 6-level virtual clipmap of 4096², 8192² and 16384² levels in 128² pages with
# pools of 512, 1024 and 2048 pages; then the plot (memory_plot.py) and its table.
#
#   bash docs/bench/pages_memory.sh [PENUMBRA] [OUT]
#
# PENUMBRA is the binary (default target/release/penumbra); OUT the folder for the outputs
# (default out/pages-memory). Run it from the repository root.
set -euo pipefail
BIN=${1:-target/release/penumbra}
OUT=${2:-out/pages-memory}
mkdir -p "$OUT"
bench() { "$BIN" bench --scenes assets/bench/long_field.ron --analysis-width 960 --frames 10 "$@" > /dev/null; }
for r in 1024 2048 4096; do bench --presets pcf2,pcss-medium --resolution $r --out "$OUT/casc-$r"; done
for r in 836 1672 3344; do bench --presets clipmap-pcf,clipmap-pcss --resolution $r --out "$OUT/clip-$r"; done
for v in 4096:512 8192:1024 16384:2048; do
  bench --presets pages-pcf,pages-pcss --virtual-resolution ${v%:*} --pool-pages ${v#*:} --out "$OUT/page-${v%:*}"
done
# NOTE: without python3 here, run this line where it is.
if command -v python3 > /dev/null; then
  python3 "$(dirname "$0")/memory_plot.py" "$OUT/memory.svg" long_field "$OUT"/casc-* "$OUT"/clip-* "$OUT"/page-* | tee "$OUT/memory.md"
fi
