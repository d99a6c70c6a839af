"""The compiled Vincenty geodesics agree with geographiclib (the reference) on WGS-84."""

import pytest
from geographiclib.geodesic import Geodesic
from hypothesis import given, settings
from hypothesis import strategies as st

from fms_testbed.core.geodesy import direct, gravity_mps2, inverse

G = Geodesic.WGS84


def _angdiff(a, b):
    return abs((a - b + 180.0) % 360.0 - 180.0)


@settings(max_examples=300, deadline=None)
@given(lat1=st.floats(-85, 85), lon1=st.floats(-180, 180), az=st.floats(-180, 180),
       s=st.floats(0.0, 2_000_000.0))
def test_direct_and_inverse_agree_with_geographiclib(lat1, lon1, az, s):
    r = G.Direct(lat1, lon1, az, s)
    lat2, lon2, az2 = direct(lat1, lon1, az, s)
    assert G.Inverse(lat2, lon2, r["lat2"], r["lon2"])["s12"] < 1e-3
    assert _angdiff(az2, r["azi2"]) < 1e-7
    d, a1, a2 = inverse(lat1, lon1, r["lat2"], r["lon2"])
    assert d == pytest.approx(s, abs=1e-3)
    if s > 1.0:  # azimuth error x distance below a micrometre
        tol = max(1e-6, 1e-4 / s)
        assert _angdiff(a1, az) < tol and _angdiff(a2, r["azi2"]) < tol


def test_nearly_antipodal_points_fall_back_to_geographiclib():
    d, a1, _ = inverse(0.0, 0.0, 0.5, 179.7)
    assert d == pytest.approx(G.Inverse(0.0, 0.0, 0.5, 179.7)["s12"], abs=1e-6)


def test_normal_gravity_at_equator_and_pole():
    assert gravity_mps2(0.0) == pytest.approx(9.7803253359)
    assert gravity_mps2(90.0) == pytest.approx(9.8321849379, abs=1e-6)
