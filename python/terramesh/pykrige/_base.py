"""The machinery shared by :class:`~terramesh.pykrige.ok.OrdinaryKriging` and
:class:`~terramesh.pykrige.uk.UniversalKriging`: PyKrige 1.7's constructor arguments,
attributes and methods over two engines.

* **terramesh** (the compiled kernel, :func:`terramesh.krige`): for PyKrige's built-in
  linear, power, Gaussian, spherical and exponential models in Euclidean coordinates, with
  no drift (OK) or ``regional_linear`` only (UK), exact values (or no nugget), no
  pseudo-inverse. The data and targets go in PyKrige's anisotropy frame, so the geometry is
  PyKrige's own. ``n_closest_points`` is terramesh's moving neighbourhood.
* **numpy** (this module): the same kriging system assembled and solved in numpy, for
  what terramesh has no kernel for: custom and hole-effect models, great-circle distances,
  ``point_log``, ``external_Z``, ``specified`` and ``functional`` drifts, smoothing at data
  points (``exact_values=False`` with a nugget), pseudo-inverses, and the leave-later-out
  statistics (``Q1``, ``Q2``, ``cR``).

:attr:`engine` says which one the last :meth:`execute` used.
"""

from __future__ import annotations

import numpy as np

from . import _setup
from .variogram_models import MODELS

BACKENDS = ("vectorized", "loop", "C")


def _unmasked(a, name):
    """``a`` without a mask hiding nothing; a ``ValueError`` (PyKrige's class for bad input)
    for a masked array with masked values, whose hidden values PyKrige would krige with."""
    from .._arrays import _unmasked as check
    from .._terramesh import InputError

    try:
        return check(a, name)
    except InputError as e:
        raise ValueError(str(e)) from None


