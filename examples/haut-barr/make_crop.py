#!/usr/bin/env python3
"""Cuts the bundled elevation crop of this example from the SRTM tile in ../shared/data.

    python3 examples/haut-barr/make_crop.py     (from the repository root; needs numpy)

Source: ../shared/data/srtm/N48E007.hgt, NASA/USGS Shuttle Radar Topography Mission, SRTM3
(3 arc-second, unfilled), US public domain. "SRTM data courtesy of NASA/USGS".
The crop covers 48.68-48.78 N, 7.28-7.40 E (121 x 145 posts, spacing 1/1200 degree) around the
Haut-Barr castle study area, written as an ESRI ASCII grid whose xllcenter/yllcenter are the
south-west post itself (SRTM posts are pixel-is-point), heights in metres above EGM96.
"""
import os

import numpy as np

here = os.path.dirname(os.path.abspath(__file__))
tile = os.path.join(here, "..", "..", "..", "shared", "data", "srtm", "N48E007.hgt")
z = np.fromfile(tile, dtype=">i2").reshape(1201, 1201)
r0, r1 = 264, 384  # rows: 49 - r/1200 = 48.78 .. 48.68 N
c0, c1 = 336, 480  # cols: 7 + c/1200 = 7.28 .. 7.40 E
crop = z[r0:r1 + 1, c0:c1 + 1]
assert (crop != -32768).all(), "no voids expected near the castle"
with open(os.path.join(here, "srtm-crop.asc"), "w") as fh:
    fh.write(f"ncols {crop.shape[1]}\nnrows {crop.shape[0]}\n")
    fh.write(f"xllcenter {7 + c0 / 1200:.10f}\nyllcenter {49 - r1 / 1200:.10f}\n")
    fh.write(f"cellsize {1 / 1200:.15f}\nNODATA_value -32768\n")
    for row in crop:
        fh.write(" ".join(str(int(v)) for v in row) + "\n")
print("wrote", crop.shape, "min", crop.min(), "max", crop.max())
