"""Quality triangle meshes of a study region."""

from __future__ import annotations

import os
from typing import Any, Dict, List, Optional, Sequence, Union

import numpy as np

from . import _terramesh as _core
from ._arrays import count, number, points as _points, vec
from ._terramesh import DEFAULTS, InputError

__all__ = ["Mesh", "mesh"]


class Mesh:
    """A triangle mesh: ``points`` (n x 3 float64; z is 0 until :meth:`with_heights`),
    ``triangles`` (m x 3 int64, counter-clockwise), per-triangle quality arrays
    (``min_angle``, ``max_angle`` in degrees, ``radius_ratio``, ``aspect_ratio``, ``area``),
    boundary and constraint edges, the UTM ``zone`` of a geographic region, and ``quality``
    (the summary after smoothing; ``quality_before`` before it).

    >>> m = mesh([[(0, 0), (10, 0), (10, 10), (0, 10)]], max_area=2.0)
    >>> m.points.shape[1], m.triangles.dtype.name
    (3, 'int64')
    >>> bool(abs(m.area.sum() - 100.0) < 1e-9)
    True
    """

    def __init__(self, d: Dict[str, Any], z: Optional[np.ndarray] = None):
        self._d = d
        xy = d["points"]
        self.points = np.empty((xy.shape[0], 3))
        self.points[:, :2] = xy
        self.points[:, 2] = 0.0 if z is None else z
        self.triangles: np.ndarray = d["triangles"]
        self.min_angle: np.ndarray = d["min_angle"]
        self.max_angle: np.ndarray = d["max_angle"]
        self.radius_ratio: np.ndarray = d["radius_ratio"]
        self.aspect_ratio: np.ndarray = d["aspect_ratio"]
        self.area: np.ndarray = d["area"]
        self.constraint_edges: np.ndarray = d["constraint_edges"]
        self.zone: Optional[str] = d["zone"]
        self.quality: Dict[str, Any] = d["quality_after"]
        self.quality_before: Dict[str, Any] = d["quality_before"]
        self.summary: str = d["summary"]

    def __repr__(self) -> str:
        return (
            f"Mesh({len(self.points)} vertices, {len(self.triangles)} triangles, "
            f"min angle {self.quality['min_angle']:.2f}°"
            + (f", zone {self.zone})" if self.zone else ")")
        )

    def with_heights(self, z) -> "Mesh":
        """A copy with vertex heights ``z`` (one per vertex), for example from :func:`krige`.

        >>> m = mesh([[(0, 0), (1, 0), (0, 1)]], min_angle=0)
        >>> m.with_heights([1.0, 2.0, 3.0]).points[:, 2].tolist()
        [1.0, 2.0, 3.0]
        """
        z = vec(z, "z")
        if len(z) != len(self.points):
            raise InputError(f"with_heights: {len(z)} heights for {len(self.points)} vertices")
        return Mesh(self._d, z)

    def to_meshio(self):
        """The mesh as a ``meshio.Mesh`` (triangle cells, cell data ``min_angle_deg``);
        needs meshio.

        >>> m = mesh([[(0, 0), (1, 0), (0, 1)]], min_angle=0)
        >>> m.to_meshio().cells_dict["triangle"].shape  # doctest: +SKIP
        (1, 3)
        """
        try:
            import meshio
        except ImportError:
            raise ImportError("Mesh.to_meshio needs meshio: pip install meshio") from None
        return meshio.Mesh(
            self.points, [("triangle", self.triangles)], cell_data={"min_angle_deg": [self.min_angle]}
        )

    def to_pyvista(self):
        """The mesh as a ``pyvista.PolyData`` with cell data ``min_angle_deg``; needs PyVista.

        >>> mesh([[(0, 0), (1, 0), (0, 1)]], min_angle=0).to_pyvista().n_cells  # doctest: +SKIP
        1
        """
        try:
            import pyvista
        except ImportError:
            raise ImportError("Mesh.to_pyvista needs PyVista: pip install pyvista") from None
        faces = np.hstack([np.full((len(self.triangles), 1), 3), self.triangles]).ravel()
        poly = pyvista.PolyData(self.points, faces)
        poly.cell_data["min_angle_deg"] = self.min_angle
        return poly


def _ring(r: Any, what: str) -> List[List[float]]:
    return _points(r, f"region: {what}")


def _geometry(geo: Any, where: str) -> Dict[str, Any]:
    if not isinstance(geo, dict):
        raise InputError(f"region: {where} is a {type(geo).__name__}, not a GeoJSON object")
    return geo


