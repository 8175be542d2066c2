#!/usr/bin/env python3
"""Writes the city scenes of the accuracy suite: boxes standing on a ground plane (1 m
pillars 1-8 m tall, thin posts, a wall), every caster touching the receiver. One layout per
seed; `city.ron` (seed 1) is the one tuned on, `town.ron` (seed 2, other sun and camera) is
held out and only scored.

    python3 assets/bench/make_city.py
"""
import math
import random
from pathlib import Path

HERE = Path(__file__).parent


def sun_direction(elevation, azimuth):
    """The direction sunlight travels for a sun `elevation` degrees up, from `azimuth`."""
    e, a = math.radians(elevation), math.radians(azimuth)
    return (-math.cos(e) * math.sin(a), -math.sin(e), -math.cos(e) * math.cos(a))


def objects(seed):
    rng = random.Random(seed)
    out = []
    # Pillars on a jittered 4 m grid: 1 m square, 1-8 m tall, standing on the ground.
    for i in range(-4, 5):
        for j in range(-5, 3):
            if rng.random() < 0.3:
                continue
            h = rng.choice([1, 1.5, 2, 3, 4, 5, 6, 8])
            x = i * 4 + rng.uniform(-1, 1)
            z = j * 4 + rng.uniform(-1, 1)
            out.append(f'(shape: Cuboid(size: (1, {h}, 1)), material: "pillar", translation: ({x:.2f}, {h / 2}, {z:.2f})),')
    # Thin posts: 8-12 cm square, 2-3 m tall.
    for _ in range(14):
        w = rng.choice([0.08, 0.1, 0.12])
        h = rng.choice([2, 2.5, 3])
        x, z = rng.uniform(-14, 14), rng.uniform(-18, 8)
        out.append(f'(shape: Cuboid(size: ({w}, {h}, {w})), material: "post", translation: ({x:.2f}, {h / 2}, {z:.2f})),')
    # A wall, 12 m long, 30 cm thick, 3 m tall.
    a = rng.uniform(0, 180)
    out.append(f'(shape: Cuboid(size: (12, 3, 0.3)), material: "wall", translation: ({rng.uniform(-6, 6):.2f}, 1.5, {rng.uniform(-14, -6):.2f}), rotation: (0, {a:.1f}, 0)),')
    return out


def scene(seed, sun, camera, target, comment):
    d = sun_direction(*sun)
    body = "\n        ".join(objects(seed))
    return f"""// {comment}
// Written by assets/bench/make_city.py (seed {seed}); every caster stands on the ground, which
// casts nothing.
Scene(
    camera: (position: {camera}, target: {target}, fov: 60, near: 0.1, far: 500),
    sun: (direction: ({d[0]:.4f}, {d[1]:.4f}, {d[2]:.4f}), illuminance: 3.0, angular_diameter: 0.53),
    ambient: (0.05, 0.05, 0.06),
    materials: {{
        "ground": (base_color: (0.6, 0.6, 0.58, 1)),
        "pillar": (base_color: (0.75, 0.72, 0.66, 1)),
        "post": (base_color: (0.3, 0.3, 0.32, 1)),
        "wall": (base_color: (0.7, 0.5, 0.4, 1)),
    }},
    objects: [
        (shape: Plane(size: (200, 200)), material: "ground", cast_shadows: false),
        {body}
    ],
)
"""


(HERE / "city.ron").write_text(scene(
    1, (35, 30), (4, 11, 16), (0, 0, -4),
    "A city of boxes under a sun 35 degrees up: the accuracy suite's tuning scene."))
(HERE / "town.ron").write_text(scene(
    2, (28, 145), (-10, 7, 14), (2, 1, -6),
    "A town of boxes under a sun 28 degrees up: the accuracy suite's held-out scene."))
