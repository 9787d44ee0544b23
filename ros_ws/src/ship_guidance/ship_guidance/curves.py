"""Parametric reference curves made into routes: sine, circle, spline through points.

Source: Martinsen and Lekkas 2018, sec. II.A: a curved path is a parameterised curve
P_d(w) = [x_d(w), y_d(w)] in NED with path angle gamma_p = atan2(y_d'(w), x_d'(w)) (eq. 1);
the paper does not give its curves' formulas, so these are the usual test shapes. They serve
both the route files (ship_planner.route_yaml) and the learning environment
(ship_autopilot.learning.env), so they live here with the path they produce.

Sine and spline curves are sampled at (nearly) equal arc-length steps with their analytic
tangents and turned into a ship_guidance.path.Route of tangent arcs through the path's pose
encoding (Route.from_curve -> Route.from_poses). A circle is exact: it is built from Arc legs.
NED frame (x north, y east), metres, radians; psi = course of the tangent, clockwise from north.

Every curve is bounded before it is sampled (check_curve_size: ship_guidance.path
MAX_ROUTE_LENGTH_M, MAX_ROUTE_SAMPLES); a larger one raises ValueError saying which bound and
by how much.
"""
import numpy as np
from scipy.interpolate import CubicSpline

from ship_guidance.path import MAX_ROUTE_LENGTH_M, MAX_ROUTE_SAMPLES, Arc, Route

_DENSE = 16     # dense evaluations per output step when measuring arc length


def _resample_by_arc_length(points_fn, tangent_fn, w0, w1, step_m):
    """Evaluate a curve at parameters giving equal arc-length steps of at most step_m.

    points_fn(w) -> (north, east); tangent_fn(w) -> (dnorth/dw, deast/dw). Arc length is
    integrated on a dense grid (trapezoid rule on |dP/dw|) and inverted by interpolation.
    """
    if not np.isfinite(step_m) or step_m <= 0.0:
        raise ValueError(f'step_m must be a positive number of metres, got {step_m}')
    # A first pass fixes the dense grid size from a rough length.
    w = np.linspace(w0, w1, 257)
    dn, de = tangent_fn(w)
    rough = np.trapezoid(np.hypot(dn, de), w)
    _bounded(rough, step_m)
    n_dense = max(int(np.ceil(rough / step_m)) * _DENSE + 1, 257)
    w = np.linspace(w0, w1, n_dense)
    dn, de = tangent_fn(w)
    speed = np.hypot(dn, de)
    if np.any(speed <= 0.0):
        raise ValueError('the curve has a cusp (zero tangent); it cannot be a route')
    s = np.concatenate(([0.0], np.cumsum(0.5 * (speed[1:] + speed[:-1]) * np.diff(w))))
    _bounded(s[-1], step_m)     # the rough pass may miss short waves: check the true length too
    n_out = int(np.ceil(s[-1] / step_m)) + 1
    w_out = np.interp(np.linspace(0.0, s[-1], n_out), s, w)
    north, east = points_fn(w_out)
    tn, te = tangent_fn(w_out)
    return np.asarray(north, float), np.asarray(east, float), np.arctan2(te, tn)


def check_curve_size(length_m, step_m, what='the curve'):
    """None if a curve of about length_m sampled every step_m is within the bounds, else the
    refusal text; called before any sample is made."""
    if not length_m <= MAX_ROUTE_LENGTH_M:
        return f'{what} is {length_m:.4g} m long; at most {MAX_ROUTE_LENGTH_M:.0e} m is accepted'
    if step_m > 0.0 and not length_m / step_m <= MAX_ROUTE_SAMPLES:
        return (f'{what} would have {length_m / step_m:.4g} samples ({length_m:.4g} m every '
                f'{step_m:.4g} m); at most {MAX_ROUTE_SAMPLES} are accepted')
    return None


def _bounded(length_m, step_m, what='the curve'):
    bad = check_curve_size(float(length_m), float(step_m), what)
    if bad:
        raise ValueError(bad)


def sine_samples(length_m, amplitude_m, wavelength_m, step_m=10.0, start=(0.0, 0.0), course=0.0, phase=0.0):
    """Samples (north, east, psi) of a sine about a straight base line.

    The base line starts at start (north, east), runs along course (rad) for length_m; the
    curve is offset to starboard of it by amplitude_m sin(2 pi s / wavelength_m + phase),
    s the distance along the base line. Smallest radius of curvature: wavelength^2 / (4 pi^2 A).
    """
    for name, v in (('length_m', length_m), ('wavelength_m', wavelength_m)):
        if not np.isfinite(v) or v <= 0.0:
            raise ValueError(f'{name} must be a positive number of metres, got {v}')
    if not np.isfinite(amplitude_m):
        raise ValueError(f'amplitude_m must be finite, got {amplitude_m}')
    _bounded(length_m, step_m if np.isfinite(step_m) else 0.0, 'the base line')
    u = np.array([np.cos(course), np.sin(course)])
    n = np.array([-u[1], u[0]])              # starboard normal in NED
    k = 2.0 * np.pi / wavelength_m

    def points(s):
        off = amplitude_m * np.sin(k * s + phase)
        return start[0] + s * u[0] + off * n[0], start[1] + s * u[1] + off * n[1]

    def tangent(s):
        doff = amplitude_m * k * np.cos(k * s + phase)
        return u[0] + doff * n[0], u[1] + doff * n[1]

    return _resample_by_arc_length(points, tangent, 0.0, float(length_m), float(step_m))


