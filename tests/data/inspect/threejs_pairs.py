"""Stereo pairs made outside stereolab: a textured sphere and box in front of a textured wall,
ray cast in numpy through three.js's StereoCamera matrices (examples: three.js
src/cameras/StereoCamera.js, MIT licence; the formulas are restated below), with planted
mistakes. Each pair is written as NAME_left.png and NAME_right.png.

usage: threejs_pairs.py OUT_DIR

Pairs:
  correct      off-axis (three.js's StereoCamera), parallax inside the budget
  swapped      the correct pair's views exchanged
  toe_in       both cameras turned toward the focus point, symmetric frusta
  misaligned   the right camera pitched down 0.4 degrees (the view about 2.5 px lower)
  rotated      the right camera rolled 0.4 degrees about its axis
  flat         eye separation 1/200 of the correct one: no visible depth
  window       the sphere moved in front of the screen, cut by the left edge
"""
import math
import os
import sys

import numpy as np
from PIL import Image

W, H = 480, 360
FOV = 50.0  # vertical, degrees (three.js's PerspectiveCamera.fov)
NEAR, FAR = 0.1, 100.0
FOCUS = 6.0  # three.js's camera.focus: the zero-parallax distance
EYE_SEP = 0.2  # three.js's StereoCamera.eyeSep


def perspective(xmin, xmax, ymin, ymax, near, far):
    """three.js's Matrix4.makePerspective (WebGL clip space), column vectors."""
    return np.array(
        [
            [2 * near / (xmax - xmin), 0, (xmax + xmin) / (xmax - xmin), 0],
            [0, 2 * near / (ymax - ymin), (ymax + ymin) / (ymax - ymin), 0],
            [0, 0, -(far + near) / (far - near), -2 * far * near / (far - near)],
            [0, 0, -1, 0],
        ]
    )


def stereo_camera(eye_sep, focus, toe_in=False):
    """(projection, eye's camera-to-world) of the left and right eye, as StereoCamera.update:
    eyes at -/+ eyeSep/2 on the camera's x axis, each frustum shifted toward the middle by
    eyeSepOnProjection = (eyeSep/2)·near/focus. With toe_in the frusta stay symmetric and
    each eye turns toward the point at `focus` on the axis."""
    ymax = NEAR * math.tan(math.radians(FOV / 2))
    aspect = W / H
    half = eye_sep / 2
    shift = 0.0 if toe_in else half * NEAR / focus
    eyes = []
    for side in (-1, 1):
        proj = perspective(-ymax * aspect - side * shift, ymax * aspect - side * shift, -ymax, ymax, NEAR, FAR)
        pose = np.eye(4)
        pose[0, 3] = side * half
        if toe_in:
            a = side * math.atan2(half, focus)  # turn toward the axis
            c, s = math.cos(a), math.sin(a)
            pose[:3, :3] = np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
        eyes.append((proj, pose))
    return eyes


def rotate(pose, axis, degrees):
    a = math.radians(degrees)
    c, s = math.cos(a), math.sin(a)
    r = {"x": [[1, 0, 0], [0, c, -s], [0, s, c]], "z": [[c, -s, 0], [s, c, 0], [0, 0, 1]]}[axis]
    out = pose.copy()
    out[:3, :3] = pose[:3, :3] @ np.array(r)
    return out


def cells(u, v, size, seed):
    """A value per texture cell of `size`: a hash of the cell's integer coordinates."""
    i = np.floor(u / size).astype(np.int64)
    j = np.floor(v / size).astype(np.int64)
    h = (i * 73856093) ^ (j * 19349663) ^ seed
    h = (h ^ (h >> 13)) * 1274126177
    return ((h ^ (h >> 16)) & 0xFFFF) / 65535.0


