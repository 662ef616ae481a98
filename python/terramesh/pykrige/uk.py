"""A drop-in for ``pykrige.uk``: ``from terramesh.pykrige.uk import UniversalKriging``.

>>> import numpy as np
>>> from terramesh.pykrige.uk import UniversalKriging
>>> x, y = np.array([0.3, 1.9, 1.1, 3.3, 4.7]), np.array([1.2, 0.6, 3.2, 4.4, 3.8])
>>> uk = UniversalKriging(x, y, [0.47, 0.56, 0.74, 1.47, 1.74], variogram_model="spherical",
...                       variogram_parameters=[1.0, 5.0, 0.0], drift_terms=["regional_linear"])
>>> z, ss = uk.execute("points", [2.0, 4.7], [2.0, 3.8])
>>> round(float(z[1]), 12), round(float(ss[1]), 12), uk.engine
(1.74, 0.0, 'terramesh')
"""

import numpy as np

from ._base import KrigingBase

__all__ = ["UniversalKriging"]

DRIFTS = ("regional_linear", "point_log", "external_Z", "specified", "functional")


class UniversalKriging(KrigingBase):
    """Universal kriging with PyKrige 1.7's constructor, drifts, attributes and methods (see
    :mod:`terramesh.pykrige._base` for what runs where)."""

    _method = "uk"
    _uk = True
    _backends = ("vectorized", "loop")

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
        drift_terms=None,
        point_drift=None,
        external_drift=None,
        external_drift_x=None,
        external_drift_y=None,
        specified_drift=None,
        functional_drift=None,
        verbose=False,
        enable_plotting=False,
        exact_values=True,
        pseudo_inv=False,
        pseudo_inv_type="pinv",
    ):
        drift_terms = [] if drift_terms is None else list(drift_terms)
        for d in drift_terms:
            if d not in DRIFTS:
                raise ValueError(f"drift term '{d}' not known: give {', '.join(DRIFTS)}")
        self.drift_terms = drift_terms
        self.UNBIAS = True
        self._init_common(
            x, y, z, variogram_model, variogram_parameters, variogram_function, nlags, weight,
            anisotropy_scaling, anisotropy_angle, verbose, enable_plotting, False,
            exact_values, pseudo_inv, pseudo_inv_type, "euclidean",
        )
        self.regional_linear_drift = "regional_linear" in drift_terms
        self.external_Z_drift = "external_Z" in drift_terms
        if self.external_Z_drift:
            if external_drift is None:
                raise ValueError("Must specify external Z drift terms.")
            if external_drift_x is None or external_drift_y is None:
                raise ValueError("Must specify coordinates of external Z drift terms.")
            ext = np.asarray(external_drift, dtype=float)
            ex = np.asarray(external_drift_x, dtype=float).ravel()
            ey = np.asarray(external_drift_y, dtype=float).ravel()
            if ext.ndim != 2:
                raise ValueError("external_drift must be a 2D array")
            if ext.shape != (ey.size, ex.size):
                if ext.shape == (ex.size, ey.size):
                    ext = ext.T
                else:
                    raise ValueError("External drift dimensions do not match provided x- and y-coordinate dimensions.")
            self.external_Z_array, self.external_Z_array_x, self.external_Z_array_y = ext, ex, ey
            self.z_scalars = self._calculate_data_point_zscalars(self.X_ORIG, self.Y_ORIG)
        self.point_log_drift = "point_log" in drift_terms
        if self.point_log_drift:
            if point_drift is None:
                raise ValueError("Must specify location(s) and strength(s) of point drift terms.")
            pl = np.atleast_2d(np.squeeze(np.array(point_drift, dtype=float)))
            self._point_log_orig = pl
            self._set_point_log()
        self.specified_drift = "specified" in drift_terms
        if self.specified_drift:
            if specified_drift is None:
                raise ValueError("Must provide a list of arrays for the 'specified' drift terms.")
            if not isinstance(specified_drift, list):
                raise TypeError("Arrays for specified drift terms must be encapsulated in a list.")
            if not specified_drift:
                raise ValueError("Must provide a list of arrays for the 'specified' drift terms.")
            self.specified_drift_data_arrays = []
            for term in specified_drift:
                s = np.atleast_1d(np.squeeze(np.array(term, dtype=float)))
                if s.size != self.X_ORIG.size:
                    raise ValueError("Must specify the drift values for each data point when using the 'specified' drift capability.")
                self.specified_drift_data_arrays.append(s)
        self.functional_drift = "functional" in drift_terms
        if self.functional_drift:
            if functional_drift is None:
                raise ValueError("Must provide a list of functions for the 'functional' drift terms.")
            if not isinstance(functional_drift, list):
                raise TypeError("Callables for functional drift terms must be encapsulated in a list.")
            if not functional_drift:
                raise ValueError("Must provide a list of functions for the 'functional' drift terms.")
            self.functional_drift_terms = functional_drift

    def _set_point_log(self):
        pl = self._point_log_orig
        arr = np.zeros(pl.shape)
        arr[:, 2] = pl[:, 2]
        arr[:, 0], arr[:, 1] = self._to_frame(pl[:, 0], pl[:, 1])
        self.point_log_array = arr

    def _on_frame_change(self):
        if getattr(self, "point_log_drift", False):
            self._set_point_log()

    def _calculate_data_point_zscalars(self, x, y, type_="array"):
        """The external drift at ``x, y`` (original coordinates), bilinear in its grid; a
        point outside the grid is a ``ValueError``."""
        x = np.asarray(x, dtype=float)
        y = np.asarray(y, dtype=float)
        gx, gy, g = self.external_Z_array_x, self.external_Z_array_y, self.external_Z_array
        xs, ys = x.ravel(), y.ravel()
        if (
            np.any(xs > gx.max()) or np.any(xs < gx.min())
            or np.any(ys > gy.max()) or np.any(ys < gy.min())
        ):
            raise ValueError("External drift array does not cover specified kriging domain.")
        ox, oy = np.argsort(gx, kind="stable"), np.argsort(gy, kind="stable")
        sx, sy = gx[ox], gy[oy]
        x2 = np.searchsorted(sx, xs, "left")
        x1 = np.searchsorted(sx, xs, "right") - 1
        y2 = np.searchsorted(sy, ys, "left")
        y1 = np.searchsorted(sy, ys, "right") - 1
        tx = np.where(x1 == x2, 0.0, (xs - sx[x1]) / np.where(x1 == x2, 1.0, sx[x2] - sx[x1]))
        ty = np.where(y1 == y2, 0.0, (ys - sy[y1]) / np.where(y1 == y2, 1.0, sy[y2] - sy[y1]))
        X1, X2, Y1, Y2 = ox[x1], ox[x2], oy[y1], oy[y2]
        z = (
            g[Y1, X1] * (1 - tx) * (1 - ty)
            + g[Y1, X2] * tx * (1 - ty)
            + g[Y2, X1] * (1 - tx) * ty
            + g[Y2, X2] * tx * ty
        )
        if type_ == "scalar":
            return float(z[0])
        return z.reshape(x.shape)

    # -- drifts for the numpy engine --------------------------------------------------------
    def _columns(self, xo, yo, xa, ya, specified):
        cols = []
        if self.regional_linear_drift:
            cols += [xa, ya]
        if self.point_log_drift:
            for xw, yw, q in self.point_log_array:
                with np.errstate(divide="ignore"):
                    ld = np.log(np.sqrt((xa - xw) ** 2 + (ya - yw) ** 2))
                ld[np.isinf(ld)] = -100.0
                cols.append(-q * ld)
        if self.external_Z_drift:
            cols.append(self._calculate_data_point_zscalars(xo, yo))
        if self.specified_drift:
            cols += list(specified)
        if self.functional_drift:
            cols += [np.broadcast_to(f(xa, ya), xa.shape).astype(float) for f in self.functional_drift_terms]
        cols.append(np.ones_like(xa))
        return np.column_stack(cols)

    def _drift_data(self):
        spec = self.specified_drift_data_arrays if self.specified_drift else []
        return self._columns(self.X_ORIG, self.Y_ORIG, self.X_ADJUSTED, self.Y_ADJUSTED, spec)

    def _drift_targets(self, xt, yt, xa, ya, extra):
        return self._columns(xt, yt, xa, ya, extra or [])

    def _fast_drift(self, extra):
        return not (self.point_log_drift or self.external_Z_drift or self.specified_drift or self.functional_drift)

    @property
    def _method(self):
        return "uk" if self.regional_linear_drift else "ok"

    def execute(
        self,
        style,
        xpoints,
        ypoints,
        mask=None,
        backend="vectorized",
        specified_drift_arrays=None,
    ):
        """Kriged values and variances on a ``'grid'``, at ``'points'`` or on a ``'masked'``
        grid; ``specified_drift_arrays`` give the specified drifts at the targets (shaped
        like the grid or the points). Both backends run the same code."""
        extra = None
        if self.specified_drift:
            if specified_drift_arrays is None:
                raise ValueError("Must provide drift values for kriging points when using 'specified' drift capability.")
            if not isinstance(specified_drift_arrays, list):
                raise TypeError("Arrays for specified drift terms must be encapsulated in a list.")
            if False:
                raise ValueError("Must provide drift values for kriging points when using 'specified' drift capability.")
            if len(specified_drift_arrays) != len(self.specified_drift_data_arrays):
                raise ValueError("Inconsistent number of specified drift terms supplied.")
            xs = np.atleast_1d(np.squeeze(np.asarray(xpoints, dtype=float)))
            ys = np.atleast_1d(np.squeeze(np.asarray(ypoints, dtype=float)))
            want = (ys.size, xs.size) if style in ("grid", "masked") else (xs.size,)
            extra = []
            for arr in specified_drift_arrays:
                a = np.asarray(arr, dtype=float)
                if style in ("grid", "masked"):
                    if a.ndim != 2:
                        raise ValueError("Dimensions of drift values array do not match specified grid dimensions.")
                    if a.shape != want:
                        if a.shape == want[::-1]:
                            a = a.T
                        else:
                            raise ValueError("Dimensions of drift values array do not match specified grid dimensions.")
                elif a.size != xs.size:
                    raise ValueError("Number of supplied drift values in array do not match specified number of kriging points.")
                extra.append(a.ravel())
        return self._execute_uk(style, xpoints, ypoints, mask, backend, extra)

    def _execute_uk(self, style, xpoints, ypoints, mask, backend, extra):
        if extra is not None and style == "masked" and mask is not None:
            m = np.asarray(mask)
            ny = np.atleast_1d(np.squeeze(np.asarray(ypoints))).size
            if m.shape[0] != ny:
                m = m.T
            keep = ~m.astype(bool).ravel()
            self._extra_full = extra
            extra = [e[keep] for e in extra]
        return self._execute(style, xpoints, ypoints, mask, backend, None, extra)
