"""Model set-up shared by the drop-in classes: parameters, anisotropy, distances, the
PyKrige-compatible experimental variogram and its least-squares fit, and the translation of a
PyKrige model into a terramesh :class:`~terramesh.Variogram`."""

from __future__ import annotations

import numpy as np

from .variogram_models import MODELS

EPS = 1e-10
"""Distances at or below this are a datum's own location (as PyKrige)."""


def parameter_list(model, params):
    """PyKrige's ``variogram_parameters`` (list or dict) as the list the model functions take:
    ``[slope, nugget]``, ``[scale, exponent, nugget]`` or ``[psill, range, nugget]`` (a list
    for these gives the *full* sill first)."""
    if params is None:
        return None
    if isinstance(params, dict):
        if model == "custom":
            raise TypeError("variogram_parameters for a custom model must be a list")
        if model == "linear":
            keys = ("slope", "nugget")
        elif model == "power":
            keys = ("scale", "exponent", "nugget")
        elif model in MODELS:
            keys = ("psill" if "psill" in params else "sill", "range", "nugget")
        else:
            raise ValueError(f"variogram model '{model}' not supported")
        missing = [k for k in keys if k not in params]
        if missing:
            # A KeyError, as PyKrige raises, that says what the dict needs.
            need = " and ".join(repr(k) for k in keys)
            if keys[0] in ("psill", "sill"):
                need = "'sill' (or 'psill'), 'range' and 'nugget'"
            raise KeyError(
                f"variogram_parameters for the {model} model: no "
                f"{', '.join(repr(k) for k in missing)} key; give {need}"
            )
        if keys[0] == "sill":
            return [params["sill"] - params["nugget"], params["range"], params["nugget"]]
        return [params[k] for k in keys]
    if isinstance(params, (list, tuple, np.ndarray)):
        params = list(params)
        if model == "custom":
            return params
        need = {"linear": 2, "power": 3}.get(model, 3)
        if model not in MODELS:
            raise ValueError(f"variogram model '{model}' not supported")
        if len(params) != need:
            raise ValueError(
                f"variogram_parameters for the {model} model need {need} values, "
                f"{len(params)} given"
            )
        if model in ("linear", "power"):
            return params
        return [params[0] - params[2], params[1], params[2]]
    raise TypeError("variogram_parameters must be a list or a dict")


def adjust(x, y, center, scaling, angle):
    """PyKrige's anisotropy frame: rotated by -angle (degrees, counter-clockwise) about
    ``center``, the second axis stretched by ``scaling`` (and the centre added back)."""
    a = np.deg2rad(angle)
    xc, yc = x - center[0], y - center[1]
    xr = np.cos(-a) * xc - np.sin(-a) * yc
    yr = np.sin(-a) * xc + np.cos(-a) * yc
    return xr + center[0], scaling * yr + center[1]


def great_circle(lon1, lat1, lon2, lat2):
    """Great-circle distance in degrees (Vincenty's formula on the sphere)."""
    lon1, lat1, lon2, lat2 = map(np.deg2rad, (lon1, lat1, lon2, lat2))
    dlon = lon2 - lon1
    c1, s1, c2, s2 = np.cos(lat1), np.sin(lat1), np.cos(lat2), np.sin(lat2)
    num = np.hypot(c2 * np.sin(dlon), c1 * s2 - s1 * c2 * np.cos(dlon))
    den = s1 * s2 + c1 * c2 * np.cos(dlon)
    return np.rad2deg(np.arctan2(num, den))


def distances(xa, ya, xb, yb, geographic):
    """The len(a) x len(b) distance matrix."""
    if geographic:
        return great_circle(xa[:, None], ya[:, None], xb[None, :], yb[None, :])
    return np.hypot(xa[:, None] - xb[None, :], ya[:, None] - yb[None, :])


def experimental(x, y, z, nlags, geographic):
    """Lags and semivariances of ``nlags`` equal classes between the least and the largest
    pair distance (classes without pairs left out), Matheron's estimator."""
    i, j = np.triu_indices(len(x), k=1)
    if geographic:
        d = great_circle(x[i], y[i], x[j], y[j])
    else:
        d = np.hypot(x[i] - x[j], y[i] - y[j])
    g = 0.5 * (z[i] - z[j]) ** 2
    dmax, dmin = np.amax(d), np.amin(d)
    dd = (dmax - dmin) / nlags
    bins = [dmin + n * dd for n in range(nlags)] + [dmax + 0.001]
    lags, sv = [], []
    for n in range(nlags):
        m = (d >= bins[n]) & (d < bins[n + 1])
        if np.any(m):
            lags.append(np.mean(d[m]))
            sv.append(np.mean(g[m]))
    return np.array(lags), np.array(sv)


def fit(lags, sv, model, function, weight):
    """Least squares (soft L1 loss) of ``function`` to the experimental variogram, from
    PyKrige's documented starting point and bounds; ``weight`` favours the short lags with a
    logistic weight falling from 90 % to 10 % across the lags 60 % to 80 % of the way along."""
    try:
        from scipy.optimize import least_squares
    except ImportError:  # pragma: no cover - scipy is a test dependency
        raise ImportError(
            "fitting a PyKrige variogram needs scipy (pip install scipy), or give "
            "variogram_parameters"
        ) from None
    if model == "linear":
        x0 = [(np.amax(sv) - np.amin(sv)) / (np.amax(lags) - np.amin(lags)), np.amin(sv)]
        bounds = ([0.0, 0.0], [np.inf, np.amax(sv)])
    elif model == "power":
        x0 = [(np.amax(sv) - np.amin(sv)) / (np.amax(lags) - np.amin(lags)), 1.1, np.amin(sv)]
        bounds = ([0.0, 0.001, 0.0], [np.inf, 1.999, np.amax(sv)])
    else:
        x0 = [np.amax(sv) - np.amin(sv), 0.25 * np.amax(lags), np.amin(sv)]
        bounds = ([0.0, 0.0, 0.0], [10.0 * np.amax(sv), np.amax(lags), np.amax(sv)])

    def residuals(p):
        r = function(p, lags) - sv
        if weight:
            span = np.amax(lags) - np.amin(lags)
            k = 2.1972 / (0.1 * span)
            mid = 0.7 * span + np.amin(lags)
            w = 1.0 / (1.0 + np.exp(-k * (mid - lags)))
            r = r * (w / np.sum(w))
        return r

    return list(least_squares(residuals, x0, bounds=bounds, loss="soft_l1").x)


def terramesh_variogram(model, p):
    """The terramesh :class:`~terramesh.Variogram` equal to PyKrige's ``model`` with the
    parameter list ``p``, or ``None`` where terramesh has no such model (hole-effect,
    custom, an exponent outside (0, 2), a zero sill)."""
    from .. import Variogram, InputError

    try:
        if model == "linear":
            if p[0] <= 0:
                return None
            return Variogram("linear", psill=p[0], range=1.0, nugget=p[1])
        if model == "power":
            if not (0 < p[1] < 2) or p[0] <= 0:
                return None
            return Variogram("power", psill=p[0], range=1.0, nugget=p[2], shape=p[1])
        if model in ("spherical", "exponential"):
            return Variogram(model, psill=p[0], range=p[1], nugget=p[2])
        if model == "gaussian":
            return Variogram("gaussian", psill=p[0], range=p[1] * 4.0 * np.sqrt(3.0) / 7.0, nugget=p[2])
    except InputError:
        return None
    return None
