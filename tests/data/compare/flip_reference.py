"""ꟻLIP's own Python package (PyPI's flip-evaluator, NVIDIA's reference implementation) on
two LDR images: prints the mean error and writes the error map as little-endian f32, row by
row from the top left.

usage: flip_reference.py REFERENCE.png TEST.png PPD OUT.f32
"""
import sys

import flip_evaluator
import numpy as np
from PIL import Image


def load(path):
    return np.asarray(Image.open(path).convert("RGB"), dtype=np.float32) / 255.0


error_map, mean, _ = flip_evaluator.evaluate(
    load(sys.argv[1]),
    load(sys.argv[2]),
    "LDR",
    applyMagma=False,
    parameters={"ppd": float(sys.argv[3])},
)
np.ascontiguousarray(error_map[:, :, 0], dtype="<f4").tofile(sys.argv[4])
print(f"{mean:.9f}")