class KrigingBase:
    """Common constructor and methods; see the subclasses."""

    _uk = False

    def _init_common(
        self,
        x,
        y,
        z,
        variogram_model,
        variogram_parameters,
        variogram_function,
        nlags,
        weight,
        anisotropy_scaling,
        anisotropy_angle,
        verbose,
        enable_plotting,
        enable_statistics,
        exact_values,
        pseudo_inv,
        pseudo_inv_type,
        coordinates_type,
    ):
        if not isinstance(exact_values, bool):
            raise ValueError("exact_values has to be boolean True or False")
        if pseudo_inv_type not in ("pinv", "pinvh"):
            raise ValueError(f"pseudo_inv_type '{pseudo_inv_type}' not known: give 'pinv' or 'pinvh'")
        if coordinates_type not in ("euclidean", "geographic"):
            raise ValueError("Only 'euclidean' and 'geographic' are valid values for coordinates-keyword.")
        self.coordinates_type = coordinates_type
        self.model = None
        if hasattr(variogram_model, "pykrige_kwargs"):
            (variogram_model, variogram_function, variogram_parameters,
             anisotropy_scaling, anisotropy_angle) = self._covmodel(variogram_model)
        if not isinstance(variogram_model, str):
            raise ValueError(
                "terramesh.pykrige takes variogram models by name ('linear', 'power', 'gaussian', "
                "'spherical', 'exponential', 'hole-effect', 'custom') or as a GSTools CovModel"
            )
        self.exact_values = exact_values
        self.pseudo_inv = bool(pseudo_inv)
        self.pseudo_inv_type = pseudo_inv_type
        self.verbose = verbose
        self.enable_plotting = enable_plotting
        self.enable_statistics = enable_statistics
        x, y, z = _unmasked(x, "x"), _unmasked(y, "y"), _unmasked(z, "z")
        self.X_ORIG = np.atleast_1d(np.squeeze(np.array(x, copy=True, dtype=np.float64)))
        self.Y_ORIG = np.atleast_1d(np.squeeze(np.array(y, copy=True, dtype=np.float64)))
        self.Z = np.atleast_1d(np.squeeze(np.array(z, copy=True, dtype=np.float64)))
        if not (self.X_ORIG.shape == self.Y_ORIG.shape == self.Z.shape):
            raise ValueError("x, y and z must have the same number of values")
        self.XCENTER = (np.amax(self.X_ORIG) + np.amin(self.X_ORIG)) / 2.0
        self.YCENTER = (np.amax(self.Y_ORIG) + np.amin(self.Y_ORIG)) / 2.0
        if coordinates_type == "geographic":
            # Distances are great circles: no anisotropy frame (PyKrige ignores it too).
            anisotropy_scaling, anisotropy_angle = 1.0, 0.0
            self.XCENTER, self.YCENTER = 0.0, 0.0
        self.anisotropy_scaling = anisotropy_scaling
        self.anisotropy_angle = anisotropy_angle
        self._frame()
        self.nlags = nlags
        self.weight = weight
        self._set_model(variogram_model, variogram_parameters, variogram_function)
        self.engine = None
        self._stats = None

    def _covmodel(self, model):
        """A GSTools ``CovModel`` as PyKrige 1.7 takes it: a ``'custom'`` model whose function
        is the model's ``pykrige_vario``, no parameters to fit, and the model's anisotropy
        (``pykrige_anis``, ``pykrige_angle``); kriged by the numpy engine. The same checks and
        messages as PyKrige's. Keeps the model as :attr:`model` and returns the model name,
        function, parameters, anisotropy scaling and angle."""
        try:
            import gstools as gs
        except ImportError as e:  # pragma: no cover - pykrige_kwargs comes from gstools
            raise ValueError("GSTools needs to be installed in order to use their CovModel class.") from e
        if not isinstance(model, gs.CovModel):
            raise ValueError("GSTools: given variogram model is not a CovModel instance.")
        if model.field_dim == 3:
            raise ValueError("GSTools: model dim is not 1 or 2")
        if self._uk and model.latlon:
            raise ValueError("GSTools: latlon models not supported for universal kriging")
        if model.latlon and self.coordinates_type == "euclidean":
            raise ValueError("GSTools: latlon models require geographic coordinates")
        self.model = model
        return "custom", model.pykrige_vario, [], model.pykrige_anis, model.pykrige_angle

    # -- geometry ---------------------------------------------------------------------------
    def _frame(self):
        if self.coordinates_type == "geographic":
            self.X_ADJUSTED, self.Y_ADJUSTED = self.X_ORIG.copy(), self.Y_ORIG.copy()
        else:
            self.X_ADJUSTED, self.Y_ADJUSTED = _setup.adjust(
                self.X_ORIG, self.Y_ORIG, (self.XCENTER, self.YCENTER),
                self.anisotropy_scaling, self.anisotropy_angle,
            )

    def _to_frame(self, x, y):
        if self.coordinates_type == "geographic":
            return x, y
        return _setup.adjust(x, y, (self.XCENTER, self.YCENTER), self.anisotropy_scaling, self.anisotropy_angle)

    # -- the variogram ----------------------------------------------------------------------
    def _set_model(self, model, params, function):
        if model not in MODELS and model != "custom":
            raise ValueError(f"Specified variogram model '{model}' is not supported.")
        if model == "custom":
            if params is None or function is None or not callable(function):
                raise ValueError(
                    "Must specify (callable) variogram_function and variogram_parameters for a custom model."
                )
            self.variogram_function = function
        else:
            self.variogram_function = MODELS[model]
        self.variogram_model = model
        self._lags = None
        p = _setup.parameter_list(model, params)
        if p is None:
            p = _setup.fit(self.lags, self.semivariance, model, self.variogram_function, self.weight)
        self.variogram_model_parameters = p
        self._tm = None if model == "custom" else _setup.terramesh_variogram(model, p)
        self._stats = None

    def _experimental(self):
        # Every pair of data: computed when first needed (a fit, or these attributes), so
        # that given parameters krige 100,000 data without 5e9 pair distances.
        if self._lags is None:
            self._lags = _setup.experimental(
                self.X_ADJUSTED, self.Y_ADJUSTED, self.Z, self.nlags,
                self.coordinates_type == "geographic",
            )
        return self._lags

    lags = property(lambda self: self._experimental()[0], doc="Mean distance of each lag class.")
    semivariance = property(lambda self: self._experimental()[1], doc="Semivariance of each lag class.")

    def update_variogram_model(
        self,
        variogram_model,
        variogram_parameters=None,
        variogram_function=None,
        nlags=6,
        weight=False,
        anisotropy_scaling=1.0,
        anisotropy_angle=0.0,
    ):
        """Changes the variogram model (and the anisotropy), as PyKrige's method; a GSTools
        ``CovModel`` brings its own function and anisotropy."""
        self.model = None
        if hasattr(variogram_model, "pykrige_kwargs"):
            (variogram_model, variogram_function, variogram_parameters,
             anisotropy_scaling, anisotropy_angle) = self._covmodel(variogram_model)
        if not isinstance(variogram_model, str):
            raise ValueError("variogram_model must be a name or a GSTools CovModel")
        if self.coordinates_type == "euclidean" and (
            anisotropy_scaling != self.anisotropy_scaling or anisotropy_angle != self.anisotropy_angle
        ):
            self.anisotropy_scaling, self.anisotropy_angle = anisotropy_scaling, anisotropy_angle
            self._frame()
            self._on_frame_change()
        self.nlags, self.weight = nlags, weight
        self._set_model(variogram_model, variogram_parameters, variogram_function)

    def _on_frame_change(self):
        pass

    def get_variogram_points(self):
        """``(lags, model semivariance at the lags)``."""
        return self.lags, self.variogram_function(self.variogram_model_parameters, self.lags)

    def display_variogram_model(self):
        """Plots the experimental variogram and the model (needs matplotlib)."""
        import matplotlib.pyplot as plt

        fig = plt.figure()
        ax = fig.add_subplot(111)
        ax.plot(self.lags, self.semivariance, "r*")
        ax.plot(self.lags, self.variogram_function(self.variogram_model_parameters, self.lags), "k-")
        plt.show()

    # -- the kriging system (numpy engine) --------------------------------------------------
    def _gamma(self, d):
        return np.asarray(self.variogram_function(self.variogram_model_parameters, d), dtype=float)

    def _drift_data(self):
        """Drift columns at the data (n x m, the constant last)."""
        return np.ones((len(self.Z), 1))

    def _drift_targets(self, xt, yt, xa, ya, extra):
        """Drift columns at the targets (original ``xt, yt`` and framed ``xa, ya``)."""
        return np.ones((len(xt), 1))

    def _solve_numpy(self, xt, yt, extra=None, n_closest=None, data_idx=None):
        """Estimates and variances of the kriging system in numpy."""
        geo = self.coordinates_type == "geographic"
        xa, ya = self._to_frame(xt, yt)
        Xd, Yd, Zd = self.X_ADJUSTED, self.Y_ADJUSTED, self.Z
        F = self._drift_data()
        Ft = self._drift_targets(xt, yt, xa, ya, extra)
        n, m = len(Zd), F.shape[1]
        est, var = np.empty(len(xt)), np.empty(len(xt))
        if n_closest is not None:
            for k in range(len(xt)):
                d_all = _setup.distances(xa[k : k + 1], ya[k : k + 1], Xd, Yd, geo)[0]
                idx = np.argsort(d_all, kind="stable")[:n_closest]
                e, v = self._system(Xd[idx], Yd[idx], Zd[idx], F[idx], d_all[idx][None, :], Ft[k : k + 1], geo)
                est[k], var[k] = e[0], v[0]
            return est, var
        step = max(1, 2_000_000 // max(n, 1))
        for lo in range(0, len(xt), step):
            sl = slice(lo, lo + step)
            bd = _setup.distances(xa[sl], ya[sl], Xd, Yd, geo)
            est[sl], var[sl] = self._system(Xd, Yd, Zd, F, bd, Ft[sl], geo)
        return est, var

    def _system(self, Xd, Yd, Zd, F, bd, Ft, geo):
        n, m = len(Zd), F.shape[1]
        d = _setup.distances(Xd, Yd, Xd, Yd, geo)
        a = np.zeros((n + m, n + m))
        a[:n, :n] = -self._gamma(d)
        np.fill_diagonal(a[:n, :n], 0.0)
        a[:n, n:] = F
        a[n:, :n] = F.T
        b = np.zeros((bd.shape[0], n + m))
        b[:, :n] = -self._gamma(bd)
        if self.exact_values:
            b[:, :n][np.abs(bd) <= _setup.EPS] = 0.0
        b[:, n:] = Ft
        if self.pseudo_inv:
            if self.pseudo_inv_type == "pinvh":
                from scipy.linalg import pinvh

                ainv = pinvh(a)
            else:
                ainv = np.linalg.pinv(a)
            x = b @ ainv.T
        else:
            try:
                x = np.linalg.solve(a, b.T).T
            except np.linalg.LinAlgError:
                # PyKrige inverts with scipy, which does not refuse a system singular only up
                # to rounding (collinear drifts); a pseudo-inverse gives its minimum-norm answer.
                import warnings

                warnings.warn(
                    "the kriging system is singular (collinear drift terms?): solved with a pseudo-inverse",
                    RuntimeWarning,
                )
                x = b @ np.linalg.pinv(a).T
        est = x[:, :n] @ Zd
        var = np.sum(x * -b, axis=1)
        return est, var

    # -- statistics -------------------------------------------------------------------------
    def _statistics(self):
        """PyKrige's leave-later-out residuals: datum i by ordinary kriging of data 0..i-1."""
        if self._stats is None:
            geo = self.coordinates_type == "geographic"
            n = len(self.Z)
            delta, sigma = np.zeros(n), np.zeros(n)
            saved = self.exact_values
            for i in range(1, n):
                X, Y, Z = self.X_ADJUSTED[:i], self.Y_ADJUSTED[:i], self.Z[:i]
                bd = _setup.distances(self.X_ADJUSTED[i : i + 1], self.Y_ADJUSTED[i : i + 1], X, Y, geo)
                try:
                    self.exact_values = True
                    k, ss = self._system(X, Y, Z, np.ones((i, 1)), bd, np.ones((1, 1)), geo)
                except np.linalg.LinAlgError:
                    continue
                finally:
                    self.exact_values = saved
                if abs(ss[0]) < _setup.EPS:
                    continue
                delta[i], sigma[i] = self.Z[i] - k[0], np.sqrt(ss[0])
            keep = sigma > _setup.EPS
            delta, sigma = delta[keep], sigma[keep]
            eps = delta / sigma
            m = max(len(eps) - 1, 1)
            q1 = abs(np.sum(eps) / m)
            q2 = np.sum(eps**2) / m
            cr = q2 * np.exp(np.sum(np.log(sigma**2)) / max(len(sigma), 1))
            self._stats = (delta, sigma, eps, q1, q2, cr)
        return self._stats

    delta = property(lambda self: self._statistics()[0], doc="Leave-later-out errors.")
    sigma = property(lambda self: self._statistics()[1], doc="Their kriging standard deviations.")
    epsilon = property(lambda self: self._statistics()[2], doc="delta / sigma.")
    Q1 = property(lambda self: self._statistics()[3], doc="|mean of epsilon| (ideally 0).")
    Q2 = property(lambda self: self._statistics()[4], doc="Mean of epsilon² (ideally 1).")
    cR = property(lambda self: self._statistics()[5], doc="Q2 times the geometric mean of sigma².")

    def get_epsilon_residuals(self):
        """The standardised residuals ``epsilon``."""
        return self.epsilon

    def plot_epsilon_residuals(self):
        """Plots ``epsilon`` (needs matplotlib)."""
        import matplotlib.pyplot as plt

        plt.scatter(range(self.epsilon.size), self.epsilon, c="k", marker="*")
        plt.axhline(y=0.0)
        plt.show()

    def get_statistics(self):
        """``(Q1, Q2, cR)``."""
        return self.Q1, self.Q2, self.cR

    def print_statistics(self):
        """Prints Q1, Q2 and cR."""
        print("Q1 =", self.Q1)
        print("Q2 =", self.Q2)
        print("cR =", self.cR)

    # -- execute ----------------------------------------------------------------------------
    def _targets(self, style, xpoints, ypoints, mask):
        if style not in ("grid", "masked", "points"):
            raise ValueError(f"style argument must be 'grid', 'points', or 'masked', not '{style}'")
        xpoints, ypoints = _unmasked(xpoints, "xpoints"), _unmasked(ypoints, "ypoints")
        xp = np.atleast_1d(np.squeeze(np.array(xpoints, copy=True, dtype=np.float64)))
        yp = np.atleast_1d(np.squeeze(np.array(ypoints, copy=True, dtype=np.float64)))
        if style in ("grid", "masked"):
            shape = (yp.size, xp.size)
            gx, gy = np.meshgrid(xp, yp)
            gx, gy = gx.ravel(), gy.ravel()
            if style == "masked":
                if mask is None:
                    raise IOError("Must specify boolean masking array when style is 'masked'.")
                mask = np.asarray(mask)
                if mask.ndim != 2:
                    raise ValueError("Mask is not two-dimensional.")
                if mask.shape != shape:
                    if mask.shape[0] == shape[1] and mask.shape[1] == shape[0]:
                        mask = mask.T
                    else:
                        raise ValueError("Mask dimensions do not match specified grid dimensions.")
                mask = mask.astype(bool)
            return gx, gy, shape, mask
        if xp.size != yp.size:
            raise ValueError("xpoints and ypoints must have same dimensions when treated as listing discrete points.")
        return xp, yp, (xp.size,), None

    def _fast_ok(self, extra):
        """Whether the terramesh kernel computes this system."""
        return (
            self._tm is not None
            and self.coordinates_type == "euclidean"
            and not self.pseudo_inv
            and (self.exact_values or self.variogram_model_parameters[-1] == 0.0)
            and self._fast_drift(extra)
        )

    def _fast_drift(self, extra):
        return True

    def _execute(self, style, xpoints, ypoints, mask, backend, n_closest_points, extra=None):
        if backend not in self._backends:
            raise ValueError(f"Specified backend {backend} is not supported for 2D kriging.")
        if n_closest_points is not None and n_closest_points <= 1:
            raise ValueError("n_closest_points has to be at least two!")
        gx, gy, shape, mask = self._targets(style, xpoints, ypoints, mask)
        sel = np.ones(gx.size, bool) if mask is None else ~mask.ravel()
        xt, yt = gx[sel], gy[sel]
        est, var = np.zeros(gx.size), np.zeros(gx.size)
        if xt.size:
            e, v = self._run(xt, yt, extra, n_closest_points)
            est[sel], var[sel] = e, v
        est, var = est.reshape(shape), var.reshape(shape)
        if mask is not None:
            est = np.ma.array(est, mask=mask)
            var = np.ma.array(var, mask=mask)
        return est, var

    def _run(self, xt, yt, extra, n_closest):
        from .. import krige, InputError, ComputationError

        if self._fast_ok(extra):
            xa, ya = self._to_frame(xt, yt)
            k = None if n_closest is None else min(int(n_closest), len(self.Z))
            try:
                est, var = krige(
                    self.X_ADJUSTED, self.Y_ADJUSTED, self.Z, xa, ya,
                    method=self._method, drift="linear", variogram=self._tm, neighbors=k,
                )
                self.engine = "terramesh"
                return est, var
            except (InputError, ComputationError):
                pass  # duplicate data or a singular system: numpy gives PyKrige's answer
        self.engine = "numpy"
        return self._solve_numpy(xt, yt, extra, n_closest)