def _key(geo: Dict[str, Any], key: str, where: str) -> Any:
    if key not in geo:
        raise InputError(
            f"region: the {geo.get('type')} {where} has no {key!r} key (GeoJSON expected)"
        )
    return geo[key]


def _polygons(region: Any) -> List[List[List[List[float]]]]:
    """Rings of a region given as rings, a polygon list or a ``__geo_interface__``."""
    if region is None:
        raise InputError(
            "region: None given: give a list of rings (n x 2 arrays or lists of (x, y) "
            "pairs), a shapely-like geometry, a GeoJSON dict or the path of a region file"
        )
    geo = getattr(region, "__geo_interface__", None)
    if geo is None and isinstance(region, dict) and "type" in region:
        geo = region
    if geo is not None:
        geo = _geometry(geo, "geometry")
        t = geo.get("type")
        if t == "Feature":
            return _polygons(_geometry(_key(geo, "geometry", "object"), "a Feature's geometry"))
        if t == "FeatureCollection":
            return [
                p
                for f in _key(geo, "features", "object")
                for p in _polygons(_geometry(_key(_geometry(f, "a feature"), "geometry", "feature"), "a feature's geometry"))
            ]
        if t == "Polygon":
            return [[_ring(r, "a ring") for r in _key(geo, "coordinates", "geometry")]]
        if t == "MultiPolygon":
            return [[_ring(r, "a ring") for r in p] for p in _key(geo, "coordinates", "geometry")]
        raise InputError(f"region: a {t} geometry is not an area (give a Polygon or MultiPolygon)")
    if isinstance(region, (dict, bytes, int, float)) or not hasattr(region, "__iter__"):
        raise InputError(
            f"region: a {type(region).__name__} given: give a list of rings, a shapely-like "
            "geometry, a GeoJSON dict or the path of a region file"
        )
    rings = list(region)
    if not rings:
        raise InputError("region: no rings given")
    return [[_ring(r, f"ring {i}") for i, r in enumerate(rings)]]


def mesh(
    region: Union[Sequence, Any, str, os.PathLike],
    min_angle: float = DEFAULTS["min_angle"],
    max_area: Optional[float] = None,
    max_edge: Optional[float] = None,
    max_vertices: Optional[int] = None,
    smooth: int = DEFAULTS["smooth"],
    smoother: str = DEFAULTS["smoother"],
    points=None,
    crs: str = "projected",
    zone: Optional[str] = None,
    strips: Optional[int] = None,
) -> Mesh:
    """A constrained Delaunay quality mesh of ``region``, refined until every angle is at
    least ``min_angle`` degrees (at most 33; 0 turns it off) and every triangle within
    ``max_area`` / ``max_edge``, optionally smoothed (``smooth`` iterations of ``"smart"``,
    ``"laplacian"`` or ``"odt"``), with ``points`` (k x 2) inserted as vertices.

    ``region`` is a list of rings (each an n x 2 array or a list of (x, y) pairs; the first
    is the shell, the others holes), an object with ``__geo_interface__`` (shapely) or a
    GeoJSON dict, or the path of a GeoJSON, KML or WKT file. Coordinates are projected metres
    unless ``crs="geographic"`` (longitude, latitude), which projects to UTM (``zone`` or the
    zone of the region's centre; the mesh is in that zone's metres and ``Mesh.zone`` says
    which).

    >>> square = [(0, 0), (100, 0), (100, 100), (0, 100)]
    >>> hole = [(40, 40), (60, 40), (60, 60), (40, 60)]
    >>> m = mesh([square, hole], max_area=50.0)
    >>> bool(abs(m.area.sum() - 9600.0) < 1e-6), bool(m.min_angle.min() >= 30 - 1e-9)
    (True, True)
    """
    if crs not in ("projected", "geographic"):
        raise InputError(f"crs '{crs}': give 'projected' or 'geographic'")
    kw = dict(
        geographic=crs == "geographic",
        zone=zone,
        min_angle=number(min_angle, "min_angle"),
        max_area=number(max_area, "max_area", none=True),
        max_edge=number(max_edge, "max_edge", none=True),
        max_vertices=count(max_vertices, "max_vertices", none=True),
        smooth=count(smooth, "smooth"),
        smoother=smoother,
        points=None if points is None else _points(points, "points"),
        strips=count(strips, "strips", 1, none=True),
    )
    if isinstance(region, (str, os.PathLike)):
        d = _core.mesh(path=os.fspath(region), **kw)
    else:
        d = _core.mesh(polygons=_polygons(region), **kw)
    return Mesh(d)
