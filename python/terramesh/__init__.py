"""terramesh: terrain elevation samples to a triangulated discrete surface model (DSM).

The Python face of the terramesh library (Rust): WGS-84/UTM conversion (:mod:`terramesh.utm`),
variograms (:class:`Variogram`), kriging and IDW (:func:`krige`, :func:`idw`,
:func:`cross_validate`), quality meshes of a region (:func:`mesh`), elevation sampling
(:func:`sample`) and the whole pipeline of ``terramesh build`` (:func:`build`). numpy arrays
in and out; the work runs without the GIL and stops on Ctrl-C (``KeyboardInterrupt``).
:mod:`terramesh.pykrige` is a drop-in for PyKrige's 2D ``OrdinaryKriging`` and
``UniversalKriging``.

>>> import numpy as np, terramesh
>>> e, n, zone = terramesh.utm.forward(48.7224, 7.3368)
>>> zone
'32N'
>>> m = terramesh.mesh([[(0, 0), (100, 0), (100, 50), (0, 50)]], max_area=100.0)
>>> bool(m.min_angle.min() >= 30.0 - 1e-9)
True
"""

from ._terramesh import (
    ComputationError,
    Error,
    InputError,
    InternalError,
    OutputError,
    TooLargeError,
    __version__,
)
from . import utm
from .variogram import Variogram, Experimental
from .geostat import krige, idw, cross_validate, CrossValidation
from .meshing import Mesh, mesh
from .pipeline import BuildResult, Samples, build, sample

__all__ = [
    "Error",
    "InputError",
    "ComputationError",
    "OutputError",
    "InternalError",
    "TooLargeError",
    "utm",
    "Variogram",
    "Experimental",
    "krige",
    "idw",
    "cross_validate",
    "CrossValidation",
    "Mesh",
    "mesh",
    "Samples",
    "sample",
    "BuildResult",
    "build",
    "__version__",
]
