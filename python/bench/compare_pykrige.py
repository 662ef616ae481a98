"""Side-by-side timing of terramesh.pykrige against PyKrige, in the same run, printing ratios.

    python python/bench/compare_pykrige.py [--scale 1.0] [--repeat 1]

Cases (sizes times --scale):
  UK: UniversalKriging(regional_linear, spherical).execute("points") on 5,000 data, 20,000 targets
  OK: OrdinaryKriging(exponential).execute("points", n_closest_points=32) on 100,000 data and
      100,000 targets (PyKrige's fastest backend for a moving window, "C")

Only ``execute`` is timed. PyKrige's UniversalKriging constructor always runs its
leave-later-out statistics (O(n^4): hours at 5,000 data), and OrdinaryKriging's computes the
experimental variogram of every pair even with given parameters (37 GB at 100,000 data): the
script stubs out the first and gives the second only 2,000 data, for the PyKrige objects
(neither changes what ``execute`` computes). The estimates of
both are compared (largest difference printed) so that the ratio compares equal work.
"""

import argparse
import time

import numpy as np


def field(n, rng):
    x = rng.uniform(0, 10_000, n)
    y = rng.uniform(0, 10_000, n)
    z = 300 + 0.01 * x - 0.02 * y + 40 * np.sin(x / 900) * np.cos(y / 700) + rng.normal(0, 0.5, n)
    return x, y, z


def timed(f, repeat):
    best, out = np.inf, None
    for _ in range(repeat):
        t = time.perf_counter()
        out = f()
        best = min(best, time.perf_counter() - t)
    return best, out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--scale", type=float, default=1.0)
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--only", choices=["uk", "ok"])
    ap.add_argument("--ok-data", type=int, default=100_000,
                    help="data of the OK case (PyKrige's execute builds the n x n kriging matrix "
                         "even for a moving window: 2 x 75 GB at 100,000; 20,000 fits in 7 GB)")
    a = ap.parse_args()
    import pykrige
    import pykrige.uk as pk_uk
    from pykrige.ok import OrdinaryKriging as PkOK

    from terramesh.pykrige.ok import OrdinaryKriging
    from terramesh.pykrige.uk import UniversalKriging

    rng = np.random.default_rng(0)
    print(f"PyKrige {pykrige.__version__}; scale {a.scale}")
    if a.only in (None, "uk"):
        n, m = int(5_000 * a.scale), int(20_000 * a.scale)
        x, y, z = field(n, rng)
        xt, yt = rng.uniform(0, 10_000, m), rng.uniform(0, 10_000, m)
        kw = dict(variogram_model="spherical", variogram_parameters=[900.0, 3000.0, 0.25],
                  drift_terms=["regional_linear"])
        real = pk_uk._find_statistics
        pk_uk._find_statistics = lambda *args, **k: (np.zeros(1), np.ones(1), np.zeros(1))
        try:
            ref = pk_uk.UniversalKriging(x, y, z, **kw)
        finally:
            pk_uk._find_statistics = real
        ours = UniversalKriging(x, y, z, **kw)
        tp, (zp, sp) = timed(lambda: ref.execute("points", xt, yt), a.repeat)
        tt, (zt, st) = timed(lambda: ours.execute("points", xt, yt), a.repeat)
        print(f"UK {n} data x {m} targets: PyKrige {tp:.2f} s, terramesh {tt:.2f} s "
              f"({ours.engine}), ratio {tt / tp:.4f}; max |dz| {np.max(np.abs(zp - zt)):.2e}, "
              f"max |dvar| {np.max(np.abs(sp - st)):.2e}")
    if a.only in (None, "ok"):
        n, m = int(a.ok_data * a.scale), int(100_000 * a.scale)
        x, y, z = field(n, rng)
        xt, yt = rng.uniform(0, 10_000, m), rng.uniform(0, 10_000, m)
        kw = dict(variogram_model="exponential", variogram_parameters=[900.0, 3000.0, 0.25])
        # PyKrige's constructor computes the experimental variogram of every pair of data even
        # with given parameters (5e9 pairs, 37 GB at 100,000 data): it gets the lags of the
        # first 2,000 data instead (the given parameters are kept; execute is unchanged).
        import pykrige.ok as pk_ok

        real_init = pk_ok._initialize_variogram_model
        pk_ok._initialize_variogram_model = lambda X, y, *args, **k: real_init(X[:2000], y[:2000], *args, **k)
        try:
            ref = PkOK(x, y, z, **kw)
        finally:
            pk_ok._initialize_variogram_model = real_init
        ours = OrdinaryKriging(x, y, z, **kw)
        tp, (zp, sp) = timed(lambda: ref.execute("points", xt, yt, backend="C", n_closest_points=32), a.repeat)
        tt, (zt, st) = timed(lambda: ours.execute("points", xt, yt, n_closest_points=32), a.repeat)
        print(f"OK n_closest_points=32, {n} data x {m} targets: PyKrige {tp:.2f} s, terramesh "
              f"{tt:.2f} s ({ours.engine}), ratio {tt / tp:.4f}; max |dz| {np.max(np.abs(zp - zt)):.2e}")


if __name__ == "__main__":
    main()
