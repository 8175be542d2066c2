#!/usr/bin/env python3
"""Generates foliage.png: a 128x128 RGBA card of green leaves on a transparent background,
for alpha-masked foliage (`alpha: Mask(0.5)`). Uses only the standard library (zlib, struct)
and a fixed-seed generator, so the output is identical on every run.

    python3 assets/textures/make_foliage.py            # writes foliage.png next to this file
    python3 assets/textures/make_foliage.py out.png    # writes elsewhere
"""

import math
import os
import struct
import sys
import zlib

SIZE = 128


class Lcg:
    """A tiny deterministic generator (Numerical Recipes LCG), independent of Python's."""

    def __init__(self, seed):
        self.state = seed & 0xFFFFFFFF

    def unit(self):
        self.state = (1664525 * self.state + 1013904223) & 0xFFFFFFFF
        return self.state / 2**32

    def range(self, lo, hi):
        return lo + (hi - lo) * self.unit()


def leaves(rng):
    """Leaves as (centre x, centre y, half length, half width, angle, shade), along a few
    stems that rise from the bottom of the card."""
    out = []
    for stem in range(4):
        x = 20 + stem * 29 + rng.range(-6, 6)
        y = SIZE - 2.0
        heading = -math.pi / 2 + rng.range(-0.35, 0.35)
        for _ in range(7):
            x += math.cos(heading) * 14
            y += math.sin(heading) * 14
            heading += rng.range(-0.3, 0.3)
            for side in (-1, 1):
                angle = heading + side * rng.range(0.5, 1.1)
                length = rng.range(9, 15)
                cx = x + math.cos(angle) * length
                cy = y + math.sin(angle) * length
                out.append((cx, cy, length, length * rng.range(0.35, 0.5), angle, rng.range(0.75, 1.15)))
        out.append((x, y, 8, 4, heading, 1.1))
    return out


def render():
    rng = Lcg(20240611)
    shapes = leaves(rng)
    pixels = bytearray(SIZE * SIZE * 4)
    for py in range(SIZE):
        for px in range(SIZE):
            best = None
            for cx, cy, a, b, angle, shade in shapes:
                dx, dy = px + 0.5 - cx, py + 0.5 - cy
                u = (dx * math.cos(angle) + dy * math.sin(angle)) / a
                v = (-dx * math.sin(angle) + dy * math.cos(angle)) / b
                r = math.sqrt(u * u + v * v)
                # Distance to the leaf edge in pixels, roughly; positive inside.
                inside = (1.0 - r) * b
                if best is None or inside > best[0]:
                    best = (inside, shade, u, v)
            inside, shade, u, v = best
            alpha = max(0.0, min(1.0, 0.5 + inside))
            vein = 0.8 if abs(v) < 0.08 and abs(u) < 0.9 else 1.0
            light = shade * vein * (0.85 + 0.15 * (1.0 - abs(v)))
            i = (py * SIZE + px) * 4
            pixels[i + 0] = int(min(255, 60 * light))
            pixels[i + 1] = int(min(255, 140 * light))
            pixels[i + 2] = int(min(255, 40 * light))
            pixels[i + 3] = int(round(alpha * 255))
    return pixels


def png(pixels):
    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)

    header = struct.pack(">IIBBBBB", SIZE, SIZE, 8, 6, 0, 0, 0)  # 8-bit RGBA
    rows = b"".join(b"\x00" + bytes(pixels[y * SIZE * 4:(y + 1) * SIZE * 4]) for y in range(SIZE))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(rows, 9))
            + chunk(b"IEND", b""))


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "foliage.png")
    with open(out, "wb") as f:
        f.write(png(render()))
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
