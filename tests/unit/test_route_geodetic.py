"""Tangent-plane conversion (ship_sim.geodetic) against independent WGS-84 geodesy."""
import math

import numpy as np
import pytest
from scipy.integrate import quad

from ship_sim.geodetic import WGS84_A, WGS84_E2, geodetic_to_ned, ned_to_geodetic


def meridian_radius(lat):
    """Meridian radius of curvature M(lat) (textbook formula)."""
    return WGS84_A * (1.0 - WGS84_E2) / (1.0 - WGS84_E2 * math.sin(lat) ** 2) ** 1.5


def meridian_arc(lat0_deg, lat1_deg):
    """Length (m) of the meridian between two latitudes, by numerical integration of M."""
    return quad(meridian_radius, math.radians(lat0_deg), math.radians(lat1_deg), epsabs=1e-6)[0]


@pytest.mark.parametrize('lat0', [0.0, 45.0, 63.4, -33.9])
def test_small_offsets_follow_the_radii_of_curvature(lat0):
    d = 1e-4   # deg: ~11 m, where plane and ellipsoid agree to far below a millimetre
    north, east = geodetic_to_ned(lat0 + d, 10.0, lat0, 10.0)
    assert north == pytest.approx(meridian_radius(math.radians(lat0)) * math.radians(d), rel=1e-5)
    assert abs(east) < 1e-6
    north, east = geodetic_to_ned(lat0, 10.0 + d, lat0, 10.0)
    n_prime = WGS84_A / math.sqrt(1.0 - WGS84_E2 * math.sin(math.radians(lat0)) ** 2)
    assert east == pytest.approx(n_prime * math.cos(math.radians(lat0)) * math.radians(d), rel=1e-5)
    assert abs(north) < 1e-3


@pytest.mark.parametrize('lat0', [10.0, 60.0])
def test_distance_along_a_meridian_is_kept_to_a_metre_within_tens_of_km(lat0):
    # 0.45 deg of latitude is ~50 km: the documented error s^3 / (6 R^2) is ~0.5 m there.
    s = meridian_arc(lat0, lat0 + 0.45)
    north, east = geodetic_to_ned(lat0 + 0.45, 5.0, lat0, 5.0)
    assert abs(east) < 1e-6
    assert 0.0 < s - north < 1.0
    # ... and the documented limit is real: at ~150 km the plane is off by much more than 1 m.
    s = meridian_arc(lat0, lat0 + 1.35)
    north, _ = geodetic_to_ned(lat0 + 1.35, 5.0, lat0, 5.0)
    assert s - north > 5.0


def test_inverse_returns_the_input():
    lat = np.array([58.0, 58.2, 57.8, 58.1])
    lon = np.array([9.0, 9.3, 8.6, 9.0])
    north, east = geodetic_to_ned(lat, lon, 58.0, 9.0)
    lat2, lon2 = ned_to_geodetic(north, east, 58.0, 9.0)
    assert np.max(np.abs(lat2 - lat)) < 1e-10
    assert np.max(np.abs(lon2 - lon)) < 1e-10
    la, lo = ned_to_geodetic(1000.0, -2000.0, -20.0, 150.0)
    assert isinstance(la, float)
    n, e = geodetic_to_ned(la, lo, -20.0, 150.0)
    assert (n, e) == (pytest.approx(1000.0, abs=1e-6), pytest.approx(-2000.0, abs=1e-6))


def test_origin_near_a_pole_is_refused():
    with pytest.raises(ValueError, match='pole'):
        geodetic_to_ned(89.5, 0.0, 89.5, 0.0)
