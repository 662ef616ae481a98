"""Conversions of user input to the contiguous float64 arrays the compiled core borrows."""

from __future__ import annotations

import numpy as np

from ._terramesh import InputError


def vec(a, name: str) -> np.ndarray:
    """A 1-D contiguous float64 array (a view when `a` already is one)."""
    try:
        arr = np.ascontiguousarray(a, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise InputError(f"{name}: not an array of numbers ({e})") from None
    if arr.ndim == 0:
        arr = arr.reshape(1)
    if arr.ndim != 1:
        arr = arr.reshape(-1)
    return arr


def shaped(a, name: str):
    """`vec(a)` and the shape to give results back (scalars stay scalars)."""
    arr = np.asarray(a, dtype=np.float64) if not isinstance(a, np.ndarray) else a
    return vec(arr, name), np.shape(arr)


def reshape(out: np.ndarray, shape):
    if shape == ():
        return float(out[0]) if out.dtype.kind == "f" else out[0]
    return out.reshape(shape)
