#!/usr/bin/env python3
"""Converts matplotlib's two terrain sample data sets into the 16-bit PNG height grids that
stereolab's `dem` mesh kind reads (assets/scenes/terrain/README.md says where they come from).

Usage: python3 tools/convert_mpl_terrain.py SAMPLE_DATA_DIR OUT_DIR

SAMPLE_DATA_DIR is `matplotlib/mpl-data/sample_data` from matplotlib's wheel
(`pip download --no-deps matplotlib`, then unzip the wheel). Standard library only (no numpy):
the .npz files are zip archives of .npy arrays, read here by their documented header.

Each grid becomes a 16-bit grayscale PNG, row 0 = north, column 0 = west, sample value
`round(height_m - offset_m)` (one metre per step), and the script prints the numbers a scene
needs: the grid's size on the ground in kilometres and the heights of gray 0 and 65535.
"""
import array
import ast
import math
import struct
import sys
import zipfile
import zlib


def load_npz(path):
    """{name: (shape, values as a flat list)} for every array of a .npz file."""
    out = {}
    with zipfile.ZipFile(path) as z:
        for name in z.namelist():
            b = z.read(name)
            if b[:6] != b"\x93NUMPY":
                raise SystemExit(f"{path}:{name}: not a .npy array")
            major = b[6]
            if major == 1:
                (hl,), off = struct.unpack("<H", b[8:10]), 10
            else:
                (hl,), off = struct.unpack("<I", b[8:12]), 12
            header = ast.literal_eval(b[off : off + hl].decode("latin-1"))
            if header["fortran_order"]:
                raise SystemExit(f"{path}:{name}: Fortran order not supported")
            code = {"<i2": "h", "<f4": "f", "<f8": "d"}[header["descr"]]
            values = array.array(code)
            values.frombytes(b[off + hl :])
            out[name[: -len(".npy")]] = (header["shape"], list(values))
    return out


def write_png16(path, width, height, samples):
    """A 16-bit grayscale PNG (big-endian samples, filter 0 on every row)."""
    raw = bytearray()
    for r in range(height):
        raw.append(0)
        for v in samples[r * width : (r + 1) * width]:
            raw += struct.pack(">H", v)

    def chunk(kind, data):
        c = struct.pack(">I", len(data)) + kind + data
        return c + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    png = b"\x89PNG\r\n\x1a\n"
    png += chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 16, 0, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(bytes(raw), 9))
    png += chunk(b"IEND", b"")
    with open(path, "wb") as f:
        f.write(png)


def km_per_degree(lat_deg):
    """Length of one degree of longitude and of latitude at `lat_deg`, km (WGS84 sphere-ish:
    111.32 km per degree of latitude, times cos(latitude) for longitude)."""
    return 111.32 * math.cos(math.radians(lat_deg)), 111.32


def convert(name, rows, cols, heights, lon, lat, out_dir):
    offset = math.floor(min(heights))
    samples = [int(round(h - offset)) for h in heights]
    if max(samples) > 65535:
        raise SystemExit(f"{name}: relief over 65535 m")
    write_png16(f"{out_dir}/{name}.png", cols, rows, samples)
    mid_lat = 0.5 * (lat[0] + lat[1])
    kx, ky = km_per_degree(mid_lat)
    width_km = abs(lon[1] - lon[0]) * kx
    depth_km = abs(lat[1] - lat[0]) * ky
    print(
        f"{name}.png: {cols}x{rows}, lon {lon[0]:.5f}..{lon[1]:.5f}, lat {lat[0]:.5f}..{lat[1]:.5f}\n"
        f"  ground {width_km:.2f} km east x {depth_km:.2f} km north; heights {min(heights):.1f}..{max(heights):.1f} m\n"
        f"  scene: extent = [{width_km:.2f}, {depth_km:.2f}], heights = [{offset / 1000:.3f}, {(offset + 65535) / 1000:.3f}] (km)"
    )


def main():
    src, out_dir = sys.argv[1], sys.argv[2]
    d = load_npz(f"{src}/jacksboro_fault_dem.npz")
    (rows, cols), elev = d["elevation"]
    # The file's cell edges: xmin..xmax west to east; its "ymin" is the north edge (row 0).
    lon = (d["xmin"][1][0], d["xmax"][1][0])
    lat = (d["ymin"][1][0], d["ymax"][1][0])
    convert("jacksboro_fault_dem", rows, cols, elev, lon, lat, out_dir)

    d = load_npz(f"{src}/topobathy.npz")
    (rows, cols), topo = d["topo"]
    lons, lats = d["longitude"][1], d["latitude"][1]
    # Latitude rows as stored; flip so row 0 is north.
    if lats[0] < lats[-1]:
        topo = [v for r in range(rows - 1, -1, -1) for v in topo[r * cols : (r + 1) * cols]]
        lats = lats[::-1]
    convert("topobathy", rows, cols, topo, (lons[0], lons[-1]), (lats[0], lats[-1]), out_dir)


if __name__ == "__main__":
    main()
