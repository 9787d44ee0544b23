"""Line-of-sight guidance laws (pure functions): LOS, integral LOS, and their stability limits.

Units: metres, seconds, radians; headings are NED (clockwise from north) and wrapped to
[-pi, pi) with ship_sim.frames.wrap_angle. Cross-track error e is positive when the vessel is
to STARBOARD of the path direction; alpha is the path angle (tangent heading) at the point the
error is measured from (a leg direction, or the closest point of a curve, see path.py).

LOS (Angelopoulos 2011 eq. 21, Simakis 1992 eq. 2.17 and 4.1; the point D at look-ahead distance d
on the path):
    psi_c = alpha - atan(e / d)

The same law serves every leg type because path.py supplies (alpha, e) for each:
- Straight legs: alpha = leg direction, e = offset from the (extended) line (Simakis 1992 eq. 4.1,
  y' = (y - y1) cos alpha - (x - x1) sin alpha in its axes).
- Circular arcs, both directions (Simakis 1992 Chapter IV.B): project the vessel radially onto the
  circle (Simakis 1992 eqs. 4.2-4.5: point 3 = O + R/A (V - O)); alpha = tangent heading at that
  point, e = signed radial offset direction * (R - A) (direction +1 for a clockwise/starboard arc
  whose centre is to starboard, -1 otherwise), then the same LOS law. atan2 gives the polar angle
  for every position around the centre, so no quadrant cases are needed: Simakis 1992 splits the
  clockwise and counter-clockwise motions into four quarters each only because it recovers the polar
  angle theta_3 with arcsin (valid on a half circle) and then re-derives the chord direction
  alpha and the target point 4 per quarter. In Simakis 1992 the vessel steers at point 4, an arc
  length d ahead of point 3 on the circle (Simakis 1992 eqs. 4.8-4.16). For small offsets both laws
  have the same cross-track gain 1/d; the chord to point 4 additionally leads the tangent by half
  the subtended angle, d / (2R), a built-in curvature feed-forward that our tangent-based law
  leaves out. With a PD heading autopilot (Angelopoulos 2011 eq. 16/20) the heading lags a turning
  command by 2 zeta r / omega_n, so plain LOS settles OUTSIDE a circle by (see ``pd_arc_offset``)
      |e| = d tan(2 zeta U / (omega_n (R + |e|)))
  in either direction; integral LOS removes that offset.
- Lee 2004 (Ch. 4, Fig. 4.6, eq. 4.24) does the same on its turning circles: the LOS point
  P_LOS lies on the circle an angle theta = d / R ahead of the vessel's bearing from the centre
  (``circle_los_point``) and the command is the bearing of P_LOS from the vessel; on the circle
  that is the tangent plus d / (2R).
- Curved paths: alpha and e of the closest point (Martinsen and Lekkas 2018 eqs. 1-3), see
  path.Route.project.

Integral LOS (Borhaug, Pavlov & Pettersen, "Integral LOS control for path following of
underactuated marine surface vessels in the presence of constant ocean currents", IEEE CDC 2008;
Fossen, Handbook of Marine Craft Hydrodynamics and Motion Control, 2011, Sec. 10.3.2;
Caharija et al., IEEE TCST 24(5), 2016):
    psi_c = alpha - atan((e + sigma e_int) / d)
    d(e_int)/dt = d e / ((e + sigma e_int)^2 + d^2)
e_int has units of seconds (for small e it is the time integral of e / d) and sigma is in m/s;
sigma e_int (m) is the offset the integrator holds. The denominator makes the integrator slow
down when far from the path (built-in anti-windup). Linearised with perfect heading tracking,
e'' + (U/d) e' + (U sigma / d^2) e = 0: damping ratio sqrt(U / (4 sigma)), critically damped at
sigma = U / 4.

Plain LOS in a steady cross current: with the current component V (m/s, positive pushing to
starboard of the path) and speed through the water U, the vessel must crab by asin(V/U) to hold
a line, and LOS only produces that heading offset from a cross-track error:
    atan(e / d) = asin(V / U)   =>   e_ss = d V / sqrt(U^2 - V^2)      (``los_current_offset``)
(the vessel sits downstream of the path). The same holds for any steady sideslip beta of the
hull with V / U replaced by sin(beta). ILOS converges to e = 0 with sigma e_int -> e_ss.

Stability limit (Angelopoulos 2011 eq. 33-34 and Simakis 1992 eq. 3.4-3.5): the PD autopilot (gains
from zeta, omega_n, Angelopoulos 2011 eq. 20) and LOS guidance on Nomoto's first-order model,
linearised,
    psi' = r,  r' = -omega_n^2 (psi + y / d) - 2 zeta omega_n r,  y' = U psi,
has the characteristic equation s^3 + 2 zeta omega_n s^2 + omega_n^2 s + omega_n^2 U / d = 0 and
Routh's criterion gives
    d > U / (2 zeta omega_n)                                            (dimensional, m)
Both theses write d > 1 / (2 zeta omega_n) because their equations are non-dimensional in ship
length L and time L/U (Angelopoulos 2011 eq. 8: y' = sin psi): there d is in ship lengths and
omega_n in units of U/L. The two agree: d/L > 1 / (2 zeta omega_n L / U)  <=>  d > U / (2 zeta
omega_n); in time units the look-ahead must exceed 1 / (2 zeta omega_n) seconds of travel. With the
ILOS integrator (linearised: e_int' = y / d, psi_c = -(y + sigma e_int)/d) the characteristic
polynomial becomes s^4 + 2 zeta omega_n s^3 + omega_n^2 s^2 + (omega_n^2 U / d) s + omega_n^2 U
sigma / d^2 and the Routh-Hurwitz condition a1 a2 a3 > a3^2 + a1^2 a4 gives (our derivation, tested
numerically)
    d > (U + 4 zeta^2 sigma) / (2 zeta omega_n).
"""
import math