def render(proj, pose, sphere_centre):
    """Ray casts the scene through the inverse of projection · view for every pixel centre."""
    xs = (np.arange(W) + 0.5) / W * 2 - 1
    ys = 1 - (np.arange(H) + 0.5) / H * 2
    nx, ny = np.meshgrid(xs, ys)
    inv = np.linalg.inv(proj @ np.linalg.inv(pose))
    def unproject(z):
        p = np.stack([nx, ny, np.full_like(nx, z), np.ones_like(nx)], axis=-1) @ inv.T
        return p[..., :3] / p[..., 3:]
    a, b = unproject(-1.0), unproject(1.0)
    d = b - a
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    o = a
    colour = np.zeros((H, W, 3))
    best = np.full((H, W), np.inf)
    # The wall: z = -12, blue-green cells.
    t = (-12.0 - o[..., 2]) / d[..., 2]
    p = o + t[..., None] * d
    v = cells(p[..., 0], p[..., 1], 0.09, 11)
    wall = np.stack([0.15 + 0.25 * v, 0.35 + 0.45 * v, 0.55 + 0.4 * v], axis=-1)
    hit = t > 0
    colour[hit] = wall[hit]
    best[hit] = t[hit]
    # A box: x in [1, 2.6], y in [-1.6, 0], z in [-8, -6.5], green-yellow cells.
    lo, hi = np.array([1.0, -1.6, -8.0]), np.array([2.6, 0.0, -6.5])
    with np.errstate(divide="ignore", invalid="ignore"):
        t0 = (lo - o) / d
        t1 = (hi - o) / d
    tmin = np.max(np.minimum(t0, t1), axis=-1)
    tmax = np.min(np.maximum(t0, t1), axis=-1)
    hit = (tmax >= tmin) & (tmin > 0) & (tmin < best)
    p = o + tmin[..., None] * d
    v = cells(p[..., 0] + p[..., 2], p[..., 1] - p[..., 2], 0.05, 5)
    box = np.stack([0.45 + 0.45 * v, 0.6 + 0.35 * v, 0.1 + 0.1 * v], axis=-1)
    colour[hit] = box[hit]
    best[hit] = tmin[hit]
    # The sphere: radius 1.1, orange-red cells in longitude and latitude.
    c = np.array(sphere_centre)
    oc = o - c
    bq = np.sum(oc * d, axis=-1)
    cq = np.sum(oc * oc, axis=-1) - 1.1**2
    disc = bq * bq - cq
    with np.errstate(invalid="ignore"):
        t = -bq - np.sqrt(disc)
    hit = (disc > 0) & (t > 0) & (t < best)
    n = (o + t[..., None] * d - c) / 1.1
    lon = np.arctan2(n[..., 0], n[..., 2])
    lat = np.arcsin(np.clip(n[..., 1], -1, 1))
    v = cells(lon, lat, 0.07, 3)
    sphere = np.stack([0.65 + 0.35 * v, 0.25 + 0.35 * v, 0.05 + 0.15 * v], axis=-1)
    colour[hit] = sphere[hit]
    return (np.clip(colour, 0, 1) * 255 + 0.5).astype(np.uint8)


def save(out, name, left, right):
    Image.fromarray(left).save(os.path.join(out, f"{name}_left.png"))
    Image.fromarray(right).save(os.path.join(out, f"{name}_right.png"))


def pair(eyes, sphere=(-1.2, 0.2, -5.0)):
    return [render(p, pose, sphere) for p, pose in eyes]


def main():
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    eyes = stereo_camera(EYE_SEP, FOCUS)
    left, right = pair(eyes)
    save(out, "correct", left, right)
    save(out, "swapped", right, left)
    save(out, "toe_in", *pair(stereo_camera(EYE_SEP, FOCUS, toe_in=True)))
    (pl, ll), (pr, lr) = eyes
    save(out, "misaligned", left, render(pr, rotate(lr, "x", 0.4), (-1.2, 0.2, -5.0)))
    save(out, "rotated", left, render(pr, rotate(lr, "z", 0.4), (-1.2, 0.2, -5.0)))
    save(out, "flat", *pair(stereo_camera(EYE_SEP / 200, FOCUS)))
    save(out, "window", *pair(eyes, sphere=(-2.9, 0.0, -4.2)))


if __name__ == "__main__":
    main()
