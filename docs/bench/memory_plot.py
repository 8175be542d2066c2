#!/usr/bin/env python3
"""Plots penumbra error against shadow memory from bench reports (report.json).

    python3 docs/bench/memory_plot.py OUT.svg SCENE DIR...

Each DIR is a `penumbra bench --out DIR` folder; every preset of every report is one point on
SCENE (a scene's short name, e.g. long_field): x the shadow memory the renderer allocated, y
the penumbra MAE against the ray-traced reference. Points whose preset names share a family
(cascades: pcf*/pcss*, clipmap-*, pages-*) and filter are joined, in order of memory. Writes
a plain SVG (no plotting library needed) and prints the points as a Markdown table.
"""
import json
import math
import sys
from pathlib import Path

COLOURS = {"cascades": "#1f77b4", "clipmap": "#2ca02c", "pages": "#d62728"}


def family(preset):
    if preset.startswith("clipmap-"):
        return "clipmap", preset[len("clipmap-"):]
    if preset.startswith("pages-"):
        return "pages", preset[len("pages-"):]
    return "cascades", "pcss" if preset.startswith("pcss") else "pcf"


def points(scene, dirs):
    out = []
    for d in dirs:
        report = json.loads((Path(d) / "report.json").read_text())
        for p in report["presets"]:
            for s in p["scenes"]:
                if s["scene"] != scene:
                    continue
                fam, filt = family(p["preset"])
                out.append((fam, filt, s["shadow_memory_bytes"] / 2**20, s["errors"]["penumbra_mae"], d))
    return out


def svg(pts, title):
    w, h, m = 640, 420, 60
    xs = [math.log2(p[2]) for p in pts]
    ys = [p[3] for p in pts]
    x0, x1 = math.floor(min(xs)), math.ceil(max(xs))
    y0, y1 = 0.0, max(ys) * 1.15
    fx = lambda v: m + (math.log2(v) - x0) / max(x1 - x0, 1e-9) * (w - 2 * m)
    fy = lambda v: h - m - (v - y0) / (y1 - y0) * (h - 2 * m)
    el = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" font-family="sans-serif" font-size="12">',
          f'<rect width="{w}" height="{h}" fill="white"/>',
          f'<text x="{w / 2}" y="20" text-anchor="middle" font-size="14">{title}</text>',
          f'<line x1="{m}" y1="{h - m}" x2="{w - m}" y2="{h - m}" stroke="black"/>',
          f'<line x1="{m}" y1="{m}" x2="{m}" y2="{h - m}" stroke="black"/>',
          f'<text x="{w / 2}" y="{h - 15}" text-anchor="middle">shadow memory allocated, MiB (log scale)</text>',
          f'<text x="15" y="{h / 2}" text-anchor="middle" transform="rotate(-90 15 {h / 2})">penumbra MAE</text>']
    for e in range(x0, x1 + 1):
        x = fx(2 ** e)
        el.append(f'<line x1="{x}" y1="{h - m}" x2="{x}" y2="{h - m + 5}" stroke="black"/>')
        el.append(f'<text x="{x}" y="{h - m + 18}" text-anchor="middle">{2 ** e}</text>')
    for k in range(6):
        v = y0 + (y1 - y0) * k / 5
        el.append(f'<text x="{m - 6}" y="{fy(v) + 4}" text-anchor="end">{v:.2f}</text>')
        el.append(f'<line x1="{m}" y1="{fy(v)}" x2="{w - m}" y2="{fy(v)}" stroke="#ddd"/>')
    groups = {}
    for p in pts:
        groups.setdefault((p[0], p[1]), []).append(p)
    # NOTE: the legend sits at the bottom right, below the errors (the axis starts at 0).
    legend = 0
    top = h - m - 16 * len(groups) - 8
    for (fam, filt), g in sorted(groups.items()):
        g.sort(key=lambda p: p[2])
        colour = COLOURS[fam]
        dash = "" if filt == "pcf" else ' stroke-dasharray="5,3"'
        path = " ".join(f"{fx(p[2]):.1f},{fy(p[3]):.1f}" for p in g)
        el.append(f'<polyline points="{path}" fill="none" stroke="{colour}"{dash}/>')
        for p in g:
            el.append(f'<circle cx="{fx(p[2]):.1f}" cy="{fy(p[3]):.1f}" r="4" fill="{colour}"/>')
        y = top + 16 * legend
        el.append(f'<line x1="{w - m - 120}" y1="{y}" x2="{w - m - 95}" y2="{y}" stroke="{colour}"{dash}/>')
        el.append(f'<text x="{w - m - 90}" y="{y + 4}">{fam} {filt}</text>')
        legend += 1
    el.append("</svg>")
    return "\n".join(el)


def main():
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    out, scene, dirs = sys.argv[1], sys.argv[2], sys.argv[3:]
    pts = points(scene, dirs)
    if not pts:
        sys.exit(f"no preset was scored on scene {scene!r} in {dirs}")
    Path(out).write_text(svg(pts, f"Penumbra error against shadow memory ({scene})"))
    print("| layout | filter | memory MiB | penumbra MAE | report |")
    print("| --- | --- | ---: | ---: | --- |")
    for p in sorted(pts, key=lambda p: (p[0], p[1], p[2])):
        print(f"| {p[0]} | {p[1]} | {p[2]:.1f} | {p[3]:.4f} | {p[4]} |")


if __name__ == "__main__":
    main()
