"""PyKrige's variogram model functions, ``f(params, dist)``, with PyKrige's parameters.

Written from PyKrige 1.7's documentation (not its code): ``linear [slope, nugget]``, ``power
[scale, exponent, nugget]``, and ``[psill, range, nugget]`` for the others, where a
Gaussian's ``range`` is PyKrige's (``4/7`` of it is the length scale) and the exponential's
and hole-effect's is three length scales. Every function gives the nugget at distance 0;
the kriging systems put γ = 0 on their diagonals.

>>> import numpy as np
>>> float(exponential_variogram_model([2.0, 30.0, 0.5], np.array([30.0]))[0].round(6))
2.400426
"""

import numpy as np


def linear_variogram_model(m, d):
    """``slope * d + nugget``."""
    return float(m[0]) * d + float(m[1])


def power_variogram_model(m, d):
    """``scale * d**exponent + nugget``."""
    return float(m[0]) * d ** float(m[1]) + float(m[2])


def gaussian_variogram_model(m, d):
    """``psill * (1 - exp(-d² / (4 range / 7)²)) + nugget``."""
    psill, range_, nugget = float(m[0]), float(m[1]), float(m[2])
    return psill * (1.0 - np.exp(-(d**2.0) / (range_ * 4.0 / 7.0) ** 2.0)) + nugget


def exponential_variogram_model(m, d):
    """``psill * (1 - exp(-d / (range / 3))) + nugget``."""
    psill, range_, nugget = float(m[0]), float(m[1]), float(m[2])
    return psill * (1.0 - np.exp(-d / (range_ / 3.0))) + nugget


def spherical_variogram_model(m, d):
    """``psill * (1.5 d/range - 0.5 (d/range)³) + nugget`` below the range, the sill beyond."""
    psill, range_, nugget = float(m[0]), float(m[1]), float(m[2])
    d = np.asarray(d, dtype=float)
    r = np.minimum(d / range_, 1.0)
    return psill * (1.5 * r - 0.5 * r**3) + nugget


def hole_effect_variogram_model(m, d):
    """``psill * (1 - (1 - d/(range/3)) exp(-d/(range/3))) + nugget``."""
    psill, range_, nugget = float(m[0]), float(m[1]), float(m[2])
    u = d / (range_ / 3.0)
    return psill * (1.0 - (1.0 - u) * np.exp(-u)) + nugget


MODELS = {
    "linear": linear_variogram_model,
    "power": power_variogram_model,
    "gaussian": gaussian_variogram_model,
    "spherical": spherical_variogram_model,
    "exponential": exponential_variogram_model,
    "hole-effect": hole_effect_variogram_model,
}
