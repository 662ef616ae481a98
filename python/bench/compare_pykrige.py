"""Side-by-side timing of terramesh.pykrige against PyKrige, in the same run, printing ratios.

    python python/bench/compare_pykrige.py [--scale 1.0] [--repeat 1]

Cases (sizes times --scale):
  UK: UniversalKriging(regional_linear, spherical).execute("points") on 5,000 data, 20,000 targets
  OK: OrdinaryKriging(exponential).execute("points", n_closest_points=32) on 100,000 data and
      100,000 targets (PyKrige's fastest backend for a moving window, "C")

Only ``execute`` is timed, by wall clock and by the process's CPU time (user + system, all
threads: terramesh's rayon workers, PyKrige's BLAS), with the load average beside them: on a
shared machine the wall time of either side depends on the other jobs.

PyKrige's ``execute`` with ``n_closest_points`` still builds the full n x n kriging matrix
(2 x 75 GB at 100,000 data): it runs the OK case at ``--pykrige-max-data`` data (default
20,000, what fits in 23 GB) beside terramesh on the same data, then terramesh alone kriges
the full ``--ok-data``.

 PyKrige's UniversalKriging constructor always runs its
leave-later-out statistics (O(n^4): hours at 5,000 data), and OrdinaryKriging's computes the
experimental variogram of every pair even with given parameters (37 GB at 100,000 data): the
script stubs out the first and gives the second only 2,000 data, for the PyKrige objects
(neither changes what ``execute`` computes). The estimates of
both are compared (largest difference printed) so that the ratio compares equal work.
"""

import argparse
import os
import time

import numpy as np


def field(n, rng):
    x = rng.uniform(0, 10_000, n)
    y = rng.uniform(0, 10_000, n)
    z = 300 + 0.01 * x - 0.02 * y + 40 * np.sin(x / 900) * np.cos(y / 700) + rng.normal(0, 0.5, n)
    return x, y, z


def timed(f, repeat):
    """(wall s, CPU s) of the fastest of ``repeat`` calls, and the last result."""
    best, out = (np.inf, np.inf), None
    for _ in range(repeat):
        t, c = time.perf_counter(), time.process_time()
        out = f()
        best = min(best, (time.perf_counter() - t, time.process_time() - c))
    return best, out


def load():
    return "load %.1f" % os.getloadavg()[0]


def side(name, tc):
    return f"{name} {tc[0]:.2f} s wall, {tc[1]:.2f} s CPU"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--scale", type=float, default=1.0)
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--only", choices=["uk", "ok"])
    ap.add_argument("--ok-data", type=int, default=100_000,
                    help="data of the OK case for terramesh alone")
    ap.add_argument("--pykrige-max-data", type=int, default=20_000,
                    help="data of the side-by-side OK case (PyKrige's execute builds the n x n "
                         "kriging matrix even for a moving window: 2 x 75 GB at 100,000; "
                         "20,000 fits in 7 GB)")
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
        l0 = load()
        tp, (zp, sp) = timed(lambda: ref.execute("points", xt, yt), a.repeat)
        l1 = load()
        tt, (zt, st) = timed(lambda: ours.execute("points", xt, yt), a.repeat)
        print(f"UK {n} data x {m} targets: {side('PyKrige', tp)} ({l0}), "
              f"{side('terramesh', tt)} ({ours.engine}, {l1}); ratio wall {tt[0] / tp[0]:.4f}, "
              f"CPU {tt[1] / tp[1]:.4f}; max |dz| {np.max(np.abs(zp - zt)):.2e}, "
              f"max |dvar| {np.max(np.abs(sp - st)):.2e}", flush=True)
    if a.only in (None, "ok"):
        big, m = int(a.ok_data * a.scale), int(100_000 * a.scale)
        n = min(big, int(a.pykrige_max_data * a.scale))
        xb, yb, zb = field(big, rng)
        x, y, z = xb[:n], yb[:n], zb[:n]
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
        l0 = load()
        tp, (zp, sp) = timed(lambda: ref.execute("points", xt, yt, backend="C", n_closest_points=32), a.repeat)
        del ref
        l1 = load()
        tt, (zt, st) = timed(lambda: ours.execute("points", xt, yt, n_closest_points=32), a.repeat)
        print(f"OK n_closest_points=32, {n} data x {m} targets: {side('PyKrige', tp)} ({l0}), "
              f"{side('terramesh', tt)} ({ours.engine}, {l1}); ratio wall {tt[0] / tp[0]:.4f}, "
              f"CPU {tt[1] / tp[1]:.4f}; max |dz| {np.max(np.abs(zp - zt)):.2e}, "
              f"max |dvar| {np.max(np.abs(sp - st)):.2e}", flush=True)
        if big > n:
            ours = OrdinaryKriging(xb, yb, zb, **kw)
            l1 = load()
            tt, _ = timed(lambda: ours.execute("points", xt, yt, n_closest_points=32), a.repeat)
            print(f"OK n_closest_points=32, {big} data x {m} targets: PyKrige not run (its n x n "
                  f"matrix: {2 * 8 * big * big / 1e9:.0f} GB), {side('terramesh', tt)} "
                  f"({ours.engine}, {l1})", flush=True)


if __name__ == "__main__":
    main()
