#!/usr/bin/env python3
"""Writes, into folder DIR, two different 8192² PNGs (each at the per-image decode limit) and
`textures.ron`, a scene that uses both: the texture-budget case of docs/scene-format.md
("Files a scene may read").

Usage: python3 assets/bench/make_textures.py DIR
then:  /usr/bin/time -f %M penumbra render DIR/textures.ron --frames 2 --asset-root DIR
"""

import os
import struct
import sys
import zlib

SIDE = 8192


def png(path, rgba):
    """A SIDE² PNG of one colour (RGBA8, no filter)."""
    row = b"\x00" + bytes(rgba) * SIDE
    data = zlib.compress(row * SIDE, 1)

    def chunk(kind, body):
        crc = zlib.crc32(kind + body) & 0xFFFFFFFF
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", crc)

    header = struct.pack(">IIBBBBB", SIDE, SIDE, 8, 6, 0, 0, 0)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", data) + chunk(b"IEND", b""))


SCENE = """Scene(
    camera: (position: (0, 4, 8), target: (0, 0, 0), fov: 60, near: 0.1, far: 100),
    sun: (direction: (0, -1, 0.2)),
    materials: { "a": (texture: "big_a.png"), "b": (texture: "big_b.png") },
    objects: [
        (shape: Plane(size: (10, 10)), material: "a"),
        (shape: Cuboid(size: (1, 1, 1)), material: "b", translation: (0, 0.5, 0)),
    ],
)
"""

if __name__ == "__main__":
    folder = sys.argv[1]
    os.makedirs(folder, exist_ok=True)
    png(os.path.join(folder, "big_a.png"), [200, 40, 40, 255])
    png(os.path.join(folder, "big_b.png"), [40, 200, 40, 255])
    with open(os.path.join(folder, "textures.ron"), "w") as f:
        f.write(SCENE)
