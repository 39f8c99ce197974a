#!/usr/bin/env python3
"""Writes assets/scenes/models/flange.obj: a CAD-like machined part for the ChromaDepth
gallery (the ChromaDepth article's "Mechanical CAD" image): a flanged hub turned on a lathe
(a profile revolved about Y, with a bore through it) and six hexagonal bolt heads on the
flange. Sharp edges stay sharp: every face of the profile gets its own vertices and normals.

Usage: python3 tools/make_cad_part.py assets/scenes/models/flange.obj
Written by stereolab's authors; the same licence as stereolab (MIT).
"""
import math
import sys

SEGMENTS = 48
# The profile in (radius, height), counter-clockwise seen with r to the right and y up, so its
# outward normal is (dy, -dr) per edge: bore, flange, hub with a chamfer.
PROFILE = [
    (1.0, -1.5), (4.0, -1.5), (4.0, -0.9), (1.8, -0.9), (1.8, 1.3), (1.6, 1.5), (1.0, 1.5),
]

verts, norms, faces = [], [], []


def add_vertex(p, n):
    verts.append(p)
    norms.append(n)
    return len(verts)


def quad(a, b, c, d):
    faces.append((a, b, c))
    faces.append((a, c, d))


def revolve():
    loop = PROFILE + PROFILE[:1]
    for (r0, y0), (r1, y1) in zip(loop, loop[1:]):
        dr, dy = r1 - r0, y1 - y0
        length = math.hypot(dr, dy)
        nr, ny = dy / length, -dr / length  # outward (right of the direction of travel)
        ring = []
        for s in range(SEGMENTS + 1):
            a = 2 * math.pi * s / SEGMENTS
            c, si = math.cos(a), -math.sin(a)
            n = (nr * c, ny, nr * si)
            ring.append((add_vertex((r0 * c, y0, r0 * si), n), add_vertex((r1 * c, y1, r1 * si), n)))
        for s in range(SEGMENTS):
            (a0, a1), (b0, b1) = ring[s], ring[s + 1]
            quad(a0, b0, b1, a1)


def hex_bolt(cx, cz, y0, height, radius):
    corners = [
        (cx + radius * math.cos(math.pi / 3 * k), cz - radius * math.sin(math.pi / 3 * k))
        for k in range(6)
    ]
    y1 = y0 + height
    for k in range(6):
        (xa, za), (xb, zb) = corners[k], corners[(k + 1) % 6]
        mx, mz = (xa + xb) / 2 - cx, (za + zb) / 2 - cz
        m = math.hypot(mx, mz)
        n = (mx / m, 0.0, mz / m)
        quad(add_vertex((xa, y0, za), n), add_vertex((xb, y0, zb), n),
             add_vertex((xb, y1, zb), n), add_vertex((xa, y1, za), n))
    top = [add_vertex((x, y1, z), (0.0, 1.0, 0.0)) for x, z in corners]
    for k in range(1, 5):
        faces.append((top[0], top[k], top[k + 1]))


def main():
    revolve()
    for k in range(6):
        a = 2 * math.pi * k / 6 + math.pi / 6
        hex_bolt(3.0 * math.cos(a), -3.0 * math.sin(a), -0.9, 0.35, 0.38)
    with open(sys.argv[1], "w") as f:
        f.write("# A flanged hub with six bolt heads (tools/make_cad_part.py; MIT, stereolab)\n")
        for x, y, z in verts:
            f.write(f"v {x:.5f} {y:.5f} {z:.5f}\n")
        for x, y, z in norms:
            f.write(f"vn {x:.5f} {y:.5f} {z:.5f}\n")
        for a, b, c in faces:
            f.write(f"f {a}//{a} {b}//{b} {c}//{c}\n")


if __name__ == "__main__":
    main()
