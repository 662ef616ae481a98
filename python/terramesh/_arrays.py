"""The one conversion of user input to what the compiled core takes: contiguous float64
arrays, whole numbers and finite floats, each refused with an :class:`InputError` naming the
argument (and the index of a bad value) instead of a crash, a silent wrong result or a bare
Python error."""

from __future__ import annotations

import operator
import sys
from typing import Optional

import numpy as np

from ._terramesh import InputError


def _what(a) -> str:
    return "None" if a is None else type(a).__name__


def _unmasked(a, name: str):
    """``a`` without its mask when nothing is masked; an error when a value is masked (a
    masked array's hidden values, such as a fill value of 1e20, must never be computed
    with)."""
    if not np.ma.isMaskedArray(a):
        return a
    masked = int(np.count_nonzero(np.ma.getmaskarray(a)))
    if masked:
        first = np.unravel_index(int(np.flatnonzero(np.ma.getmaskarray(a))[0]), np.shape(a))
        at = first[0] if len(first) == 1 else tuple(int(i) for i in first)
        raise InputError(
            f"{name}: a masked array with {masked} masked value(s) (the first at index {at}): "
            "drop those points from every argument (np.ma.compressed, or a common boolean "
            "index), or fill them with a value of your choice (a.filled(value))"
        )
    return np.ma.getdata(a)


def _finite(arr: np.ndarray, name: str, shape) -> None:
    ok = np.isfinite(arr)
    if not ok.all():
        i = int(np.flatnonzero(~ok)[0])
        at = np.unravel_index(i, shape) if len(shape) > 1 else (i,)
        index = ", ".join(str(int(k)) for k in at)
        raise InputError(
            f"{name}[{index}] is {arr[i]}: every value must be a finite number (drop or fill "
            "missing values first)"
        )


def _floats(a, name: str) -> np.ndarray:
    """``a`` as a float64 ndarray of any shape: numbers only, no masked value."""
    if a is None:
        raise InputError(f"{name}: give an array of numbers, not None")
    if isinstance(a, (str, bytes, dict)):
        raise InputError(f"{name}: give an array of numbers, not a {_what(a)}")
    a = _unmasked(a, name)
    if np.iscomplexobj(a):
        raise InputError(f"{name}: complex numbers given: give real numbers")
    try:
        arr = np.asarray(a, dtype=np.float64)
    except (TypeError, ValueError, OverflowError) as e:
        raise InputError(f"{name}: not an array of numbers ({e})") from None
    return arr


def vec(a, name: str, finite: bool = True) -> np.ndarray:
    """A 1-D contiguous float64 array of ``a`` (a view when it already is one; other shapes
    are flattened), every value finite unless ``finite=False``.

    >>> vec([1, 2.5], "x").tolist()
    [1.0, 2.5]
    >>> vec([1.0, float("inf")], "xt")
    Traceback (most recent call last):
    _terramesh.InputError: xt[1] is inf: every value must be a finite number (drop or fill missing values first)
    """
    arr = _floats(a, name)
    shape = arr.shape
    arr = np.ascontiguousarray(arr.reshape(-1))
    if finite:
        _finite(arr, name, shape)
    return arr


def shaped(a, name: str, finite: bool = True):
    """``vec(a)`` and the shape to give results back (scalars stay scalars)."""
    arr = _floats(a, name)
    return vec(arr, name, finite), arr.shape


def reshape(out: np.ndarray, shape):
    if shape == ():
        return float(out[0]) if out.dtype.kind == "f" else out[0]
    return out.reshape(shape)


def points(a, name: str) -> list:
    """An n x 2 (or n x 3, the third column dropped) array of finite coordinates as a list of
    ``[x, y]``.

    >>> points([(0, 1), (2, 3)], "points")
    [[0.0, 1.0], [2.0, 3.0]]
    """
    arr = _floats(a, name)
    if arr.ndim != 2 or arr.shape[1] < 2:
        raise InputError(
            f"{name}: an array of shape {arr.shape} given: give an n x 2 array or a list of "
            "(x, y) pairs"
        )
    arr = np.ascontiguousarray(arr[:, :2])
    _finite(arr.reshape(-1), name, arr.shape)
    return arr.tolist()


def count(v, name: str, minimum: int = 0, none: bool = False) -> Optional[int]:
    """A whole number of at least ``minimum`` (``None`` passes when ``none``).

    >>> count(3.0, "lags", 1)
    3
    >>> count(-1, "folds", 2)
    Traceback (most recent call last):
    _terramesh.InputError: folds -1: give a whole number of at least 2
    """
    if v is None:
        if none:
            return None
        raise InputError(f"{name}: give a whole number, not None")
    if isinstance(v, bool):
        raise InputError(f"{name} {v}: give a whole number, not a bool")
    try:
        n = operator.index(v)
    except TypeError:
        if isinstance(v, (float, np.floating)) and float(v).is_integer():
            n = int(v)
        else:
            raise InputError(f"{name} {v!r}: give a whole number") from None
    if n < minimum:
        raise InputError(f"{name} {n}: give a whole number of at least {minimum}")
    if n > sys.maxsize:
        raise InputError(f"{name} {n}: give a whole number of at most {sys.maxsize}")
    return n


def number(v, name: str, none: bool = False) -> Optional[float]:
    """A finite float (``None`` passes when ``none``).

    >>> number(2, "power")
    2.0
    """
    if v is None:
        if none:
            return None
        raise InputError(f"{name}: give a number, not None")
    if isinstance(v, (str, bytes)) or np.iscomplexobj(v):
        raise InputError(f"{name} {v!r}: give a real number")
    try:
        f = float(v)
    except (TypeError, ValueError, OverflowError):
        raise InputError(f"{name}: give a number, not a {_what(v)}") from None
    if not np.isfinite(f):
        raise InputError(f"{name} {f}: give a finite number")
    return f
