#!/usr/bin/env python3
"""Writes assets/scenes/textures/sirds_mts.png: the texture of the mapped-texture stereogram
scene (sirds_texture.toml): 256×128 RGB, the size of that scene's image, so texel (x, y) lies on
pixel (x, y). A black background (its top-left pixel, the background color) and, where the
scene's sphere is seen, a disc of colored rings and spokes. Deterministic (no random numbers).

Usage: python3 tools/make_mts_texture.py assets/scenes/textures/sirds_mts.png
Written by stereolab's authors; the same licence as stereolab (MIT).
"""
import math
import struct
import sys
import zlib

W, H = 256, 128
CX, CY, R = 128, 64, 52


def pixel(x, y):
    dx, dy = x + 0.5 - CX, y + 0.5 - CY
    r = math.hypot(dx, dy)
    if r > R:
        return [0, 0, 0]
    ring = int(r / 9) % 3
    spoke = int((math.atan2(dy, dx) + math.pi) / (2 * math.pi) * 12) % 2
    base = [[230, 60, 40], [250, 200, 30], [40, 120, 230]][ring]
    if spoke:
        base = [255 - v // 2 for v in base]
    return base


def main():
    raw = bytearray()
    for y in range(H):
        raw.append(0)
        for x in range(W):
            raw.extend(pixel(x, y))

    def chunk(kind, data):
        c = struct.pack(">I", len(data)) + kind + data
        return c + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    png = b"\x89PNG\r\n\x1a\n"
    png += chunk(b"IHDR", struct.pack(">IIBBBBB", W, H, 8, 2, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(bytes(raw), 9))
    png += chunk(b"IEND", b"")
    with open(sys.argv[1], "wb") as f:
        f.write(png)


if __name__ == "__main__":
    main()
