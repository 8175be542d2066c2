#!/usr/bin/env python3
"""Writes a scene of N + 1 lights to standard output, for measuring scenes with many lights
(docs/benchmarks.md, "Any number of lights"): N dim lights, spot and point in turn, 3.9 m
apart in rows of 100 over a 400 m ground (moved 40 m off its middle), then one strong red
point light over the middle, last in the list.

Usage: python3 assets/bench/make_lights.py N > lights.ron
"""

import sys


def light(i):
    x = -195.0 + (i % 100) * 3.9
    z = -195.0 + (i // 100) * 3.9
    if abs(x) < 20 and abs(z) < 20:
        z += 40
    if i % 2:
        return f"Point(position: ({x}, 2, {z}), intensity: 0.5, range: 3)"
    return f"Spot(position: ({x}, 3, {z}), direction: (0, -1, 0), intensity: 0.5, range: 4, outer_angle: 40)"


def main():
    n = int(sys.argv[1])
    lights = [light(i) for i in range(n)]
    lights.append("Point(position: (0, 2, 0), color: (1, 0, 0), intensity: 200, range: 10)")
    print("""Scene(
    camera: (position: (0, 30, 0.1), target: (0, 0, 0), fov: 40, near: 0.1, far: 100),
    ambient: (0.01, 0.01, 0.01),
    lights: [%s],
    materials: { "m": (base_color: (0.8, 0.8, 0.8, 1)) },
    objects: [
        (shape: Plane(size: (400, 400)), material: "m"),
        (shape: Cuboid(size: (1, 1, 1)), material: "m", translation: (60, 0.5, 60)),
    ],
)""" % ",\n".join(lights))


if __name__ == "__main__":
    main()
