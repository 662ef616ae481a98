"""COLLADA checks of the output verifier: dsm.dae (pycollada, the COLLADA 1.4.1 schema) and
dsm-model.kml (the KML 2.2 schema), and the model's positions taken back to lat/lon/altitude
with PROJ, independently of terramesh's conversions (see docs/verification.md)."""

import xml.etree.ElementTree as ET

import numpy as np

from vcommon import (DAE_ALT, DAE_DEG, F32_EPS, CheckFailed, canonical_triangles, close, kml_schema_dir,
                     planar_areas, require, xmllint_schema)

NS = {"c": "http://www.collada.org/2005/11/COLLADASchema", "k": "http://www.opengis.net/kml/2.2"}
# A COLLADA point (x, y, z) with this up axis in east, north, up.
UP_AXIS_TO_ENU = {"Z_UP": lambda p: p, "Y_UP": lambda p: np.column_stack([p[:, 0], -p[:, 2], p[:, 1]])}


def check_dae_schema(out):
    """dsm.dae: COLLADA 1.4.1 and valid against its schema (pycollada's copy, lxml)."""
    from collada.schema import ColladaValidator
    from lxml import etree
    try:
        doc = etree.parse(str(out.path("dsm.dae")))
    except etree.XMLSyntaxError as e:
        raise CheckFailed(f"dsm.dae: not well-formed XML: {e}")
    version = doc.getroot().get("version")
    require(version == "1.4.1", f"dsm.dae: COLLADA version {version!r}, Google Earth reads 1.4.1")
    schema = ColladaValidator().COLLADA_SCHEMA_1_4_1_INSTANCE
    if not schema.validate(doc):
        errs = [f"line {e.line}: {e.message}" for e in list(schema.error_log)[:3]]
        raise CheckFailed(f"dsm.dae: invalid against the COLLADA 1.4.1 schema: {' | '.join(errs)}")


def model_location(out):
    """dsm-model.kml: the <Model>'s altitude mode, link and location (lon, lat, alt)."""
    root = ET.parse(out.path("dsm-model.kml")).getroot()
    models = root.findall(".//k:Model", NS)
    require(len(models) == 1, f"dsm-model.kml: {len(models)} <Model> elements, expected 1")
    m = models[0]
    mode = (m.findtext("k:altitudeMode", "", NS) or "").strip()
    require(mode == "absolute", f"dsm-model.kml: <Model> altitudeMode {mode!r}, expected 'absolute'")
    href = (m.findtext("k:Link/k:href", "", NS) or "").strip()
    require(href == "dsm.dae", f"dsm-model.kml: <Link><href> {href!r}, expected 'dsm.dae'")
    loc = []
    for tag in ["longitude", "latitude", "altitude"]:
        text = m.findtext(f"k:Location/k:{tag}", None, NS)
        require(text is not None, f"dsm-model.kml: <Location> lacks <{tag}>")
        try:
            loc.append(float(text))
        except ValueError:
            raise CheckFailed(f"dsm-model.kml: <Location><{tag}> {text!r} is not a number")
    for tag, neutral in [("Orientation/k:heading", 0), ("Orientation/k:tilt", 0), ("Orientation/k:roll", 0),
                         ("Scale/k:x", 1), ("Scale/k:y", 1), ("Scale/k:z", 1)]:
        text = m.findtext(f"k:{tag}", None, NS)
        require(text is None or float(text) == neutral,
                f"dsm-model.kml: <{tag.replace('/k:', '><')}> {text}, the model must not be turned or scaled")
    return loc


def check_model_kml(out):
    """dsm-model.kml valid against the KML 2.2 schema (xmllint); absolute <Model> linking dsm.dae."""
    xmllint_schema(out, "dsm-model.kml", kml_schema_dir() / "ogckml22.xsd")
    model_location(out)


def dae_double_positions(name, root, source_id, count):
    """The float_array of <source id=source_id> parsed as float64, shape (count, 3)."""
    src = root.find(f".//c:source[@id='{source_id}']", NS)
    require(src is not None, f"{name}: no <source id='{source_id}'>")
    fa = src.find("c:float_array", NS)
    require(fa is not None, f"{name}: <source id='{source_id}'> has no float_array")
    vals = np.array((fa.text or "").split(), dtype=np.float64)
    require(fa.get("count") == str(len(vals)), f"{name}: float_array count {fa.get('count')} holds {len(vals)}")
    require(len(vals) == 3 * count, f"{name}: {len(vals)} position values for {count} vertices")
    require(np.all(np.isfinite(vals)), f"{name}: non-finite positions")
    return vals.reshape(-1, 3)


