#!/usr/bin/env python3
"""Writes `many_boxes.ron`: the 100k field's layout with boxes only, each of its own size, so
the scene has thousands of distinct meshes (a `Cuboid` is one mesh per size). 2 120 box sizes
(0.3-1.2 m wide, 0.4-2 m tall, to the millimetre, no two alike), each placed 48 times on an
8 x 6 grid of 48 m x 64 m cells with 20 m x 28 m of jitter, over the field's 384 m square:
101 760 boxes standing on a 500 m ground.

    python3 assets/bench/make_many_boxes.py
"""
import random
from pathlib import Path

HERE = Path(__file__).parent
SIZES = 2120


def sizes(rng):
    seen = set()
    while len(seen) < SIZES:
        w = round(rng.uniform(0.3, 1.2), 3)
        h = round(rng.uniform(0.4, 2.0), 3)
        d = round(rng.uniform(0.3, 1.2), 3)
        seen.add((w, h, d))
    return sorted(seen)


def main():
    rng = random.Random(7)
    lines = []
    for n, (w, h, d) in enumerate(sizes(rng)):
        x = round(-192 + rng.uniform(0, 48), 2)
        z = round(-192 + rng.uniform(0, 64), 2)
        lines.append(
            f'        (shape: Cuboid(size: ({w}, {h}, {d})), material: "rock", translation: ({x}, {h / 2}, {z}), '
            f"grid: (count: (8, 1, 6), spacing: (48, 0, 64), jitter: (seed: {n}, offset: (20, 0, 28), yaw: 180))),"
        )
    text = f"""// Written by `python3 assets/bench/make_many_boxes.py`: the 100k field's layout with
// boxes only, each size its own mesh. {SIZES} box sizes, 48 copies each: {SIZES * 48} boxes
// over a 384 m square on a 500 m ground, under a 4-cascade sun. Today every mesh is its own
// draw in every view; batching distinct meshes into one multi-draw is what this scene tests.
Scene(
    camera: (position: (0, 3, 196), target: (0, 0.5, 150), fov: 65, near: 0.1, far: 600),
    sun: (direction: (-0.6, -0.65, -0.45), color: (1.0, 0.97, 0.92), illuminance: 3.0),
    ambient: (0.06, 0.07, 0.09),
    shadows: (mode: Pcf, cascade_count: 4, resolution: 2048, max_distance: 150, split_lambda: 0.75),
    materials: {{
        "grass": (base_color: (0.22, 0.36, 0.14, 1)),
        "rock": (base_color: (0.5, 0.48, 0.45, 1)),
    }},
    objects: [
        (shape: Plane(size: (500, 500)), material: "grass", cast_shadows: false),
{chr(10).join(lines)}
    ],
)
"""
    (HERE / "many_boxes.ron").write_text(text)


if __name__ == "__main__":
    main()
