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


def route_geometry(route, g):
    """The arrays of ``route`` and of BatchGuidance ``g`` the kernel reads (one tuple)."""
    sweep = np.array([getattr(leg, 'sweep', 0.0) for leg in route.legs], dtype=float)
    return (route._is_arc.astype(np.bool_), route._p0, route._unit, route._angle,
            route._center, route._radius, route._theta0, route._dir, sweep,
            np.asarray(route.leg_lengths, dtype=float), np.asarray(route.cumulative, dtype=float),
            np.asarray(route.curvatures, dtype=float), g._ends, g._starts, g._lo, g._hi,
            g._end_leg, g._end_ne, float(g.acceptance_radius), float(route.s_tol))


def _foot(geo, i, pn, pe, lo_local, hi_local):
    """Route.closest_on_legs for one leg i: (t, north, east, path angle, distance)."""
    (is_arc, p0, unit, angle, center, radius, theta0, dirn) = geo[:8]
    length = geo[9][i]
    ta = min(max(lo_local, 0.0), length)
    tb = min(max(hi_local, 0.0), length)
    if not is_arc[i]:
        t = min(max((pn - p0[i, 0]) * unit[i, 0] + (pe - p0[i, 1]) * unit[i, 1], ta), tb)
        fn, fe = p0[i, 0] + t * unit[i, 0], p0[i, 1] + t * unit[i, 1]
        return t, fn, fe, angle[i], math.hypot(fn - pn, fe - pe)
    rad, d = radius[i], dirn[i]
    phi = math.atan2(pe - center[i, 1], pn - center[i, 0])
    t_free = ((d * (phi - theta0[i])) % TWO_PI) * rad
    ga = abs(_wrap((ta - t_free) / rad))
    gb = abs(_wrap((tb - t_free) / rad))
    t = t_free if (t_free >= ta and t_free <= tb) else (ta if ga <= gb else tb)
    theta = theta0[i] + d * t / rad
    fn = center[i, 0] + rad * math.cos(theta)
    fe = center[i, 1] + rad * math.sin(theta)
    return t, fn, fe, _wrap(theta + d * HALF_PI), math.hypot(fn - pn, fe - pe)


def _project(geo, pn, pe, hint, w, lo, hi):
    """BatchGuidance._project for one vessel: (s, leg, cross, gamma, kappa)."""
    cumulative, curvatures, ends, starts = geo[10], geo[11], geo[12], geo[13]
    n_legs = ends.shape[0]
    sh = min(max(hint, lo), hi)
    lo = max(lo, sh - w)
    hi = min(hi, sh + w)
    i0 = min(np.searchsorted(ends, lo, side='right'), n_legs - 1)
    i1 = max(np.searchsorted(starts, hi, side='left') - 1, i0)
    c0 = cumulative[i0]
    t, fn, fe, gamma, dist = _foot(geo, i0, pn, pe, lo - c0, hi - c0)
    s, leg = c0 + t, i0
    for li in range(i0 + 1, i1 + 1):
        cj = cumulative[li]
        tj, fnj, fej, gj, dj = _foot(geo, li, pn, pe, lo - cj, hi - cj)
        if dj < dist:
            dist, s, leg, fn, fe, gamma = dj, cj + tj, li, fnj, fej, gj
    cross = -math.sin(gamma) * (pn - fn) + math.cos(gamma) * (pe - fe)
    return s, leg, cross, gamma, curvatures[leg]


def _along(geo, leg, pn, pe):
    """Route.along (Line.along / Arc.along) of one leg."""
    (is_arc, p0, unit, _, center, radius, theta0, dirn, sweep) = geo[:9]
    if not is_arc[leg]:
        return (pn - p0[leg, 0]) * unit[leg, 0] + (pe - p0[leg, 1]) * unit[leg, 1]
    phi = math.atan2(pe - center[leg, 1], pn - center[leg, 0])
    cut = math.pi - 0.5 * sweep[leg]
    rel = (dirn[leg] * (phi - theta0[leg]) + cut) % TWO_PI - cut
    return rel * radius[leg]


def _reached_end(geo, k, s, pn, pe):
    """BatchGuidance._reached_end for one vessel in stretch k."""
    leg_lengths, hi_all, end_leg, end_ne, r_acc, s_tol = (geo[9], geo[15], geo[16], geo[17],
                                                          geo[18], geo[19])
    hi = hi_all[k]
    if (math.hypot(pn - end_ne[k, 0], pe - end_ne[k, 1]) <= r_acc
            and hi - s <= math.pi * r_acc):
        return True
    if s >= hi - s_tol:
        leg = end_leg[k]
        return _along(geo, leg, pn, pe) >= leg_lengths[leg]
    return False


def _step(geo, north, east, dt, ilos, reset_at_corners, lookahead, sigma, lead, window,
          s, k, prev_n, prev_e, integral, finished, psi_c, cross, gamma, kappa, leg):
    """One update of every vessel; state arrays (s, k, prev_n, prev_e, integral, finished)
    are updated in place, the outputs written to the last five."""
    lo_all, hi_all = geo[14], geo[15]
    last = lo_all.shape[0] - 1
    for i in range(north.shape[0]):
        pn, pe = north[i], east[i]
        w = max(window[i], 3.0 * math.hypot(pn - prev_n[i], pe - prev_e[i]))
        ki = k[i]
        si, li, ci, gi, kai = _project(geo, pn, pe, s[i], w, lo_all[ki], hi_all[ki])
        while ki < last and _reached_end(geo, ki, si, pn, pe):
            ki += 1
            if reset_at_corners:
                integral[i] = 0.0
            lo = lo_all[ki]
            si, li, ci, gi, kai = _project(geo, pn, pe, lo, w, lo, hi_all[ki])
        if not finished[i] and ki == last:
            finished[i] = _reached_end(geo, ki, si, pn, pe)
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
    kernels.compile_globals(globals(), ['_wrap', '_foot', '_project', '_along', '_reached_end',
                                        '_step'], cache=True)
    return _step
