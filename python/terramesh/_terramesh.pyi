"""Type stubs of the compiled core ``terramesh._terramesh`` (the public API wraps these in
:mod:`terramesh`; call those). Arrays are 1-D contiguous float64 unless said otherwise."""

from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np
import numpy.typing as npt

F64 = npt.NDArray[np.float64]

__version__: str

DEFAULTS: Dict[str, Any]
"""The library's defaults the Python signatures show (``min_angle``, ``max_min_angle``,
``smooth``, ``smoother``, ``lags``, ``max_points``, ``tolerance``, ``estimator``,
``weighting``, ``reml_block``, ``idw_power``, ``rows``, ``cols``, ``margin``), each from the
facade's constant."""

class Error(Exception):
    """Every error terramesh raises (its message is the library's)."""

class InputError(Error):
    """Bad input: a value, a setting, a project key, a file's contents, coordinates."""

class ComputationError(Error):
    """The numerics could not finish (a singular kriging system, a mesh that cannot be refined)."""

class OutputError(Error):
    """Reading or writing a file failed."""

class InternalError(Error):
    """A bug in terramesh (a caught panic)."""

class TooLargeError(InputError, MemoryError):
    """A size that follows from the input would not fit in memory: refused before allocating."""

def cli(argv: Sequence[str], program: Optional[str] = None) -> int:
    """Runs the ``terramesh`` command with ``argv`` (program name first) and returns its exit
    code; a process's main only (see :mod:`terramesh._cli`)."""

def utm_forward(
    lat: F64, lon: F64, zone: Optional[str] = None
) -> Tuple[F64, F64, npt.NDArray[np.uint8], npt.NDArray[np.bool_]]:
    """``(easting, northing, zone number, north)`` of each point (see :func:`terramesh.utm.forward`)."""

def utm_inverse(easting: F64, northing: F64, zone: str) -> Tuple[F64, F64]:
    """``(lat, lon)`` degrees of UTM points in ``zone`` (see :func:`terramesh.utm.inverse`)."""

def parse_dms(text: str, axis: Optional[str] = None) -> float:
    """Decimal degrees of a decimal or DMS angle (see :func:`terramesh.utm.parse_dms`)."""

def zone_for(lat: float, lon: float) -> str:
    """The standard UTM zone of a point, e.g. ``"32N"``."""

def variogram_check(json: str) -> str:
    """The ``model`` JSON of a variogram, validated, in canonical form."""

def variogram_gamma(json: str, h: F64) -> F64:
    """γ of the model at lags ``h``."""

def variogram_file_model(text: str) -> str:
    """The ``model`` object of a ``variogram.json`` text, as JSON."""

def variogram_file_json(json: str) -> str:
    """A ``variogram.json`` text with only this model."""

def experimental(
    x: F64, y: F64, z: F64, lags: int, max_dist: Optional[float] = None,
    estimator: str = "matheron", azimuth: Optional[float] = None,
    tolerance: Optional[float] = None, max_points: Optional[int] = None,
) -> Dict[str, Any]:
    """The lag classes: ``lo``, ``hi``, ``distance``, ``gamma``, ``pairs`` arrays."""

def variogram_fit(
    x: F64, y: F64, z: F64, model: str = "auto", weighting: str = "cressie", lags: int = ...,
    max_dist: Optional[float] = None, estimator: str = "matheron",
    azimuth: Optional[float] = None, tolerance: Optional[float] = None,
    max_points: Optional[int] = ..., fit: Optional[str] = None, drift: str = "linear",
    reml_block: int = ...,
) -> str:
    """The ``variogram.json`` text of the fitted model (see :meth:`terramesh.Variogram.fit`)."""

def krige(
    x: F64, y: F64, z: F64, xt: F64, yt: F64, variogram: str, method: str = "uk",
    drift: str = "linear", mean: Optional[float] = None, neighbors: Optional[int] = None,
    return_variance: bool = True,
) -> Tuple[F64, Optional[F64]]:
    """Kriging estimates and variances (see :func:`terramesh.krige`)."""

def idw(
    x: F64, y: F64, z: F64, xt: F64, yt: F64, power: float = ...,
    neighbors: Optional[int] = None, radius: Optional[float] = None,
) -> F64:
    """IDW estimates (see :func:`terramesh.idw`)."""

def cross_validate(
    x: F64, y: F64, z: F64, method: str = "uk", variogram: Optional[str] = None,
    drift: str = "linear", mean: Optional[float] = None, neighbors: Optional[int] = None,
    folds: Optional[int] = None, power: float = ..., radius: Optional[float] = None,
) -> Dict[str, Any]:
    """Cross-validation estimates, variances and statistics (see :func:`terramesh.cross_validate`)."""

def mesh(
    polygons: Optional[List[List[List[Sequence[float]]]]] = None, path: Optional[str] = None,
    corners: Optional[str] = None, geographic: bool = False, zone: Optional[str] = None,
    min_angle: float = ..., max_area: Optional[float] = None, max_edge: Optional[float] = None,
    max_vertices: Optional[int] = None, smooth: int = 0, smoother: Optional[str] = None,
    points: Optional[List[Sequence[float]]] = None, strips: Optional[int] = None,
) -> Dict[str, Any]:
    """Points, triangles and quality of a mesh (see :func:`terramesh.mesh`)."""

def sample(
    source: str, region: Optional[str] = None, region_file: Optional[str] = None,
    geographic: bool = True, zone: Optional[str] = None, rows: Optional[int] = ...,
    cols: Optional[int] = ..., spacing: Optional[float] = None, margin: Optional[str] = None,
    clip: bool = False, on_missing: str = "error", output: Optional[str] = None,
    progress: bool = False,
) -> Dict[str, Any]:
    """Sampled ``lat``, ``lon``, ``x``, ``y``, ``z`` and ``zone`` (see :func:`terramesh.sample`)."""

def build(
    out_dir: str, path: Optional[str] = None, text: Optional[str] = None,
    base: Optional[str] = None, sets: List[str] = ..., progress: bool = True,
) -> Dict[str, Any]:
    """``files``, ``vertices``, ``triangles``, ``timings`` of a build (see :func:`terramesh.build`)."""
