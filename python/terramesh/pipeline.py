"""The pipeline: elevation sampling (``terramesh sample``) and whole builds (``terramesh
build``)."""

from __future__ import annotations

import csv
import os
import tempfile
from pathlib import Path
from typing import Any, Dict, List, Mapping, NamedTuple, Optional, Union

import numpy as np

from . import _terramesh as _core
from ._arrays import count, number
from ._terramesh import DEFAULTS, InputError
from .variogram import Variogram

__all__ = ["sample", "Samples", "build", "BuildResult"]


class Samples(NamedTuple):
    """Sampled elevations, one entry per grid node (or point)."""

    lat: np.ndarray
    """WGS-84 latitude (NaN for projected output)."""
    lon: np.ndarray
    """WGS-84 longitude (NaN for projected output)."""
    x: np.ndarray
    """UTM easting (or the source's projected x)."""
    y: np.ndarray
    """UTM northing (or the source's projected y)."""
    z: np.ndarray
    """Elevation (NaN where the source has none and ``on_missing="nodata"``)."""
    zone: Optional[str]
    """The UTM zone of ``x, y`` for geographic output."""


def _region_args(region: Any, crs: str) -> Dict[str, Any]:
    """A region for the sampler: a corner list, a file, or rings/geometry (via WKT)."""
    geographic = crs == "geographic"
    if region is None:
        return dict(region=None, region_file=None, geographic=geographic)
    if isinstance(region, os.PathLike) or (
        isinstance(region, str) and ";" not in region and os.path.exists(region)
    ):
        return dict(region=None, region_file=os.fspath(region), geographic=geographic)
    if isinstance(region, str):
        return dict(region=region, region_file=None, geographic=geographic)
    from .meshing import _polygons

    polys = _polygons(region)

    def ring(r):
        pts = list(r) + ([r[0]] if r[0] != r[-1] else [])
        return "(" + ", ".join(f"{p[0]!r} {p[1]!r}" for p in pts) + ")"

    wkt = "MULTIPOLYGON(" + ", ".join("(" + ", ".join(ring(r) for r in p) + ")" for p in polys) + ")"
    fd, path = tempfile.mkstemp(suffix=".wkt", prefix="terramesh-region-")
    with os.fdopen(fd, "w") as f:
        f.write(wkt)
    return dict(region=None, region_file=path, geographic=geographic, _tmp=path)


def sample(
    source: Union[str, os.PathLike],
    region: Any = None,
    rows: Optional[int] = DEFAULTS["rows"],
    cols: Optional[int] = DEFAULTS["cols"],
    margin: Union[float, str] = DEFAULTS["margin"],
    spacing: Optional[float] = None,
    clip: bool = False,
    crs: str = "geographic",
    zone: Optional[str] = None,
    on_missing: str = "error",
    output: Union[str, os.PathLike, None] = None,
    progress: bool = False,
) -> Samples:
    """Elevations of ``source`` on a ``rows`` x ``cols`` grid (or one of ``spacing`` metres)
    over ``region`` enlarged by ``margin`` (a fraction such as 0.1, or ``"50m"``), as
    ``terramesh sample``: ``source`` is a DEM (SRTM ``.hgt``, GeoTIFF, ESRI ASCII, or a folder
    of tiles), a CSV or LAS/LAZ points file, a tile URL template or a web service name.
    ``region`` is a corner list ``"LAT LON; LAT LON; ..."`` (DMS allowed), a region file
    (GeoJSON, KML, WKT), rings or a ``__geo_interface__`` object (longitude, latitude
    unless ``crs="projected"``). ``clip`` keeps only the nodes inside the region;
    ``on_missing`` is ``"error"``, ``"skip"`` or ``"nodata"``. ``output`` also writes the
    table as ``samples.csv`` does.

    >>> import terramesh, pathlib
    >>> crop = pathlib.Path("examples/haut-barr/srtm-crop.asc")
    >>> s = terramesh.sample(crop, "48.7224 7.3368; 48.7224 7.3404; 48.726 7.3404; 48.726 7.3368",
    ...                      rows=10, cols=5)  # doctest: +SKIP
    >>> len(s.z), s.zone  # doctest: +SKIP
    (50, '32N')
    """
    args = _region_args(region, crs)
    tmp = args.pop("_tmp", None)
    try:
        d = _core.sample(
            os.fspath(source),
            zone=zone,
            rows=count(rows, "rows", 1, none=True),
            cols=count(cols, "cols", 1, none=True),
            spacing=number(spacing, "spacing", none=True),
            margin=str(margin),
            clip=bool(clip),
            on_missing=on_missing,
            output=None if output is None else os.fspath(output),
            progress=progress,
            **args,
        )
    finally:
        if tmp:
            os.unlink(tmp)
    return Samples(d["lat"], d["lon"], d["x"], d["y"], d["z"], d["zone"])


def _toml_value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        return repr(v)
    if isinstance(v, (str, os.PathLike)):
        s = os.fspath(v)
        return '"' + s.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n") + '"'
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    raise InputError(f"project: a value of type {type(v).__name__} cannot go into a project file")


