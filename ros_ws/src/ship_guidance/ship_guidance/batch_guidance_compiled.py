"""Compiled step of BatchGuidance (ship_sim.kernels selects it): every update after the first.

Per vessel, in order, what ``BatchGuidance.update`` does on arrays: the search window, the
closest point on the stretch (``Route.closest_on_legs``' arithmetic for lines and arcs, legs
in ascending order, a later leg winning only if strictly closer: the first minimum that both
the column search and the pruned block search of the array path return), the corner switches
with their re-projections, the end test of the last stretch (``_reached_end``, with
``Line.along`` / ``Arc.along`` at a stretch's end normal), then the LOS / ILOS law and the
turn-rate lead (los.py's arithmetic as batch_guidance.py writes it). Angles are wrapped by
frames.wrap_angle itself, compiled. The first update (the whole route) stays on the array
path.

``geometry`` is the tuple ``route_geometry(route, guidance)`` builds once per BatchGuidance.
"""
import math

import numpy as np

from ship_sim import kernels
from ship_sim.frames import wrap_angle

from .path import HALF_PI, TWO_PI

_wrap = wrap_angle

# Columns of the leg table (route_geometry): one float row per leg, so the loop passes one
# array to its helpers (a tuple of arrays is reference-counted array by array at every call).
(IS_ARC, P0N, P0E, UN, UE, ANGLE, CN, CE, RADIUS, THETA0, DIR, SWEEP, LENGTH, START, END,
 CURVATURE, MID_N, MID_E, MID_RADIUS) = range(19)
# Columns of the stretch table: arc-length bounds, last leg and end point of each stretch.
(LO, HI, END_LEG, END_N, END_E) = range(5)


def route_geometry(route, g):
    """(leg table, stretch table, acceptance radius, s_tol) of ``route`` and BatchGuidance
    ``g``, the arrays the kernel reads."""
    legs = np.zeros((len(route.legs), 19))
    legs[:, IS_ARC] = route._is_arc
    legs[:, [P0N, P0E]] = route._p0
    legs[:, [UN, UE]] = route._unit
    legs[:, ANGLE] = route._angle
    legs[:, [CN, CE]] = route._center
    legs[:, RADIUS] = route._radius
    legs[:, THETA0] = route._theta0
    legs[:, DIR] = route._dir
    legs[:, SWEEP] = [getattr(leg, 'sweep', 0.0) for leg in route.legs]
    legs[:, LENGTH] = route.leg_lengths
    legs[:, START] = route.cumulative[:-1]
    legs[:, END] = route.cumulative[1:]
    legs[:, CURVATURE] = route.curvatures
    legs[:, [MID_N, MID_E]] = g._leg_mid
    legs[:, MID_RADIUS] = g._leg_radius
    stretches = np.zeros((len(g._lo), 5))
    stretches[:, LO], stretches[:, HI], stretches[:, END_LEG] = g._lo, g._hi, g._end_leg
    stretches[:, [END_N, END_E]] = g._end_ne
    return legs, stretches, float(g.acceptance_radius), float(route.s_tol)


def _foot(legs, i, pn, pe, lo_local, hi_local):
    """Route.closest_on_legs for one leg i: (t, north, east, path angle, distance)."""
    length = legs[i, LENGTH]
    ta = min(max(lo_local, 0.0), length)
    tb = min(max(hi_local, 0.0), length)
    if legs[i, IS_ARC] == 0.0:
        p0n, p0e, un, ue = legs[i, P0N], legs[i, P0E], legs[i, UN], legs[i, UE]
        t = min(max((pn - p0n) * un + (pe - p0e) * ue, ta), tb)
        fn, fe = p0n + t * un, p0e + t * ue
        return t, fn, fe, legs[i, ANGLE], math.hypot(fn - pn, fe - pe)
    rad, d, cn, ce, theta0 = (legs[i, RADIUS], legs[i, DIR], legs[i, CN], legs[i, CE],
                              legs[i, THETA0])
    phi = math.atan2(pe - ce, pn - cn)
    t_free = ((d * (phi - theta0)) % TWO_PI) * rad
    ga = abs(_wrap((ta - t_free) / rad))
    gb = abs(_wrap((tb - t_free) / rad))
    t = t_free if (t_free >= ta and t_free <= tb) else (ta if ga <= gb else tb)
    theta = theta0 + d * t / rad
    fn = cn + rad * math.cos(theta)
    fe = ce + rad * math.sin(theta)
    return t, fn, fe, _wrap(theta + d * HALF_PI), math.hypot(fn - pn, fe - pe)


def _count_below(legs, col, v, inclusive):
    """np.searchsorted(legs[:, col], v, 'right' if inclusive else 'left') on a sorted column:
    how many rows are <= v (< v); a bisection, no array made for the scalar."""
    lo, hi = 0, legs.shape[0]
    while lo < hi:
        mid = (lo + hi) // 2
        a = legs[mid, col]
        if a < v or (inclusive and a == v):
            lo = mid + 1
        else:
            hi = mid
    return lo


