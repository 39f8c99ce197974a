"""OpenCV's StereoSGBM on a left/right pair: writes the disparity map as little-endian f32
in stereolab's sign (x_right - x_left), NaN where OpenCV found none.

usage: opencv_sgbm.py LEFT.png RIGHT.png RANGE OUT.f32
"""
import sys

import cv2
import numpy as np

left = cv2.imread(sys.argv[1], cv2.IMREAD_GRAYSCALE)
right = cv2.imread(sys.argv[2], cv2.IMREAD_GRAYSCALE)
r = int(sys.argv[3])
# numDisparities must be a multiple of 16; search -n/2 .. n/2 - 1 around zero.
n = 16 * ((2 * r + 15) // 16 + 1)
block = 5
sgbm = cv2.StereoSGBM_create(
    minDisparity=-n // 2,
    numDisparities=n,
    blockSize=block,
    P1=8 * block * block,
    P2=32 * block * block,
    disp12MaxDiff=1,
    uniquenessRatio=10,
    mode=cv2.STEREO_SGBM_MODE_HH,
)
raw = sgbm.compute(left, right).astype(np.float32)
invalid = raw < (-n // 2) * 16
d = -raw / 16.0
d[invalid] = np.nan
d.astype("<f4").tofile(sys.argv[4])
print(f"opencv {cv2.__version__}: StereoSGBM {left.shape[1]}x{left.shape[0]}, {n} disparities")
