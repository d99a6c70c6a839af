"""The Earth model against published WGS-84 values, geographiclib and the exact normal gravity."""

from __future__ import annotations

import math

import numpy as np
import pytest
from geographiclib.geodesic import Geodesic

from fms_testbed.core import earth
from fms_testbed.core.earth import (A_M, B_M, E2, FLATTENING, GM_M3PS2, OMEGA_IE_RPS, earth_rate_enu,
                                    normal_gravity_and_gradient, normal_gravity_mps2, radii_and_derivatives,
                                    radii_m, transport_rate_enu)

LATS_DEG = (0.0, 15.0, 30.0, 45.0, 60.0, 75.0, 89.9)


def exact_normal_gravity_mps2(lat_rad: float, h_m: float) -> float:
    """Magnitude of the normal gravity vector of the level ellipsoid, closed form in ellipsoidal
    harmonic coordinates (u, β) — Heiskanen & Moritz (1967) eq. 2-151, 2-152; Hofmann-Wellenhof &
    Moritz (2005) §2.8; NIMA TR8350.2 §4. Independent of the series in :mod:`earth`."""
    a, b, gm, w = A_M, B_M, GM_M3PS2, OMEGA_IE_RPS
    lin_e = math.sqrt(a * a - b * b)
    n = a / math.sqrt(1.0 - E2 * math.sin(lat_rad) ** 2)
    p = (n + h_m) * math.cos(lat_rad)
    z = (n * (1.0 - E2) + h_m) * math.sin(lat_rad)
    r2 = p * p + z * z
    u2 = 0.5 * (r2 - lin_e ** 2) * (1.0 + math.sqrt(1.0 + 4.0 * lin_e ** 2 * z * z / (r2 - lin_e ** 2) ** 2))
    u = math.sqrt(u2)
    beta = math.atan2(z * math.sqrt(u2 + lin_e ** 2), u * p)
    sb, cb = math.sin(beta), math.cos(beta)
    wf = math.sqrt((u2 + lin_e ** 2 * sb * sb) / (u2 + lin_e ** 2))
    q = 0.5 * ((1.0 + 3.0 * u2 / lin_e ** 2) * math.atan(lin_e / u) - 3.0 * u / lin_e)
    q0 = 0.5 * ((1.0 + 3.0 * b * b / lin_e ** 2) * math.atan(lin_e / b) - 3.0 * b / lin_e)
    qp = 3.0 * (1.0 + u2 / lin_e ** 2) * (1.0 - u / lin_e * math.atan(lin_e / u)) - 1.0
    v2 = u2 + lin_e ** 2
    g_u = -(gm / v2 + w * w * a * a * lin_e / v2 * qp / q0 * (0.5 * sb * sb - 1.0 / 6.0)
            - w * w * u * cb * cb) / wf
    g_b = (-w * w * a * a / math.sqrt(v2) * q / q0 + w * w * math.sqrt(v2)) * sb * cb / wf
    return math.hypot(g_u, g_b)


def test_defining_and_derived_constants_are_those_of_wgs84():
    # TR8350.2 Tables 3.1, 3.3, 3.4, 3.5; geographiclib's WGS-84 ellipsoid
    assert (A_M, FLATTENING) == (Geodesic.WGS84.a, Geodesic.WGS84.f)
    assert B_M == pytest.approx(6356752.3142, abs=1e-4)
    assert E2 == pytest.approx(6.69437999014e-3, rel=1e-12)
    assert earth.MEAN_RADIUS_M == pytest.approx(6371008.7714, abs=1e-4)
    assert earth.K_SOMIGLIANA == pytest.approx(
        B_M * earth.GAMMA_P_MPS2 / (A_M * earth.GAMMA_E_MPS2) - 1.0, abs=1e-11)
    assert earth.M_RATIO == pytest.approx(OMEGA_IE_RPS ** 2 * A_M ** 2 * B_M / GM_M3PS2, rel=1e-11)


def test_normal_gravity_on_the_ellipsoid_is_the_published_equator_and_pole_value():
    assert normal_gravity_mps2(0.0, 0.0) == pytest.approx(9.7803253359, abs=1e-10)
    assert normal_gravity_mps2(math.pi / 2, 0.0) == pytest.approx(9.8321849378, abs=1e-9)


@pytest.mark.parametrize("lat_deg", LATS_DEG)
def test_exact_formula_reproduces_somigliana_on_the_ellipsoid(lat_deg):
    # validates the independent oracle: at h = 0 both are the same field
    lat = math.radians(lat_deg)
    assert exact_normal_gravity_mps2(lat, 0.0) == pytest.approx(normal_gravity_mps2(lat, 0.0), abs=1e-10)


@pytest.mark.parametrize("lat_deg", LATS_DEG)
def test_height_term_matches_the_exact_normal_gravity_to_aircraft_heights(lat_deg):
    lat = math.radians(lat_deg)
    for h, tol in ((3000.0, 3e-7), (10000.0, 8e-7), (20000.0, 1.5e-6)):
        assert normal_gravity_mps2(lat, h) == pytest.approx(exact_normal_gravity_mps2(lat, h), abs=tol)


