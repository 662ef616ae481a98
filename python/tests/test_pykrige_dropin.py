"""terramesh.pykrige against PyKrige itself on the same inputs (beyond PyKrige's own suite,
which python/conformance/run.py runs)."""

import numpy as np
import pytest
from pykrige.ok import OrdinaryKriging as PkOK
from pykrige.uk import UniversalKriging as PkUK

from terramesh.pykrige.ok import OrdinaryKriging
from terramesh.pykrige.uk import UniversalKriging


@pytest.mark.parametrize("model,params", [
    ("linear", [0.08, 1.0]),
    ("power", [0.5, 1.3, 0.0]),
    ("spherical", [120.0, 900.0, 2.0]),
    ("exponential", [100.0, 600.0, 0.0]),
    ("gaussian", [100.0, 500.0, 0.5]),
])
def test_same_numbers_through_the_terramesh_kernel(field, model, params):
    x, y, z = field
    gx, gy = np.linspace(0, 2000, 25), np.linspace(0, 1500, 20)
    kw = dict(variogram_model=model, variogram_parameters=params, anisotropy_scaling=1.5, anisotropy_angle=30.0)
    for ours, ref, extra in ((OrdinaryKriging, PkOK, {}), (UniversalKriging, PkUK, {"drift_terms": ["regional_linear"]})):
        a = ours(x, y, z, **kw, **extra)
        b = ref(x, y, z, **kw, **extra)
        za, sa = a.execute("grid", gx, gy)
        zb, sb = b.execute("grid", gx, gy)
        assert a.engine == "terramesh"
        np.testing.assert_allclose(za, zb, rtol=1e-7, atol=1e-6)
        np.testing.assert_allclose(sa, sb, rtol=1e-6, atol=1e-6)


def test_fitted_variogram_and_statistics_match_pykrige(field):
    x, y, z = field
    x, y, z = x[:80], y[:80], z[:80]
    a = OrdinaryKriging(x, y, z, variogram_model="spherical", nlags=8, weight=True)
    b = PkOK(x, y, z, variogram_model="spherical", nlags=8, weight=True, enable_statistics=True)
    np.testing.assert_allclose(a.lags, b.lags, rtol=1e-12)
    np.testing.assert_allclose(a.semivariance, b.semivariance, rtol=1e-12)
    # The fitted nugget sits at its bound 0 (about 5e-10 in both, orders of magnitude below the
    # sill): a parameter at rounding size is compared absolutely, relative to the largest.
    scale = 1e-9 * max(b.variogram_model_parameters)
    np.testing.assert_allclose(a.variogram_model_parameters, b.variogram_model_parameters, rtol=1e-5, atol=scale)
    np.testing.assert_allclose(a.get_statistics(), b.get_statistics(), rtol=1e-6)
    np.testing.assert_allclose(a.get_epsilon_residuals(), b.get_epsilon_residuals(), rtol=1e-6)


def test_moving_window_matches_pykrige(field):
    x, y, z = field
    rng = np.random.default_rng(5)
    xt, yt = rng.uniform(0, 2000, 300), rng.uniform(0, 1500, 300)
    kw = dict(variogram_model="exponential", variogram_parameters=[100.0, 600.0, 1.0])
    za, sa = OrdinaryKriging(x, y, z, **kw).execute("points", xt, yt, n_closest_points=32)
    zb, sb = PkOK(x, y, z, **kw).execute("points", xt, yt, n_closest_points=32, backend="loop")
    np.testing.assert_allclose(za, zb, atol=1e-7)
    np.testing.assert_allclose(sa, sb, rtol=1e-6, atol=1e-7)


def test_numpy_engine_for_what_terramesh_has_no_kernel_for(field):
    x, y, z = field
    kw = dict(variogram_model="hole-effect", variogram_parameters=[100.0, 600.0, 1.0])
    a = OrdinaryKriging(x, y, z, **kw)
    za, sa = a.execute("points", [100.0, 900.0], [200.0, 700.0])
    zb, sb = PkOK(x, y, z, **kw).execute("points", np.array([100.0, 900.0]), np.array([200.0, 700.0]))
    assert a.engine == "numpy"
    np.testing.assert_allclose(za, zb, rtol=1e-9)
    np.testing.assert_allclose(sa, sb, rtol=1e-9)


def test_a_gstools_covmodel_as_pykrige_takes_it(field):
    # PyKrige 1.7 takes a GSTools CovModel as variogram_model: its pykrige_vario as a custom
    # function, its anisotropy as the frame. The same numbers through terramesh.pykrige.
    gs = pytest.importorskip("gstools")
    x, y, z = field
    gx, gy = np.linspace(0, 2000, 15), np.linspace(0, 1500, 12)
    model = gs.Gaussian(dim=2, var=100.0, len_scale=[500.0, 250.0], angles=0.4, nugget=0.5)
    for ours, ref, extra in ((OrdinaryKriging, PkOK, {}), (UniversalKriging, PkUK, {"drift_terms": ["regional_linear"]})):
        a = ours(x, y, z, variogram_model=model, **extra)
        b = ref(x, y, z, variogram_model=model, **extra)
        assert a.model is model and a.variogram_model == "custom"
        assert (a.anisotropy_scaling, a.anisotropy_angle) == (b.anisotropy_scaling, b.anisotropy_angle)
        za, sa = a.execute("grid", gx, gy)
        zb, sb = b.execute("grid", gx, gy)
        np.testing.assert_allclose(za, zb, rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(sa, sb, rtol=1e-9, atol=1e-9)
    # A latlon model needs geographic coordinates, and universal kriging takes none.
    latlon = gs.Gaussian(latlon=True, var=1.0, len_scale=0.2)
    with pytest.raises(ValueError, match="latlon"):
        OrdinaryKriging(x, y, z, variogram_model=latlon)
    with pytest.raises(ValueError, match="latlon"):
        UniversalKriging(x, y, z, variogram_model=latlon)
