#!/usr/bin/env python3
"""Writes assets/scenes/textures/fig6_init.png: the initialization texture of the SIRDS paper's
Fig. 6 scene (an image instead of a random color field): 160×160 RGB, tileable, a smooth
colored interference of waves with fine grain, deterministic (no random numbers).

Usage: python3 tools/make_init_texture.py assets/scenes/textures/fig6_init.png
Written by stereolab's authors; the same licence as stereolab (MIT).
"""
import math
import struct
import sys
import zlib

N = 160


def pixel(x, y):
    t = 2 * math.pi / N
    a = math.sin(3 * t * x) + math.sin(5 * t * y) + math.sin(t * (4 * x + 7 * y))
    b = math.cos(7 * t * x - 2 * t * y) + math.sin(11 * t * y)
    grain = ((x * 73 + y * 151) ^ (x * y * 13)) % 64 - 32  # fixed fine texture
    r = 128 + 40 * a + grain
    g = 128 + 55 * b - grain / 2
    bl = 128 + 45 * (a - b) / 2 + grain / 2
    return [max(0, min(255, int(round(v)))) for v in (r, g, bl)]


def main():
    raw = bytearray()
    for y in range(N):
        raw.append(0)
        for x in range(N):
            raw += bytes(pixel(x, y))

    def chunk(kind, data):
        c = struct.pack(">I", len(data)) + kind + data
        return c + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", N, N, 8, 2, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(bytes(raw), 9)) + chunk(b"IEND", b"")
    with open(sys.argv[1], "wb") as f:
        f.write(png)


if __name__ == "__main__":
    main()
