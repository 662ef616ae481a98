#!/usr/bin/env python3
"""The Python way to do `terramesh convert --to utm IN.csv -o OUT.csv` for one zone: pandas +
pyproj's vectorised Transformer. Used by compare_convert.py as the anchor.

Usage: pyproj_convert.py IN.csv OUT.csv EPSG
"""
import sys

import pandas as pd
import pyproj

src, dst, epsg = sys.argv[1], sys.argv[2], int(sys.argv[3])
df = pd.read_csv(src)
t = pyproj.Transformer.from_crs(4326, epsg, always_xy=True)
e, n = t.transform(df["lon"].to_numpy(), df["lat"].to_numpy())
zone = f"{epsg % 100}{'N' if epsg < 32700 else 'S'}"
df["easting"] = e
df["northing"] = n
df["zone"] = zone
df.to_csv(dst, index=False, float_format="%.6f")