def spline_samples(points, step_m=10.0, bc_type='natural'):
    """Samples (north, east, psi) of a cubic spline through points ((N, 2) north, east, N >= 2).

    The spline is parameterised by cumulative chord length (scipy CubicSpline, one per
    coordinate), which approximates arc length; the output is then resampled by true arc length.
    """
    pts = np.asarray(points, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 2 or len(pts) < 2:
        raise ValueError('a spline needs at least 2 points given as (north, east)')
    if not np.all(np.isfinite(pts)):
        raise ValueError('spline points must be finite')
    chord = np.hypot(*np.diff(pts, axis=0).T)
    if np.any(chord <= 0.0):
        i = int(np.argmin(chord))
        raise ValueError(f'spline points {i + 1} and {i + 2} coincide')
    w = np.concatenate(([0.0], np.cumsum(chord)))
    if len(pts) == 2:
        bc_type = 'not-a-knot'          # two points: scipy fits the straight line
    spline = CubicSpline(w, pts, bc_type=bc_type, axis=0)
    deriv = spline.derivative()

    def pos(x):
        p = spline(x)
        return p[..., 0], p[..., 1]

    def tan(x):
        d = deriv(x)
        return d[..., 0], d[..., 1]

    return _resample_by_arc_length(pos, tan, 0.0, float(w[-1]), float(step_m))


def circle_segments(center, radius_m, start_bearing, sweep, clockwise, max_piece=0.5 * np.pi):
    """An exact circular route as ship_guidance.path.Arc legs of at most max_piece (rad) each.

    center (north, east); the start point lies at bearing start_bearing (rad, clockwise from
    north) from the centre; the route sweeps `sweep` rad (> 0, may exceed 2 pi) clockwise
    (starboard turn) or counter-clockwise seen from above.
    """
    if not np.isfinite(radius_m) or radius_m <= 0.0:
        raise ValueError(f'radius_m must be a positive number of metres, got {radius_m}')
    if not np.isfinite(sweep) or sweep <= 0.0:
        raise ValueError(f'sweep must be a positive angle, got {sweep}')
    _bounded(radius_m * sweep, radius_m * max_piece, 'the circle')
    n_piece = int(np.ceil(sweep / max_piece - 1e-12))
    sign = 1.0 if clockwise else -1.0           # bearings grow clockwise in NED
    bearings = start_bearing + sign * np.linspace(0.0, sweep, n_piece + 1)
    c = (float(center[0]), float(center[1]))
    pts = [(c[0] + radius_m * np.cos(b), c[1] + radius_m * np.sin(b)) for b in bearings]
    return [Arc(pts[i], pts[i + 1], c, bool(clockwise)) for i in range(n_piece)]


def samples_to_route(north, east, psi):
    """Curve samples with their exact tangents -> ship_guidance.path.Route of tangent arcs.

    Route.from_curve decodes them like the nav_msgs/Path pose encoding (Route.from_poses): leg i
    leaves sample i along psi_i and passes through sample i + 1. Its deviation from a smooth
    curve is O(|dkappa/ds| h^3) for sample spacing h (path.py; tests/unit/test_curves.py bounds
    it for ship-sized curves).
    """
    return Route.from_curve(np.asarray(north, float), np.asarray(east, float), np.asarray(psi, float))


def sine_route(length_m, amplitude_m, wavelength_m, step_m=10.0, start=(0.0, 0.0), course=0.0, phase=0.0):
    """A sine curve (see sine_samples) as a Route."""
    return samples_to_route(*sine_samples(length_m, amplitude_m, wavelength_m, step_m, start, course, phase))


def spline_route(points, step_m=10.0, bc_type='natural'):
    """A cubic spline through points (see spline_samples) as a Route."""
    return samples_to_route(*spline_samples(points, step_m, bc_type))


def circle_route(center, radius_m, start_bearing, sweep, clockwise):
    """An exact circle or circular arc (see circle_segments) as a Route of Arc legs."""
    return Route(circle_segments(center, radius_m, start_bearing, sweep, clockwise))