def check_dae(out):
    """dsm.dae (pycollada): one triangle mesh with the CSV's vertex and triangle counts and dsm.vtu's
    triangles, counter-clockwise from above; its positions (doubles, east-north-up metres around
    dsm-model.kml's <Location>) go back through PROJ's topocentric and cart inverses to the
    lat/lon/altitude of the CSV vertices (PROJ's UTM inverse)."""
    import collada
    from pyproj import Transformer
    name = "dsm.dae"
    _, ref_pts, ref_tris = out.ref()
    try:
        doc = collada.Collada(str(out.path(name)))
    except collada.DaeError as e:
        raise CheckFailed(f"{name}: pycollada cannot read it: {type(e).__name__}: {e}")
    up = doc.assetInfo.upaxis
    require(up in UP_AXIS_TO_ENU, f"{name}: up_axis {up!r}, expected Z_UP or Y_UP")
    unit = float(doc.assetInfo.unitmeter or 1.0)
    require(unit == 1.0, f"{name}: unit {unit} m, expected metres (1.0)")
    bound = list(doc.scene.objects("geometry")) if doc.scene is not None else []
    require(len(bound) == 1, f"{name}: the scene instantiates {len(bound)} geometries, expected 1")
    require(np.array_equal(bound[0].matrix, np.identity(4)), f"{name}: node transform {bound[0].matrix.tolist()} "
            "is not the identity")
    prims = list(bound[0].original.primitives)
    require(len(prims) == 1, f"{name}: {len(prims)} primitives, expected one triangle set")
    p = prims[0]
    if isinstance(p, collada.polylist.Polylist):
        p = p.triangleset()
    require(isinstance(p, collada.triangleset.TriangleSet), f"{name}: primitive {type(p).__name__}, expected triangles")
    require(len(p.vertex) == len(ref_pts), f"{name}: {len(p.vertex)} vertices, dsm-vertices.csv has {len(ref_pts)}")
    tris = np.asarray(p.vertex_index)
    require(len(tris) == len(ref_tris), f"{name}: {len(tris)} triangles, dsm.vtu has {len(ref_tris)}")
    require(np.array_equal(canonical_triangles(tris), canonical_triangles(ref_tris)),
            f"{name}: triangles differ from dsm.vtu's")
    # pycollada keeps float32; the file's doubles come from the XML, checked against pycollada's.
    # pycollada lists the <vertices> POSITION input as the VERTEX source.
    require(len(p.sources.get("VERTEX", [])) == 1, f"{name}: {len(p.sources.get('VERTEX', []))} position inputs")
    pos_id = p.sources["VERTEX"][0][2].lstrip("#")
    raw = dae_double_positions(name, doc.xmlnode.getroot(), pos_id, len(ref_pts))
    require(np.all(np.abs(p.vertex - raw) <= F32_EPS * np.maximum(np.abs(raw), 1e-30)),
            f"{name}: pycollada's positions differ from the float_array beyond float32 rounding")
    enu = UP_AXIS_TO_ENU[up](raw)
    area = planar_areas(enu, tris)
    require(np.all(area > 0), f"{name}: {int(np.sum(area <= 0))} triangles not counter-clockwise seen from above, "
            f"e.g. #{int(np.argmin(area))}")
    if p.normal is not None:
        n = np.asarray(p.normal, dtype=float)
        close(np.linalg.norm(n, axis=1), np.ones(len(n)), 1e-6, f"{name}: normal lengths")
        up_n = UP_AXIS_TO_ENU[up](n)[:, 2]
        require(np.all(up_n > 0), f"{name}: normal #{int(np.argmin(up_n))} points down ({up_n.min()!r})")
    lon0, lat0, h0 = model_location(out)
    back = Transformer.from_pipeline(
        "+proj=pipeline "
        f"+step +inv +proj=topocentric +ellps=WGS84 +lon_0={lon0!r} +lat_0={lat0!r} +h_0={h0!r} "
        "+step +inv +proj=cart +ellps=WGS84 +step +proj=unitconvert +xy_in=rad +xy_out=deg")
    lon, lat, alt = back.transform(enu[:, 0], enu[:, 1], enu[:, 2])
    epsg = out.epsg()
    require(epsg is not None, f"{name}: no EPSG in dsm.tif to take the vertices to lat/lon")
    want_lon, want_lat = Transformer.from_crs(epsg, 4326, always_xy=True).transform(ref_pts[:, 0], ref_pts[:, 1])
    close(np.column_stack([lon, lat]), np.column_stack([want_lon, want_lat]), 0.0,
          f"{name} + dsm-model.kml: lon/lat vs PROJ's UTM inverse of the CSV", atol=DAE_DEG)
    close(alt, ref_pts[:, 2], 0.0, f"{name} + dsm-model.kml: altitude vs elevation_uk", atol=DAE_ALT)


CHECKS = [
    ("dae schema (COLLADA 1.4.1)", check_dae_schema),
    ("dae geometry (pycollada, PROJ)", check_dae),
    ("dae model kml schema (xmllint)", check_model_kml),
]
