"""The vertical datum of a geological model's outputs (issue 13), read back by readers that
share no code with terramesh: meshio (VTU field data), pyproj (is `vertical_crs` a vertical
CRS) and GDAL through rasterio (the GeoTIFF GeoKeys). A check of tests/verify/check_model.py;
see docs/geology.md, "The vertical datum".
"""

import re

import numpy as np

from vcommon import meshio_read, require

# Names terramesh writes for the datums it knows, and their EPSG vertical CRS codes.
KNOWN_DATUMS = {"egm96": 5773, "egm2008": 3855, "navd88": 5703, "ngvd29": 5702, "nap": 5709,
                "dhhn92": 5783, "dhhn2016": 7837, "ign69": 5720, "odn": 5701}


def vertical_of(fd, what):
    """(datum name, EPSG code or None) from field data text, checked for consistency: a
    `vertical_crs` is an EPSG vertical CRS (pyproj says so), and a known name has its code."""
    require("vertical_datum" in fd, f"{what}: no vertical_datum in the field data {sorted(fd)}")
    name, vcrs = fd["vertical_datum"], fd.get("vertical_crs")
    code = None
    if vcrs is not None:
        m = re.fullmatch(r"EPSG:(\d+)", vcrs)
        require(m, f"{what}: vertical_crs {vcrs!r} is not EPSG:<code>")
        code = int(m.group(1))
        import pyproj
        require(pyproj.CRS.from_epsg(code).is_vertical, f"{what}: {vcrs} is not a vertical CRS (pyproj)")
    if name in KNOWN_DATUMS:
        require(code == KNOWN_DATUMS[name], f"{what}: {name} is EPSG:{KNOWN_DATUMS[name]}, vertical_crs says {vcrs}")
    elif name == "source":
        require(code is None, f"{what}: vertical datum not named (source) but vertical_crs {vcrs}")
    else:
        require(name == vcrs, f"{what}: vertical_datum {name!r} is neither a known name nor {vcrs}")
    return name, code


def geotiff_vertical(path):
    """(horizontal EPSG, vertical EPSG or None, vertical unit or None) of a GeoTIFF as GDAL
    (rasterio) reads its GeoKeys, compound CRSs reported (GTIFF_REPORT_COMPD_CS)."""
    import rasterio
    with rasterio.Env(GTIFF_REPORT_COMPD_CS=True):
        with rasterio.open(path) as src:
            wkt = src.crs.to_wkt() if src.crs else ""
    import pyproj
    c = pyproj.CRS.from_wkt(wkt)
    if c.is_compound:
        h, v = c.sub_crs_list
        unit = v.axis_info[0].unit_name if v.axis_info else None
        return h.to_epsg(), v.to_epsg(), unit
    return c.to_epsg(), None, None


def check_vertical_datum(model):
    """model.vtu names the vertical datum of its heights in field data; model.json, dsm.vtu
    (meshio) and the GeoTIFF grids (GDAL's VerticalCSType, in metres) say the same."""
    model.vtu()
    name, code = vertical_of(model.field_data, "model.vtu")
    j = model.root / "model.json"
    if j.is_file():
        import json
        doc = json.loads(j.read_text())
        require(doc.get("vertical_datum") == name, f"model.json: vertical_datum {doc.get('vertical_datum')!r}, "
                f"model.vtu says {name!r}")
        want = None if code is None else f"EPSG:{code}"
        require(doc.get("vertical_crs") == want, f"model.json: vertical_crs {doc.get('vertical_crs')!r}, "
                f"model.vtu says {want!r}")
    d = model.root / "dsm.vtu"
    if d.is_file():
        m = meshio_read(d)
        fd = {k: bytes(np.asarray(v, dtype=np.uint8)).decode() for k, v in m.field_data.items()}
        require(vertical_of(fd, "dsm.vtu") == (name, code), f"dsm.vtu: datum {fd.get('vertical_datum')!r}, "
                f"model.vtu's is {name!r}")
    tifs = sorted((model.root / "interfaces").glob("*.tif")) + sorted(model.root.glob("dsm.tif"))
    for t in tifs:
        h, v, unit = geotiff_vertical(t)
        require(v == code, f"{t.name}: GDAL reads vertical CRS {v}, model.vtu says {code}")
        if code is not None:
            require(unit in ("metre", "meter"), f"{t.name}: vertical unit {unit!r}, not metre")
        crs = model.vtu()[4]
        if crs.startswith("EPSG:"):
            require(h == int(crs[5:]), f"{t.name}: GDAL reads horizontal CRS {h}, model.vtu says {crs}")