import numpy as np

from ship_sim.frames import wrap_angle


def los_heading(path_angle, cross_track, lookahead):
    """LOS heading command (rad, NED, wrapped): alpha - atan(e / d). Works on arrays."""
    return wrap_angle(path_angle - np.arctan(cross_track / lookahead))


def ilos_heading(path_angle, cross_track, integral, lookahead, sigma):
    """Integral-LOS heading command (rad): alpha - atan((e + sigma e_int) / d)."""
    return wrap_angle(path_angle - np.arctan((cross_track + sigma * integral) / lookahead))


def ilos_integral_rate(cross_track, integral, lookahead, sigma):
    """d(e_int)/dt = d e / ((e + sigma e_int)^2 + d^2) (Borhaug et al. 2008); dimensionless, so
    e_int is in seconds."""
    return lookahead * cross_track / ((cross_track + sigma * integral) ** 2 + lookahead ** 2)


def ship_lengths_to_metres(n_lengths, ship_length):
    """Distance in ship lengths (as Lee 2004 gives look-ahead and acceptance radius) -> m."""
    return float(n_lengths) * float(ship_length)


def critical_lookahead(zeta, omega_n, speed, sigma=0.0):
    """Smallest stable look-ahead (m) for the PD autopilot (zeta, omega_n in rad/s) at speed U
    (m/s): U / (2 zeta omega_n) for LOS (Angelopoulos 2011 eq. 34 in dimensional form); with
    ILOS gain sigma (m/s): (U + 4 zeta^2 sigma) / (2 zeta omega_n). The loop is stable for d
    strictly above. Broadcasting: scalars give a float, arrays an array (the platoon check and
    the Table 1 reproduction of string_stability use the same function)."""
    z, w, u, s = (np.asarray(v, dtype=float) for v in (zeta, omega_n, speed, sigma))
    if not np.all((z > 0.0) & (w > 0.0) & (u > 0.0) & (s >= 0.0)
                  & np.isfinite(z) & np.isfinite(w) & np.isfinite(u) & np.isfinite(s)):
        raise ValueError(f'critical_lookahead needs zeta > 0, omega_n > 0, speed > 0, sigma >= 0; '
                         f'got zeta={zeta}, omega_n={omega_n}, speed={speed}, sigma={sigma}')
    d = (u + 4.0 * z ** 2 * s) / (2.0 * z * w)
    return float(d) if d.ndim == 0 else d


