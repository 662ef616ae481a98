#!/usr/bin/env python3
"""OpenBLAS's triangular solve and matrix product rates here, beside faer's (`trsm_split`).

Run from the repository root: `OPENBLAS_NUM_THREADS=2 .venv-bench/bin/python bench/blas_rate.py`.
The same size as `target/release/examples/trsm_split 5000 4096`: a lower-triangular 5,000 x 5,000
factor and 4,096 right-hand sides (the dense kriging variances' solves, in one block). Prints
GFLOP/s of `scipy.linalg.blas.dtrsm` (n^2 m flops) and of a dgemm of the same shape (2 n^2 m).
"""
import time

import numpy as np
import scipy.linalg.blas as blas

n, m = 5000, 4096
rng = np.random.default_rng(0)
a = rng.standard_normal((n, n))
lower = np.asfortranarray(np.linalg.cholesky(a @ a.T / n + np.eye(n)))
rhs = np.asfortranarray(rng.standard_normal((n, m)))
for _ in range(3):
    t = time.perf_counter()
    blas.dtrsm(1.0, lower, rhs, lower=1)
    dt = time.perf_counter() - t
    print(f"dtrsm n={n} m={m}: {n * n * m / dt / 1e9:.1f} GFLOP/s ({dt:.2f} s)")
for _ in range(2):
    t = time.perf_counter()
    _ = lower.T @ rhs
    dt = time.perf_counter() - t
    print(f"dgemm {n}x{n} by {n}x{m}: {2 * n * n * m / dt / 1e9:.1f} GFLOP/s ({dt:.2f} s)")