def _project(legs, pn, pe, hint, w, lo, hi):
    """BatchGuidance._project for one vessel: (s, leg, cross, gamma, kappa)."""
    n_legs = legs.shape[0]
    sh = min(max(hint, lo), hi)
    lo = max(lo, sh - w)
    hi = min(hi, sh + w)
    i0 = min(_count_below(legs, END, lo, True), n_legs - 1)
    i1 = max(_count_below(legs, START, hi, False) - 1, i0)
    # The leg at the hint first (usually the closest), then the others only where their
    # bounding circle (BatchGuidance._leg_mid, _leg_radius) could hold a point as close; the
    # tie rule (lowest leg index among equal distances) is that of an ascending search.
    hint_leg = min(max(_count_below(legs, END, sh, True), i0), i1)
    leg = hint_leg
    c0 = legs[leg, START]
    t, fn, fe, gamma, dist = _foot(legs, leg, pn, pe, lo - c0, hi - c0)
    s = c0 + t
    for li in range(i0, i1 + 1):
        if li == hint_leg:
            continue
        lower = math.hypot(pn - legs[li, MID_N], pe - legs[li, MID_E]) - legs[li, MID_RADIUS]
        if lower > dist * (1.0 + 1e-9) + 1e-6:
            continue
        cj = legs[li, START]
        tj, fnj, fej, gj, dj = _foot(legs, li, pn, pe, lo - cj, hi - cj)
        if dj < dist or (dj == dist and li < leg):
            dist, s, leg, fn, fe, gamma = dj, cj + tj, li, fnj, fej, gj
    cross = -math.sin(gamma) * (pn - fn) + math.cos(gamma) * (pe - fe)
    return s, leg, cross, gamma, legs[leg, CURVATURE]


def _along(legs, leg, pn, pe):
    """Route.along (Line.along / Arc.along) of one leg."""
    if legs[leg, IS_ARC] == 0.0:
        return (pn - legs[leg, P0N]) * legs[leg, UN] + (pe - legs[leg, P0E]) * legs[leg, UE]
    phi = math.atan2(pe - legs[leg, CE], pn - legs[leg, CN])
    cut = math.pi - 0.5 * legs[leg, SWEEP]
    rel = (legs[leg, DIR] * (phi - legs[leg, THETA0]) + cut) % TWO_PI - cut
    return rel * legs[leg, RADIUS]


def _reached_end(legs, stretches, r_acc, s_tol, k, s, pn, pe):
    """BatchGuidance._reached_end for one vessel in stretch k."""
    hi = stretches[k, HI]
    if (math.hypot(pn - stretches[k, END_N], pe - stretches[k, END_E]) <= r_acc
            and hi - s <= math.pi * r_acc):
        return True
    if s >= hi - s_tol:
        leg = int(stretches[k, END_LEG])
        return _along(legs, leg, pn, pe) >= legs[leg, LENGTH]
    return False


def _step(legs, stretches, r_acc, s_tol, north, east, dt, ilos, reset_at_corners, lookahead,
          sigma, lead, window, s, k, prev_n, prev_e, integral, finished, psi_c, cross, gamma,
          kappa, leg):
    """One update of every vessel; state arrays (s, k, prev_n, prev_e, integral, finished)
    are updated in place, the outputs written to the last five."""
    last = stretches.shape[0] - 1
    for i in range(north.shape[0]):
        pn, pe = north[i], east[i]
        w = max(window[i], 3.0 * math.hypot(pn - prev_n[i], pe - prev_e[i]))
        ki = k[i]
        si, li, ci, gi, kai = _project(legs, pn, pe, s[i], w, stretches[ki, LO],
                                       stretches[ki, HI])
        while ki < last and _reached_end(legs, stretches, r_acc, s_tol, ki, si, pn, pe):
            ki += 1
            if reset_at_corners:
                integral[i] = 0.0
            lo = stretches[ki, LO]
            si, li, ci, gi, kai = _project(legs, pn, pe, lo, w, lo, stretches[ki, HI])
        if not finished[i] and ki == last:
            finished[i] = _reached_end(legs, stretches, r_acc, s_tol, ki, si, pn, pe)
        k[i], s[i], prev_n[i], prev_e[i] = ki, si, pn, pe
        d = lookahead[i]
        if ilos:
            y = ci + sigma[i] * integral[i]
            p = gi - math.atan(y / d)
            rate = dt * d * ci / (y * y + d * d)
            if not finished[i]:
                integral[i] = integral[i] + rate
        else:
            p = gi - math.atan(ci / d)
        psi_c[i] = _wrap(p + lead[i] * kai)
        cross[i], gamma[i], kappa[i], leg[i] = ci, gi, kai, li


@kernels.lazy
def guidance_step():
    kernels.compile_globals(globals(), ['_wrap', '_foot', '_count_below', '_project', '_along',
                                        '_reached_end'], cache=True, inline='always')
    kernels.compile_globals(globals(), ['_step'], cache=True)
    return _step
