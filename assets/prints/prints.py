#!/usr/bin/env python3
"""Writes the bundled print textures of assets/prints/, one repeat each, tileable.

Run once; the PNGs are committed and bundled with include_bytes! (src/settings/registry.rs).
The bundled fabrics name them in `[appearance.texture]` with the repeat's size on the
cloth; texture u (x, left to right) runs along the warp and v (y, top to bottom) along the
weft. The prints are drawn after the names of Wang, O'Brien and Ramamoorthi's fabrics, not
from their photographs (presets/fabrics/arcsim/README.md says so).

- white-dots-on-black.png: white dots, 3 mm across, on a black ground, half-dropped on a
  10 mm repeat (64 x 64 px).
- pink-ribbon-on-brown.png: pink awareness ribbons on a brown ground, two to a 40 mm
  repeat, half-dropped (128 x 128 px).

Only the standard library is used (no PIL), so it runs anywhere.
"""
import math
import os
import struct
import zlib


def png(width, height, rows):
    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)

    raw = b"".join(b"\x00" + bytes(v for p in row for v in p) for row in rows)
    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)  # 8-bit RGB
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")


def mix(a, b, t):
    return tuple(x + (y - x) * t for x, y in zip(a, b))


def render(size, coverage, ground, ink, samples=4):
    """Each pixel the ground mixed with the ink by the share of its samples `coverage`
    (a function of x, y in repeats, 0..1) says are inked."""
    rows = []
    for py in range(size):
        row = []
        for px in range(size):
            inked = 0
            for sy in range(samples):
                for sx in range(samples):
                    x = (px + (sx + 0.5) / samples) / size
                    y = (py + (sy + 0.5) / samples) / size
                    inked += coverage(x, y)
            c = mix(ground, ink, inked / samples**2)
            row.append(tuple(max(0, min(255, round(v))) for v in c))
        rows.append(row)
    return rows


def tiled_distance(x, y, cx, cy, distance):
    """The least `distance` from (x, y) to a motif centred at (cx, cy) or its copies one
    repeat away."""
    return min(distance(x - cx - i, y - cy - j) for i in (-1, 0, 1) for j in (-1, 0, 1))


def dots(x, y):
    radius = 1.5 / 10.0  # 3 mm across on a 10 mm repeat
    d = min(tiled_distance(x, y, cx, cy, lambda u, v: math.hypot(u, v)) for cx, cy in ((0.25, 0.25), (0.75, 0.75)))
    return 1 if d < radius else 0


# The ribbon's centre line: the nodal cubic x = t² − 1, y = t(t² − 1), turned so that its
# loop is on top (y grows downwards) and its tails cross below it, about 15 mm tall on the 40 mm repeat.
RIBBON = [((t * (t * t - 1)) * 0.11, (t * t - 1) * 0.16 - 0.01) for t in [-1.45 + 2.9 * k / 120 for k in range(121)]]
HALF_WIDTH = 0.022


def to_segment(u, v, a, b):
    (ax, ay), (bx, by) = a, b
    dx, dy = bx - ax, by - ay
    t = max(0.0, min(1.0, ((u - ax) * dx + (v - ay) * dy) / (dx * dx + dy * dy)))
    return math.hypot(u - ax - t * dx, v - ay - t * dy)


def ribbon_distance(u, v):
    if abs(u) > 0.25 or abs(v) > 0.25:
        return 1.0
    return min(to_segment(u, v, RIBBON[k], RIBBON[k + 1]) for k in range(len(RIBBON) - 1))


def ribbons(x, y):
    d = min(tiled_distance(x, y, cx, cy, ribbon_distance) for cx, cy in ((0.25, 0.27), (0.75, 0.77)))
    return 1 if d < HALF_WIDTH else 0


if __name__ == "__main__":
    here = os.path.dirname(os.path.abspath(__file__))
    for name, size, coverage, ground, ink, samples in [
        ("white-dots-on-black.png", 64, dots, (22, 22, 25), (238, 236, 230), 4),
        ("pink-ribbon-on-brown.png", 128, ribbons, (92, 60, 42), (233, 140, 176), 2),
    ]:
        rows = render(size, coverage, ground, ink, samples)
        path = os.path.join(here, name)
        with open(path, "wb") as f:
            f.write(png(size, size, rows))
        print(f"wrote {path}")
