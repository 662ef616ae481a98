"""terramesh.utm against PROJ (pyproj), the independent reference."""

import numpy as np
import pytest
from pyproj import Transformer

import terramesh
from terramesh import utm


def proj(epsg):
    return Transformer.from_crs("EPSG:4326", f"EPSG:{epsg}", always_xy=True)


def test_forward_matches_proj_to_a_millimetre_over_a_zone():
    rng = np.random.default_rng(1)
    lat = rng.uniform(-79.0, 83.0, 20_000)
    lon = rng.uniform(6.0, 12.0, 20_000)  # zone 32 (no Norway exception below 56 N? forced)
    e, n, z = utm.forward(lat, lon, zone="32N")
    pe, pn = proj(32632).transform(lon, lat)
    assert z == "32N"
    assert np.max(np.abs(e - pe)) < 1e-3
    assert np.max(np.abs(n - pn)) < 1e-3


def test_forced_zone_far_outside_stays_accurate():
    lat = np.linspace(-60, 60, 500)
    lon = np.full(500, 9.0 + 20.0)  # 20 degrees east of zone 32's meridian
    e, n, _ = utm.forward(lat, lon, zone="32N")
    pe, pn = proj(32632).transform(lon, lat)
    assert np.max(np.hypot(e - pe, n - pn)) < 1e-3


def test_own_zones_and_the_south():
    lat = np.array([48.7224, -33.9, 60.5])
    lon = np.array([7.3368, 18.4, 5.0])
    e, n, z = utm.forward(lat, lon)
    assert z.tolist() == ["32N", "34S", "32N"]
    pe, pn = proj(32734).transform(18.4, -33.9)
    assert abs(e[1] - pe) < 1e-3 and abs(n[1] - pn) < 1e-3


def test_inverse_round_trips_and_matches_proj():
    rng = np.random.default_rng(2)
    lat = rng.uniform(-70, 70, 5000)
    lon = rng.uniform(-3, 3, 5000)
    e, n, z = utm.forward(lat, lon, zone="31N")
    la, lo = utm.inverse(e, n, "31N")
    assert np.max(np.abs(la - lat)) < 1e-9 and np.max(np.abs(lo - lon)) < 1e-9
    back = Transformer.from_crs("EPSG:32631", "EPSG:4326", always_xy=True)
    plo, pla = back.transform(e, n)
    assert np.max(np.abs(la - pla)) < 1e-8 and np.max(np.abs(lo - plo)) < 1e-8


def test_scalars_stay_scalars_and_shapes_are_kept():
    e, n, z = utm.forward(48.7224, 7.3368)
    assert isinstance(e, float) and isinstance(n, float) and z == "32N"
    e2, n2, _ = utm.forward(np.full((3, 4), 48.7224), np.full((3, 4), 7.3368))
    assert e2.shape == (3, 4) and np.all(e2 == e)


def test_parse_dms_matches_the_decimal_value():
    assert utm.parse_dms("N48°43'20.64\"") == pytest.approx(48 + 43 / 60 + 20.64 / 3600, abs=1e-12)
    assert utm.parse_dms("7°20'12.48\"W", axis="lon") == pytest.approx(-(7 + 20 / 60 + 12.48 / 3600), abs=1e-12)


def test_bad_input_raises_input_error_naming_the_point():
    with pytest.raises(terramesh.InputError, match="point 1"):
        utm.forward([48.0, 95.0], [7.0, 7.0])
    with pytest.raises(terramesh.InputError, match="zone '99X'"):
        utm.forward([48.0], [7.0], zone="99X")
    with pytest.raises(terramesh.InputError, match="same length"):
        utm.inverse([1.0, 2.0], [3.0], "32N")
    with pytest.raises(terramesh.InputError):
        utm.parse_dms("E7°20'", axis="lat")
    assert issubclass(terramesh.InputError, terramesh.Error)
