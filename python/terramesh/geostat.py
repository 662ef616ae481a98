"""Kriging, inverse distance weighting and cross-validation of scattered data."""

from __future__ import annotations

import json
import os
from typing import Any, NamedTuple, Optional, Union

import numpy as np

from . import _terramesh as _core
from ._arrays import count, number, reshape, shaped, vec
from ._terramesh import DEFAULTS, InputError
from .variogram import Variogram

__all__ = ["krige", "idw", "cross_validate", "CrossValidation"]

VariogramLike = Union[Variogram, dict, str, os.PathLike, None]


def _variogram(v: VariogramLike, x, y, z) -> Variogram:
    if v is None:
        return Variogram.fit(x, y, z, model="auto")
    if isinstance(v, Variogram):
        return v
    if isinstance(v, dict):
        return Variogram.from_json(v if "model" in v else {"model": v})
    if isinstance(v, bytes):
        v = v.decode("utf-8", "replace")
    if isinstance(v, (str, os.PathLike)):
        return Variogram.from_json(v)
    raise InputError(
        f"variogram: expected a terramesh.Variogram, a dict, JSON text or a path, not {type(v).__name__}"
    )


def _neighbors(k: Optional[int]) -> Optional[int]:
    # A whole number here; its range (at least 1) is the library plan's to check.
    return None if k is None else count(k, "neighbors")


def _name(v, name: str) -> str:
    if not isinstance(v, str):
        raise InputError(f"{name}: give a name (a str), not a {type(v).__name__}")
    return v


def krige(
    x,
    y,
    z,
    xt,
    yt,
    method: str = "uk",
    drift: str = "linear",
    variogram: VariogramLike = None,
    neighbors: Optional[int] = None,
    return_variance: bool = True,
    mean: Optional[float] = None,
):
    """Kriging of data ``x, y, z`` at targets ``xt, yt``.

    ``method`` is ``"uk"`` (universal, with ``drift`` ``"linear"``, ``"quadratic"`` or
    ``"constant"``), ``"ok"`` (ordinary) or ``"sk"`` (simple, around ``mean``, default the
    data mean). ``variogram`` is a :class:`Variogram` (or its dict, JSON text or file);
    ``None`` fits one (``Variogram.fit(x, y, z, "auto")``). ``neighbors=None`` krige with
    all data (one factorisation), an integer with that many nearest data per target.
    Returns ``(estimate, variance)`` shaped like ``xt``, or only the estimate with
    ``return_variance=False``. Exact at data points (variance 0).

    >>> import numpy as np
    >>> x, y = np.meshgrid(np.arange(10.0), np.arange(10.0))
    >>> z = 2 * x + y
    >>> v = Variogram("exponential", 1.0, 5.0)
    >>> est, var = krige(x.ravel(), y.ravel(), z.ravel(), [4.5], [4.5], variogram=v)
    >>> round(float(est[0]), 9), bool(var[0] > 0)
    (13.5, True)
    """
    xs, ys, zs = vec(x, "x"), vec(y, "y"), vec(z, "z")
    xtv, shape = shaped(xt, "xt")
    ytv, _ = shaped(yt, "yt")
    v = _variogram(variogram, xs, ys, zs)
    est, var = _core.krige(
        xs, ys, zs, xtv, ytv, v._json, _name(method, "method"), _name(drift, "drift"),
        number(mean, "mean", none=True), _neighbors(neighbors), bool(return_variance),
    )
    if return_variance:
        return reshape(est, shape), reshape(var, shape)
    return reshape(est, shape)


def idw(
    x,
    y,
    z,
    xt,
    yt,
    power: float = DEFAULTS["idw_power"],
    neighbors: Optional[int] = None,
    radius: Optional[float] = None,
):
    """Inverse distance weighting ``Σ w z / Σ w`` with ``w = d^-power`` of all data, the
    ``neighbors`` nearest, or those within ``radius``; exact at data points.

    >>> idw([0.0, 2.0], [0.0, 0.0], [1.0, 3.0], [1.0], [0.0]).tolist()
    [2.0]
    """
    xtv, shape = shaped(xt, "xt")
    ytv, _ = shaped(yt, "yt")
    est = _core.idw(
        vec(x, "x"), vec(y, "y"), vec(z, "z"), xtv, ytv, number(power, "power"),
        _neighbors(neighbors), number(radius, "radius", none=True),
    )
    return reshape(est, shape)


class CrossValidation(NamedTuple):
    """The result of :func:`cross_validate`; errors are ``estimate - observed``."""

    estimate: np.ndarray
    """Each datum estimated without it (or its fold)."""
    variance: Optional[np.ndarray]
    """The kriging variance of each estimate (``None`` for IDW)."""
    n: int
    """Number of estimates."""
    rmse: float
    """Root mean square error."""
    mae: float
    """Mean absolute error."""
    mean_error: float
    """Mean error (bias)."""
    mean_standardized: Optional[float]
    """Mean of error / σ (kriging; ideally 0)."""
    var_standardized: Optional[float]
    """Variance of error / σ (kriging; ideally 1)."""


def cross_validate(
    x,
    y,
    z,
    method: str = "uk",
    variogram: VariogramLike = None,
    drift: str = "linear",
    neighbors: Optional[int] = None,
    folds: Optional[int] = None,
    power: float = DEFAULTS["idw_power"],
    radius: Optional[float] = None,
    mean: Optional[float] = None,
) -> CrossValidation:
    """Leave-one-out (``folds=None``) or k-fold cross-validation of kriging (``"uk"``,
    ``"ok"``, ``"sk"``, arguments as :func:`krige`) or of ``"idw"`` (``power``,
    ``neighbors``, ``radius`` as :func:`idw`). Leave-one-out of global kriging uses Dubrule's
    closed form.

    >>> import numpy as np
    >>> x, y = np.meshgrid(np.arange(8.0), np.arange(8.0))
    >>> cv = cross_validate(x.ravel(), y.ravel(), (x - y).ravel(), method="idw", neighbors=4)
    >>> cv.n, bool(cv.rmse > 0), cv.variance is None
    (64, True, True)
    """
    xs, ys, zs = vec(x, "x"), vec(y, "y"), vec(z, "z")
    vj = None
    if _name(method, "method").lower() != "idw":
        vj = _variogram(variogram, xs, ys, zs)._json
    d = _core.cross_validate(
        xs, ys, zs, method, vj, _name(drift, "drift"), number(mean, "mean", none=True),
        _neighbors(neighbors), count(folds, "folds", 2, none=True), number(power, "power"),
        number(radius, "radius", none=True),
    )
    return CrossValidation(**d)