def to_toml(project: Mapping[str, Any]) -> str:
    """The TOML text of a project dict (``{"region": {"corners": ...}, "mesh": {...}}``).

    >>> print(to_toml({"title": "x", "mesh": {"min_angle": 30, "smooth": True}}))
    title = "x"
    <BLANKLINE>
    [mesh]
    min_angle = 30
    smooth = true
    <BLANKLINE>
    """
    top = [f"{k} = {_toml_value(v)}" for k, v in project.items() if not isinstance(v, Mapping)]
    out = "\n".join(top) + ("\n" if top else "")
    for k, sec in project.items():
        if isinstance(sec, Mapping):
            out += f"\n[{k}]\n" + "".join(f"{kk} = {_toml_value(vv)}\n" for kk, vv in sec.items())
    return out


def _csv_rows(path: Path) -> List[Dict[str, Any]]:
    if not path.is_file():
        return []
    with open(path, newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))

    def num(v: str):
        try:
            return float(v)
        except ValueError:
            return v

    return [{k: num(v) for k, v in r.items()} for r in rows]


class BuildResult:
    """What :func:`build` made: ``out_dir``, ``files`` (every file written, as paths),
    ``vertices`` and ``triangles`` of the DSM, ``timings`` (seconds per stage), and the
    statistics of the report read from the build folder: :attr:`variogram`,
    :attr:`cross_validation` (rows of ``cross-validation.csv``), :attr:`mesh_quality`
    (rows of ``mesh-quality.csv``)."""

    def __init__(self, out_dir: Path, d: Dict[str, Any]):
        self.out_dir = Path(out_dir)
        self.files: List[Path] = [Path(f) for f in d["files"]]
        self.vertices: int = d["vertices"]
        self.triangles: int = d["triangles"]
        self.timings: Dict[str, float] = dict(d["timings"])
        vj = self.out_dir / "variogram.json"
        self.variogram: Optional[Variogram] = Variogram.from_json(vj) if vj.is_file() else None
        self.cross_validation = _csv_rows(self.out_dir / "cross-validation.csv")
        self.mesh_quality = _csv_rows(self.out_dir / "mesh-quality.csv")

    def __repr__(self) -> str:
        return (
            f"BuildResult({str(self.out_dir)!r}, {self.vertices} vertices, "
            f"{self.triangles} triangles, {len(self.files)} files)"
        )

    def path(self, name: str) -> Path:
        """The path of output ``name`` (``"dsm.vtu"``) in the build folder.

        >>> BuildResult("out", {"files": [], "vertices": 0, "triangles": 0, "timings": []}).path("dsm.vtu").as_posix()
        'out/dsm.vtu'
        """
        return self.out_dir / name

    def vertices_table(self) -> Dict[str, np.ndarray]:
        """``dsm-vertices.csv`` as columns of float64 arrays.

        >>> r = terramesh.build("examples/haut-barr/terramesh.toml", "out")  # doctest: +SKIP
        >>> sorted(r.vertices_table())[:3]  # doctest: +SKIP
        ['elevation_idw', 'elevation_uk', 'kriging_std']
        """
        with open(self.out_dir / "dsm-vertices.csv", newline="", encoding="utf-8") as f:
            r = csv.reader(f)
            head = next(r)
            data = np.array([[float(v) if v else np.nan for v in row] for row in r])
        return {h: data[:, i] for i, h in enumerate(head)}

    def to_meshio(self):
        """``dsm.vtu`` read by meshio (needs meshio).

        >>> r.to_meshio().point_data["elevation_uk"].shape  # doctest: +SKIP
        (2869,)
        """
        try:
            import meshio
        except ImportError:
            raise ImportError("BuildResult.to_meshio needs meshio: pip install meshio") from None
        return meshio.read(self.out_dir / "dsm.vtu")

    def to_pyvista(self):
        """``dsm.vtu`` read by PyVista (needs PyVista).

        >>> r.to_pyvista().n_points  # doctest: +SKIP
        2869
        """
        try:
            import pyvista
        except ImportError:
            raise ImportError("BuildResult.to_pyvista needs PyVista: pip install pyvista") from None
        return pyvista.read(self.out_dir / "dsm.vtu")


def build(
    project: Union[str, os.PathLike, Mapping[str, Any]],
    out_dir: Union[str, os.PathLike],
    set: Optional[Mapping[str, Any]] = None,  # noqa: A002 - the contract's name (--set)
    progress: bool = True,
    base: Union[str, os.PathLike, None] = None,
) -> BuildResult:
    """Runs ``terramesh build``: the project (a ``terramesh.toml`` path, or a dict of its
    sections whose relative paths are relative to ``base``, default the current folder) into
    ``out_dir``, with ``set`` overriding keys (``{"mesh.min_angle": 32}``, like ``--set``).
    ``progress`` prints each stage to standard error. The build folder is replaced as a
    whole at the end, so an error or Ctrl-C (``KeyboardInterrupt``) leaves it as it was.

    >>> r = build("examples/haut-barr/terramesh.toml", "out")  # doctest: +SKIP
    >>> r.vertices, r.path("report.html").is_file()  # doctest: +SKIP
    (2869, True)
    """
    sets = [f"{k}={_toml_value(v) if not isinstance(v, str) else v}" for k, v in (set or {}).items()]
    out = os.fspath(out_dir)
    if isinstance(project, Mapping):
        d = _core.build(
            out, text=to_toml(project), base=os.fspath(base or os.getcwd()), sets=sets,
            progress=progress,
        )
    else:
        d = _core.build(out, path=os.fspath(project), sets=sets, progress=progress)
    return BuildResult(Path(out), d)