def test_second_order_series_beats_the_inverse_square_rule_it_replaced():
    # the SINS model used γ0 (a/(a+h))² before: 2e-4 m/s² (20 µg) off at 10 km on the equator
    lat, h = 0.0, 10000.0
    exact = exact_normal_gravity_mps2(lat, h)
    inverse_square = normal_gravity_mps2(lat, 0.0) * (A_M / (A_M + h)) ** 2
    assert abs(inverse_square - exact) > 1e-4
    assert abs(normal_gravity_mps2(lat, h) - exact) < abs(inverse_square - exact) / 100


def test_gravity_gradient_is_the_derivative_of_normal_gravity():
    for lat_deg in LATS_DEG[:-1]:
        for h in (0.0, 3000.0, 12000.0):
            lat = math.radians(lat_deg)
            g, dg_dlat, dg_dh = normal_gravity_and_gradient(lat, h)
            assert g == normal_gravity_mps2(lat, h)
            d = 1e-5
            num_lat = (normal_gravity_mps2(lat + d, h) - normal_gravity_mps2(lat - d, h)) / (2 * d)
            num_h = (normal_gravity_mps2(lat, h + 1.0) - normal_gravity_mps2(lat, h - 1.0)) / 2.0
            assert dg_dlat == pytest.approx(num_lat, rel=1e-6, abs=1e-12)
            assert dg_dh == pytest.approx(num_h, rel=1e-6)
            assert dg_dh == pytest.approx(-2.0 * g / A_M, rel=0.01)     # free-air gradient


@pytest.mark.parametrize("lat_deg", LATS_DEG)
def test_radii_of_curvature_agree_with_geographiclib_geodesics(lat_deg):
    geod = Geodesic.WGS84
    m, n = radii_m(math.radians(lat_deg))
    d = 1e-4                                             # deg
    # meridian: arc length per radian of latitude
    arc = geod.Inverse(lat_deg - d, 10.0, lat_deg + d, 10.0)["s12"]
    assert m == pytest.approx(arc / math.radians(2 * d), rel=1e-8)
    if lat_deg < 89.0:
        # prime vertical: a short east-west geodesic spans N cos φ Δλ
        ew = geod.Inverse(lat_deg, 10.0 - d, lat_deg, 10.0 + d)["s12"]
        assert n == pytest.approx(ew / (math.radians(2 * d) * math.cos(math.radians(lat_deg))), rel=1e-8)


def test_radii_derivatives_are_the_latitude_derivatives_of_the_radii():
    for lat in np.radians(LATS_DEG[:-1]):
        m, n, dm, dn = radii_and_derivatives(lat)
        assert (m, n) == radii_m(lat)
        (mp, np_), (mm, nm) = radii_m(lat + 1e-6), radii_m(lat - 1e-6)
        assert dm == pytest.approx((mp - mm) / 2e-6, rel=1e-6, abs=1e-3)
        assert dn == pytest.approx((np_ - nm) / 2e-6, rel=1e-6, abs=1e-3)


def test_functions_are_element_wise_on_arrays():
    lat = np.radians(np.array([[0.0, 20.0, 40.0], [55.0, 70.0, 85.0]]))
    h = np.array([[0.0, 1000.0, 5000.0], [9000.0, 12000.0, 300.0]])
    g = normal_gravity_mps2(lat, h)
    m, n = radii_m(lat)
    assert g.shape == m.shape == n.shape == lat.shape
    for i in np.ndindex(lat.shape):
        assert g[i] == normal_gravity_mps2(float(lat[i]), float(h[i]))
        assert (m[i], n[i]) == radii_m(float(lat[i]))


def test_earth_and_transport_rates_in_enu():
    lat = math.radians(47.0)
    w = earth_rate_enu(lat)
    assert w.shape == (3,) and w[0] == 0.0
    assert np.linalg.norm(w) == pytest.approx(OMEGA_IE_RPS, rel=1e-15)
    assert w[2] == pytest.approx(OMEGA_IE_RPS * math.sin(lat))
    m, n = radii_m(lat)
    h = 3000.0
    rho = transport_rate_enu(lat, h, [100.0, 50.0, 2.0])
    expected = [-50.0 / (m + h), 100.0 / (n + h), 100.0 * math.tan(lat) / (n + h)]
    assert rho == pytest.approx(expected, rel=1e-14)
    lats = np.radians([10.0, 47.0])
    v = np.array([[0.0, 200.0, 0.0], [100.0, 50.0, 2.0]])
    stack = transport_rate_enu(lats, h, v)
    assert stack.shape == (2, 3) and stack[1] == pytest.approx(rho, rel=1e-14)
    assert earth_rate_enu(lats).shape == (2, 3)
