"""A drop-in for ``pykrige.ok``: ``from terramesh.pykrige.ok import OrdinaryKriging``.

>>> import numpy as np
>>> from terramesh.pykrige.ok import OrdinaryKriging
>>> x, y = np.array([0.3, 1.9, 1.1, 3.3, 4.7]), np.array([1.2, 0.6, 3.2, 4.4, 3.8])
>>> ok = OrdinaryKriging(x, y, [0.47, 0.56, 0.74, 1.47, 1.74], variogram_model="exponential",
...                      variogram_parameters=[1.0, 5.0, 0.0])
>>> z, ss = ok.execute("grid", np.arange(0.0, 5.5, 0.5), np.arange(0.0, 5.5, 0.5))
>>> z.shape, ok.engine
((11, 11), 'terramesh')
"""

from ._base import BACKENDS, KrigingBase

__all__ = ["OrdinaryKriging"]


class OrdinaryKriging(KrigingBase):
    """Ordinary kriging with PyKrige 1.7's constructor, attributes and methods (see
    :mod:`terramesh.pykrige._base` for what runs where)."""

    _method = "ok"
    _backends = BACKENDS

    def __init__(
        self,
        x,
        y,
        z,
        variogram_model="linear",
        variogram_parameters=None,
        variogram_function=None,
        nlags=6,
        weight=False,
        anisotropy_scaling=1.0,
        anisotropy_angle=0.0,
        verbose=False,
        enable_plotting=False,
        enable_statistics=False,
        coordinates_type="euclidean",
        exact_values=True,
        pseudo_inv=False,
        pseudo_inv_type="pinv",
    ):
        self._init_common(
            x, y, z, variogram_model, variogram_parameters, variogram_function, nlags, weight,
            anisotropy_scaling, anisotropy_angle, verbose, enable_plotting, enable_statistics,
            exact_values, pseudo_inv, pseudo_inv_type, coordinates_type,
        )

    def execute(
        self,
        style,
        xpoints,
        ypoints,
        mask=None,
        backend="vectorized",
        n_closest_points=None,
    ):
        """Kriged values and variances on a ``'grid'`` (``(ny, nx)`` arrays), at
        ``'points'`` or on a ``'masked'`` grid (masked arrays); ``n_closest_points`` krige
        with that many nearest data per target. Every backend runs the same code."""
        return self._execute(style, xpoints, ypoints, mask, backend, n_closest_points)