def critical_lookahead_nondim(zeta, omega_n_nd):
    """The theses' form (Angelopoulos 2011 eq. 34, Simakis 1992 eq. 3.5): d* = 1 / (2 zeta omega_n)
    in ship lengths, with omega_n non-dimensional (units of U/L)."""
    return critical_lookahead(zeta, omega_n_nd, 1.0)


def omega_n_from_nondim(omega_n_nd, speed, ship_length):
    """Non-dimensional natural frequency (units of U/L, as in Angelopoulos 2011 and Simakis
    1992) -> rad/s."""
    return float(omega_n_nd) * float(speed) / float(ship_length)


def linear_loop_matrix(zeta, omega_n, speed, lookahead, sigma=None):
    """System matrix of the linearised autopilot + (I)LOS loop about a straight path.

    State (psi - alpha, r, e) for LOS (Angelopoulos 2011 eq. 30 in dimensional form) and (psi -
    alpha, r, e, e_int) for ILOS when ``sigma`` is given. Its eigenvalues decide local stability."""
    w2, c, d, u = omega_n ** 2, 2.0 * zeta * omega_n, lookahead, speed
    if sigma is None:
        return np.array([[0.0, 1.0, 0.0],
                         [-w2, -c, -w2 / d],
                         [u, 0.0, 0.0]])
    return np.array([[0.0, 1.0, 0.0, 0.0],
                     [-w2, -c, -w2 / d, -w2 * sigma / d],
                     [u, 0.0, 0.0, 0.0],
                     [0.0, 0.0, 1.0 / d, 0.0]])


def circle_los_point(center, radius, clockwise, north, east, lookahead):
    """Lee 2004 eq. 4.24: the LOS point on a turning circle (NED, m).

    The vessel at (north, east) has bearing phi from the centre; the LOS point lies on the
    circle at phi + theta (clockwise turn) or phi - theta, theta = lookahead / radius, so it
    runs ahead of the vessel by one look-ahead of arc. Returns (north, east) of that point.
    """
    r = float(radius)
    if not np.isfinite(r) or r <= 0.0 or not np.isfinite(lookahead) or lookahead <= 0.0:
        raise ValueError(f'radius and lookahead must be positive finite metres, got {radius}, {lookahead}')
    phi = math.atan2(east - center[1], north - center[0])
    theta = float(lookahead) / r
    a = phi + (theta if clockwise else -theta)
    return (center[0] + r * math.cos(a), center[1] + r * math.sin(a))


def los_current_offset(lookahead, cross_current, speed):
    """Steady cross-track error (m) of plain LOS on a straight line in a constant current whose
    component across the path is ``cross_current`` (m/s, positive to starboard), at speed
    through the water ``speed`` (m/s): d V / sqrt(U^2 - V^2). Positive = downstream."""
    v, u = float(cross_current), float(speed)
    if not abs(v) < u:
        raise ValueError(f'a cross current of {v} m/s cannot be compensated at {u} m/s')
    return float(lookahead) * v / math.sqrt(u * u - v * v)


def pd_arc_offset(lookahead, radius, speed, zeta, omega_n, iterations=50):
    """Steady |cross-track error| (m) of plain LOS on a circle of ``radius`` with the PD heading
    autopilot of Angelopoulos 2011 and Simakis 1992 on a Nomoto model (no sideslip, rudder not
    saturated): the heading lags the command by 2 zeta r / omega_n with r = U / (R + |e|), the
    vessel runs outside the circle, and |e| = d tan(2 zeta U / (omega_n (R + |e|))) (fixed
    point)."""
    e = 0.0
    for _ in range(iterations):
        e = lookahead * math.tan(2.0 * zeta * speed / (omega_n * (radius + e)))
    return e
