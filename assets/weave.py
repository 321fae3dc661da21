#!/usr/bin/env python3
"""Writes assets/weave.png: one tileable repeat of a plain weave, 64 x 64 pixels.

Run once; the PNG is committed and bundled with include_bytes!. Texture u (x, left to
right) runs along the warp and v (y, top to bottom) along the weft, as the renderer maps
them: warp yarns lie along x, weft yarns along y. The repeat holds 4 warp and 4 weft yarns
(16 px each); warp yarns are a shade lighter and warmer than weft yarns, so the warp
direction stays visible when the texture is tinted. The image is an sRGB multiplier for the
fabric colour: 1.0 is the yarn's crown, shadows between yarns are darker.
Only the standard library is used (no PIL), so it runs anywhere.
"""
import math
import random
import struct
import zlib

SIZE = 64
YARNS = 4
PITCH = SIZE // YARNS  # pixels per yarn

random.seed(5)
# Per-yarn brightness jitter: tileable because it is indexed by yarn, not by pixel.
warp_jitter = [1.0 + random.uniform(-0.05, 0.05) for _ in range(YARNS)]
weft_jitter = [1.0 + random.uniform(-0.05, 0.05) for _ in range(YARNS)]
WARP = (1.00, 0.97, 0.92)
WEFT = (0.86, 0.86, 0.88)


def profile(t):
    """Brightness across a yarn, t in [0, 1): a rounded crown with dark gaps at the sides."""
    return 0.35 + 0.65 * math.sin(math.pi * t) ** 0.6


def along(t):
    """Brightness along a floating yarn between two crossings: it dips where it goes under."""
    return 0.80 + 0.20 * math.sin(math.pi * t) ** 0.5


def pixel(x, y):
    warp_index, warp_t = divmod(y + 0.5, PITCH)  # warp yarns run along x: indexed by row
    weft_index, weft_t = divmod(x + 0.5, PITCH)
    warp_index, weft_index = int(warp_index), int(weft_index)
    warp_t, weft_t = warp_t / PITCH, weft_t / PITCH
    # Plain weave: the warp is on top where the yarn indices have equal parity.
    if (warp_index + weft_index) % 2 == 0:
        shade = profile(warp_t) * along(weft_t) * warp_jitter[warp_index]
        colour = WARP
    else:
        shade = profile(weft_t) * along(warp_t) * weft_jitter[weft_index]
        colour = WEFT
    # Fine fibre streaks along each yarn.
    streak = 1.0 + 0.04 * math.sin(2 * math.pi * 3 * (warp_t if colour is WARP else weft_t) + 1.3)
    return tuple(max(0, min(255, round(255 * c * shade * streak))) for c in colour)


def png(width, height, rows):
    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)

    raw = b"".join(b"\x00" + bytes(v for p in row for v in p) for row in rows)
    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)  # 8-bit RGB
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")


if __name__ == "__main__":
    import os

    rows = [[pixel(x, y) for x in range(SIZE)] for y in range(SIZE)]
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "weave.png")
    with open(path, "wb") as f:
        f.write(png(SIZE, SIZE, rows))
    print(f"wrote {path}")
