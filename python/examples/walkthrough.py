"""The walkthrough of python/README.md as one script: samples of the bundled SRTM crop over
the paper's Haut-Barr region, a variogram fitted to them, a quality mesh of the region,
universal kriging at its vertices, cross-validation, and the picture
python/docs/walkthrough.png (needs matplotlib).

    python python/examples/walkthrough.py     # from the repository root
"""

import pathlib

import numpy as np

import terramesh

ROOT = pathlib.Path(__file__).resolve().parents[2]
CROP = ROOT / "examples" / "haut-barr" / "srtm-crop.asc"
CORNERS = "N48°43'20.64\" E7°20'12.48\"; N48°43'20.64\" E7°20'25.44\"; N48°43'33.6\" E7°20'25.44\"; N48°43'33.6\" E7°20'12.48\""

# 1. Elevations on a 100 x 50 grid over the region enlarged by 10 %, in UTM zone 32N.
s = terramesh.sample(CROP, CORNERS, rows=100, cols=50, margin=0.1)
print(f"{len(s.z)} samples in zone {s.zone}, z {s.z.min():.1f}..{s.z.max():.1f} m")

# 2. A variogram fitted automatically (every model, the best by cross-validation).
v = terramesh.Variogram.fit(s.x, s.y, s.z)
print("variogram:", v)

# 3. A quality mesh of the region itself (its corners projected to the same zone).
lat = [terramesh.utm.parse_dms(c.split()[0]) for c in CORNERS.split(";")]
lon = [terramesh.utm.parse_dms(c.split()[1]) for c in CORNERS.split(";")]
ring = np.column_stack(terramesh.utm.forward(lat, lon, zone="32N")[:2])
mesh = terramesh.mesh([ring], min_angle=30, max_area=40.0, smooth=10)
print(mesh)

# 4. Universal kriging (linear drift, 64 neighbours) at every vertex, and its error estimate.
z, var = terramesh.krige(s.x, s.y, s.z, mesh.points[:, 0], mesh.points[:, 1],
                         method="uk", drift="linear", variogram=v, neighbors=64)
dsm = mesh.with_heights(z)
cv = terramesh.cross_validate(s.x, s.y, s.z, method="uk", variogram=v, neighbors=64)
print(f"DSM {z.min():.1f}..{z.max():.1f} m; leave-one-out RMSE {cv.rmse:.3f} m")

# 5. The picture.
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

fig, ax = plt.subplots(1, 2, figsize=(11, 4.6), constrained_layout=True)
x0, y0 = dsm.points[:, 0].min(), dsm.points[:, 1].min()
px, py = dsm.points[:, 0] - x0, dsm.points[:, 1] - y0
t = ax[0].tripcolor(px, py, dsm.triangles, z, shading="gouraud", cmap="terrain")
ax[0].tricontour(px, py, dsm.triangles, z, levels=12, colors="k", linewidths=0.5)
ax[0].triplot(px, py, dsm.triangles, color="w", lw=0.15, alpha=0.5)
fig.colorbar(t, ax=ax[0], label="UK elevation (m)")
ax[0].set_title(f"Haut-Barr DSM: {len(dsm.triangles)} triangles, min angle {mesh.min_angle.min():.1f}°")
t2 = ax[1].tripcolor(px, py, dsm.triangles, np.sqrt(np.maximum(var, 0)), shading="gouraud", cmap="magma")
ax[1].plot(s.x - x0, s.y - y0, ".", ms=1, color="c")
ax[1].set_xlim(ax[0].get_xlim()); ax[1].set_ylim(ax[0].get_ylim())
fig.colorbar(t2, ax=ax[1], label="kriging standard deviation (m)")
ax[1].set_title("kriging standard deviation, samples")
for a in ax:
    a.set_aspect("equal")
    a.set_xlabel(f"easting − {x0:.0f} m (UTM {mesh.zone or '32N'})")
    a.set_ylabel(f"northing − {y0:.0f} m")
out = ROOT / "python" / "docs" / "walkthrough.png"
fig.savefig(out, dpi=66)
print("wrote", out.relative_to(ROOT))
