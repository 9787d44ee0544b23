"""Latitude/longitude <-> local tangent plane (north, east) in metres, on the WGS-84 ellipsoid.

Route files may give waypoints as geodetic latitude/longitude with an origin; the planner and
guidance work in a flat local NED frame. pyproj is not a dependency, so the conversion is
written out here (standard geodesy, e.g. Hofmann-Wellenhof et al., "GNSS", 2008, sec. 5.6):

1. geodetic (lat, lon, h = 0) -> Earth-centred Earth-fixed (ECEF), WGS-84 a and f:
       N(lat) = a / sqrt(1 - e^2 sin^2 lat)        (prime-vertical radius of curvature)
       X = N cos(lat) cos(lon),  Y = N cos(lat) sin(lon),  Z = N (1 - e^2) sin(lat)
2. ECEF offset from the origin rotated into the origin's east/north/up axes:
       east  = -sin(lon0) dX + cos(lon0) dY
       north = -sin(lat0) cos(lon0) dX - sin(lat0) sin(lon0) dY + cos(lat0) dZ
   "up" is dropped: a point is projected orthogonally onto the tangent plane at the origin.

Accuracy: directions from the origin are kept; a distance s from the origin becomes about
R sin(s / R), shorter by s^3 / (6 R^2): 0.1 m at 30 km, 0.5 m at 50 km, 1 m at 62 km
(R ~ 6371 km). The map is therefore good to < 1 m within ~60 km of the origin, enough for
routes of tens of km; longer passages need a chain of origins or a real projection.

The inverse goes back along the origin's "up" direction to the ellipsoid surface (a quadratic
in the up offset) and reads latitude exactly from tan(lat) = Z / (p (1 - e^2)) for a point on
the ellipsoid. Both directions accept numpy arrays. Angles in degrees (human-facing data).
"""
import numpy as np

WGS84_A = 6378137.0                      # semi-major axis (m)
WGS84_F = 1.0 / 298.257223563            # flattening
WGS84_E2 = WGS84_F * (2.0 - WGS84_F)     # first eccentricity squared
WGS84_B = WGS84_A * (1.0 - WGS84_F)      # semi-minor axis (m)


def _ecef(lat, lon):
    """Geodetic (rad) on the ellipsoid surface (h = 0) -> ECEF (m)."""
    s = np.sin(lat)
    n = WGS84_A / np.sqrt(1.0 - WGS84_E2 * s * s)
    return (n * np.cos(lat) * np.cos(lon), n * np.cos(lat) * np.sin(lon), n * (1.0 - WGS84_E2) * s)


def _enu_axes(lat0, lon0):
    """Unit vectors east, north, up of the tangent plane at (lat0, lon0) (rad), in ECEF."""
    sl, cl = np.sin(lat0), np.cos(lat0)
    so, co = np.sin(lon0), np.cos(lon0)
    east = np.array([-so, co, 0.0])
    north = np.array([-sl * co, -sl * so, cl])
    up = np.array([cl * co, cl * so, sl])
    return east, north, up


def _check_origin(lat0_deg, lon0_deg):
    if not (np.isfinite(lat0_deg) and np.isfinite(lon0_deg)):
        raise ValueError(f'origin must be finite, got lat {lat0_deg}, lon {lon0_deg}')
    if abs(lat0_deg) >= 89.0:
        raise ValueError(f'origin latitude {lat0_deg} deg is too close to a pole for a local plane')


def geodetic_to_ned(lat_deg, lon_deg, lat0_deg, lon0_deg):
    """Latitude/longitude (deg) -> (north, east) metres in the tangent plane at the origin."""
    _check_origin(lat0_deg, lon0_deg)
    lat0, lon0 = np.radians(lat0_deg), np.radians(lon0_deg)
    x, y, z = _ecef(np.radians(lat_deg), np.radians(lon_deg))
    x0, y0, z0 = _ecef(lat0, lon0)
    e_ax, n_ax, _ = _enu_axes(lat0, lon0)
    dx, dy, dz = x - x0, y - y0, z - z0
    north = n_ax[0] * dx + n_ax[1] * dy + n_ax[2] * dz
    east = e_ax[0] * dx + e_ax[1] * dy
    return north, east


def ned_to_geodetic(north, east, lat0_deg, lon0_deg):
    """(north, east) metres in the tangent plane at the origin -> latitude/longitude (deg)."""
    _check_origin(lat0_deg, lon0_deg)
    lat0, lon0 = np.radians(lat0_deg), np.radians(lon0_deg)
    e_ax, n_ax, u_ax = _enu_axes(lat0, lon0)
    o = np.array(_ecef(lat0, lon0))
    north = np.asarray(north, dtype=float)
    east = np.asarray(east, dtype=float)
    p0 = o[:, None] * np.ones(north.size) + np.outer(e_ax, east.ravel()) + np.outer(n_ax, north.ravel())
    # Walk along -up to the surface: (p0 + u up)^T W (p0 + u up) = 1, W = diag(1/a^2, 1/a^2, 1/b^2).
    w = np.array([1.0 / WGS84_A**2, 1.0 / WGS84_A**2, 1.0 / WGS84_B**2])
    qa = np.sum(w * u_ax * u_ax)
    qb = np.sum(w[:, None] * p0 * u_ax[:, None], axis=0)
    qc = np.sum(w[:, None] * p0 * p0, axis=0) - 1.0
    disc = qb * qb - qa * qc
    if np.any(disc < 0.0):
        raise ValueError('point too far from the origin for the tangent-plane inverse')
    u = -qc / (qb + np.sqrt(disc))       # the root nearest the plane, written without cancellation
    p = p0 + u_ax[:, None] * u
    lon = np.arctan2(p[1], p[0])
    lat = np.arctan2(p[2], np.hypot(p[0], p[1]) * (1.0 - WGS84_E2))
    lat_deg, lon_deg = np.degrees(lat).reshape(north.shape), np.degrees(lon).reshape(north.shape)
    if north.ndim == 0:
        return float(lat_deg), float(lon_deg)
    return lat_deg, lon_deg
