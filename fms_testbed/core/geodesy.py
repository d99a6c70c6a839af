"""WGS-84 geodesy primitives shared by the path segments and the leg builder.

``inverse``/``direct`` solve the geodesic problems with Vincenty's formulae compiled by numba
(:mod:`.vincenty`, 0.5 µs a call against 37 µs for pure-Python geographiclib, measured) and fall
back to :mod:`geographiclib` (Karney 2013) where Vincenty does not converge (nearly antipodal
points); the two agree to 0.1 mm on procedure-sized problems (``tests/test_path_geodesy.py``).
A local azimuthal-equidistant frame serves the small planar constructions of the leg builder.
Angles are degrees (azimuths clockwise from true north), distances metres.
"""

from __future__ import annotations

import math

from geographiclib.geodesic import Geodesic

from fms_testbed.core.earth import normal_gravity_and_gradient
from fms_testbed.core.vincenty import vincenty_direct, vincenty_inverse

WGS84 = Geodesic.WGS84
_INV_MASK = Geodesic.DISTANCE | Geodesic.AZIMUTH
_DIR_MASK = Geodesic.LATITUDE | Geodesic.LONGITUDE | Geodesic.AZIMUTH


def inverse(lat1_deg: float, lon1_deg: float, lat2_deg: float, lon2_deg: float
            ) -> tuple[float, float, float]:
    """Geodesic inverse problem on WGS-84.

    Returns
    -------
    (s_m, az1_deg, az2_deg): distance, m; forward azimuth at point 1 and at point 2, deg true.
    """
    s, a1, a2, ok = vincenty_inverse(lat1_deg, lon1_deg, lat2_deg, lon2_deg)
    if ok:
        return s, a1, a2
    r = WGS84.Inverse(lat1_deg, lon1_deg, lat2_deg, lon2_deg, _INV_MASK)
    return r["s12"], r["azi1"], r["azi2"]


def direct(lat_deg: float, lon_deg: float, az_deg: float, s_m: float
           ) -> tuple[float, float, float]:
    """Geodesic direct problem on WGS-84.

    Returns
    -------
    (lat_deg, lon_deg, az2_deg): end point and forward azimuth there, deg.
    """
    lat, lon, az2, ok = vincenty_direct(lat_deg, lon_deg, az_deg, s_m)
    if ok:
        return lat, lon, az2
    r = WGS84.Direct(lat_deg, lon_deg, az_deg, s_m, _DIR_MASK)
    return r["lat2"], r["lon2"], r["azi2"]


def gravity_mps2(lat_deg: float, alt_m: float = 0.0) -> float:
    """Normal gravity of WGS-84, m/s², at geodetic latitude ``lat_deg`` (deg) and height ``alt_m``
    (m, default on the ellipsoid): :func:`fms_testbed.core.earth.normal_gravity_mps2` (TR8350.2
    eq. 4-1, 4-3) in the degree convention of this module."""
    # the kernel's Python body: one scalar call needs no compilation (or cache load) of numba
    return float(normal_gravity_and_gradient.py_func(math.radians(lat_deg), float(alt_m))[0])


def wrap180(a_deg: float) -> float:
    """Wrap an angle to (-180, 180], deg."""
    a = math.fmod(a_deg, 360.0)
    if a <= -180.0:
        a += 360.0
    elif a > 180.0:
        a -= 360.0
    return a


def wrap360(a_deg: float) -> float:
    """Wrap an angle to [0, 360), deg."""
    a = math.fmod(a_deg, 360.0)
    return a + 360.0 if a < 0 else a


class LocalFrame:
    """Azimuthal-equidistant plane about an origin (exact range/azimuth from the origin).

    ``x`` east, ``y`` north, metres. Accurate to centimetres within a few kilometres of the
    origin, which is where the leg builder uses it (turn tangents, intercepts).
    """

    __slots__ = ("lat_deg", "lon_deg")

    def __init__(self, lat_deg: float, lon_deg: float):
        self.lat_deg = lat_deg
        self.lon_deg = lon_deg

    def to_xy(self, lat_deg: float, lon_deg: float) -> tuple[float, float]:
        """Project a point to the plane, m."""
        s, az, _ = inverse(self.lat_deg, self.lon_deg, lat_deg, lon_deg)
        a = math.radians(az)
        return s * math.sin(a), s * math.cos(a)

    def to_latlon(self, x_m: float, y_m: float) -> tuple[float, float]:
        """Back from the plane to latitude/longitude, deg."""
        s = math.hypot(x_m, y_m)
        if s == 0.0:
            return self.lat_deg, self.lon_deg
        lat, lon, _ = direct(self.lat_deg, self.lon_deg, math.degrees(math.atan2(x_m, y_m)), s)
        return lat, lon
