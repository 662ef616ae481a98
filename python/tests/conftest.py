"""Shared fixtures: the repository root and seeded data."""

import pathlib

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture
def root():
    return ROOT


@pytest.fixture
def field():
    """300 seeded scattered points of a smooth surface with a trend (metres)."""
    rng = np.random.default_rng(7)
    x = rng.uniform(0, 2000, 300)
    y = rng.uniform(0, 1500, 300)
    z = 300 + 0.02 * x - 0.01 * y + 15 * np.sin(x / 300) * np.cos(y / 250)
    return x, y, z
