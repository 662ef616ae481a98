"""WGS-84 latitude/longitude <-> UTM, vectorised over numpy arrays (float64).

The same kernel and accuracy as ``terramesh convert``: Krüger's series to the sixth order
(Karney 2011), better than a millimetre within the zone and usable in a forced zone up to
about 35 degrees of longitude away from its central meridian.

>>> from terramesh import utm
>>> e, n, z = utm.forward(48.7224, 7.3368)
>>> round(e, 2), round(n, 2), z
(377676.93, 5397931.49, '32N')
>>> lat, lon = utm.inverse(e, n, z)
>>> round(lat, 9), round(lon, 9)
(48.7224, 7.3368)
>>> utm.parse_dms('N48°43\\'20.64"')
48.7224
"""

from __future__ import annotations

from typing import Optional, Tuple, Union

import numpy as np

from . import _terramesh as _core
from ._arrays import reshape, shaped

ArrayLike = Union[float, np.ndarray, list]

__all__ = ["forward", "inverse", "parse_dms", "zone_of"]


def forward(lat: ArrayLike, lon: ArrayLike, zone: Optional[str] = None):
    """Projects WGS-84 points to UTM.

    ``lat`` and ``lon`` in degrees (scalars or arrays of one shape). With ``zone=None`` every
    point goes to its own standard zone (with Norway's and Svalbard's exceptions); a zone
    such as ``"32N"`` forces all of them into it. Returns ``(easting, northing, zone)``:
    arrays shaped like the input (floats for scalars) and the zone as a string when it is
    one for all points, else an array of strings.

    >>> import numpy as np
    >>> e, n, z = forward(np.array([48.7224, -33.9]), np.array([7.3368, 18.4]))
    >>> z.tolist()
    ['32N', '34S']
    >>> e, n, z = forward([48.7224, 48.726], [7.3368, 7.3404], zone="31N")
    >>> z, bool(e[0] > 800_000)
    ('31N', True)
    """
    la, shape = shaped(lat, "lat")
    lo, shape_lon = shaped(lon, "lon")
    if shape != shape_lon:
        from ._terramesh import InputError

        raise InputError(f"lat and lon must have the same shape ({shape} and {shape_lon})")
    e, n, num, north = _core.utm_forward(la, lo, zone)
    if zone is not None:
        z = zone.strip().upper()
    else:
        names = np.char.add(num.astype(str), np.where(north, "N", "S"))
        uniq = np.unique(names)
        if len(uniq) == 1:
            z = str(uniq[0])
        elif shape == ():
            z = str(names[0])
        else:
            z = names.reshape(shape)
    return reshape(e, shape), reshape(n, shape), z


def inverse(easting: ArrayLike, northing: ArrayLike, zone: str):
    """UTM points of one ``zone`` (``"32N"``) back to WGS-84 ``(lat, lon)`` degrees.

    >>> lat, lon = inverse([377676.934248], [5397931.493907], "32N")
    >>> round(float(lat[0]), 7), round(float(lon[0]), 7)
    (48.7224, 7.3368)
    """
    e, shape = shaped(easting, "easting")
    n, _ = shaped(northing, "northing")
    lat, lon = _core.utm_inverse(e, n, zone)
    return reshape(lat, shape), reshape(lon, shape)


def parse_dms(text: str, axis: Optional[str] = None) -> float:
    """Decimal degrees of an angle in decimal or degrees-minutes-seconds form.

    Accepts ``48.7224``, ``N48°43'20.64"``, ``48 43 20.64 N``, ``7d20m12.48s E``,
    ``48:43:20.64``, ``48°43.344'N``; ``axis`` (``"lat"`` or ``"lon"``) checks the hemisphere
    letter and the range.

    >>> parse_dms("48 43 20.64 S")
    -48.7224
    >>> round(parse_dms("7d20m12.48s E", axis="lon"), 10)
    7.3368
    """
    return _core.parse_dms(text, axis)


def zone_of(lat: float, lon: float) -> str:
    """The standard UTM zone of a point.

    >>> zone_of(60.5, 5.0)  # Norway's exception: zone 32, not 31
    '32N'
    """
    return _core.zone_for(lat, lon)
