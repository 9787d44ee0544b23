"""Route-following guidance for N vessels on one route, stepped together as arrays (pure).

``BatchGuidance`` is ``guidance.Guidance`` (LOS / ILOS, optional turn-rate lead) for a batch:
each vessel's output equals what its own ``Guidance`` would give for the same positions, to
rounding (tested in tests/unit/test_batch_closed_loop.py). It keeps Guidance's rules (closest
point within a progress window, corners, acceptance circle, end normal, the ILOS integrator of
Borhaug et al. 2008, frozen once finished) and takes them from it where they are not per-step
work: the corner stretches and the first update (closest point of the whole route) come from a
template ``Guidance`` of the same route; the per-step closest-point search runs the route's
one kernel (``Route.closest_on_legs``) on a (vessels x candidate legs) table; switching at
corners is re-run only for the vessels that switched. The law is los.py's (``los_heading``'s
arithmetic, unwrapped until the lead is added, as Guidance does).

Per-vessel parameters may be arrays of length N or scalars: lookahead d (m), integral_gain
sigma (m/s, ILOS), lead (s; the turn-rate lead 2 zeta U / omega_n of Guidance, 0 for none),
window (m; default 2 d). Per batch: law, acceptance_radius (m), corner_angle (rad),
reset_integral_at_corners. Every update after the first runs compiled when ship_sim.kernels
selects numba (batch_guidance_compiled: the same steps per vessel). Units m, s, rad, NED.
Not covered: the course law and ``arc_los_point`` (use Guidance).
"""
import math
from dataclasses import dataclass

import numpy as np

from ship_sim import kernels
from ship_sim.frames import wrap_angle

from .batch_guidance_compiled import guidance_step, route_geometry
from .guidance import Guidance
from .path import Route

BATCH_LAWS = ('los', 'ilos')
#: Windows spanning at least this many legs are searched block by block (_closest_pruned).
FEW_COLUMNS = 8
#: Legs per block of the pruned search.
BLOCK = 16


@dataclass
class BatchGuidanceOutput:
    """One batch guidance step, arrays of length N (fields as guidance.GuidanceOutput)."""
    heading_cmd: np.ndarray
    cross_track: np.ndarray
    path_angle: np.ndarray
    curvature: np.ndarray
    s: np.ndarray
    leg_index: np.ndarray
    finished: np.ndarray
    integral: np.ndarray


def _per_vessel(name, value, n, positive=True, allow_zero=False):
    v = np.broadcast_to(np.asarray(value, dtype=float), (n,)).copy()
    bad = ~np.isfinite(v) | (v < 0.0) | ((v == 0.0) & (not allow_zero)) if positive else \
        ~np.isfinite(v)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        bound = '>= 0' if allow_zero else '> 0'
        raise ValueError(f'{name} must be finite and {bound}, got {v[i]!r} (vessel {i})')
    return v


class BatchGuidance:
    """LOS / ILOS guidance of N vessels on ``route`` (module docstring).

    ``update(north, east, dt)`` -> BatchGuidanceOutput; the first call (and the first after
    ``reset``) searches the whole route, as Guidance's does; ``dt`` (s) integrates ILOS.
    """

    def __init__(self, route, n, law='ilos', lookahead=100.0, *, integral_gain=0.5, lead=0.0,
                 window=None, acceptance_radius=0.0, corner_angle=math.radians(1.0),
                 reset_integral_at_corners=False):
        if not isinstance(route, Route):
            raise ValueError(f'route must be a ship_guidance.path.Route, got '
                             f'{type(route).__name__}')
        if law not in BATCH_LAWS:
            raise ValueError(f'law must be one of {BATCH_LAWS} for a batch, got {law!r}')
        self.n = n = int(n)
        self.route, self.law = route, law
        self.lookahead = _per_vessel('lookahead', lookahead, n)
        self.integral_gain = (_per_vessel('integral_gain', integral_gain, n) if law == 'ilos'
                              else np.zeros(n))
        self.lead = _per_vessel('lead', lead, n, positive=False)
        self.window = (2.0 * self.lookahead if window is None
                       else _per_vessel('window', window, n))
        self.reset_integral_at_corners = bool(reset_integral_at_corners)
        # The scalar guidance of this route: its stretches, and its first update.
        self.template = Guidance(route, 'los', 1.0, acceptance_radius,
                                 corner_angle=corner_angle)
        g = self.template
        self.acceptance_radius = g.acceptance_radius
        self._lo = np.array([b[0] for b in g._stretch_s])
        self._hi = np.array([b[1] for b in g._stretch_s])
        self._end_leg = np.array([e[0] for e in g._stretch_end], dtype=int)
        self._end_ne = np.array([e[1:] for e in g._stretch_end], dtype=float)
        self._n_stretch = len(self._lo)
        self._ends = route.cumulative[1:]
        self._starts = route.cumulative[:-1]
        self._n_legs = len(route.legs)
        # Bounding circles of blocks of BLOCK legs: every point of a block lies within half its
        # arc length of its middle point (along the path, so also in a straight line).
        first = np.arange(0, self._n_legs, BLOCK)
        s0 = route.cumulative[first]
        s1 = route.cumulative[np.minimum(first + BLOCK, self._n_legs)]
        mid_n, mid_e, _ = route.point_at(0.5 * (s0 + s1))
        self._block_mid = np.stack([np.atleast_1d(mid_n), np.atleast_1d(mid_e)], axis=1)
        self._block_radius = 0.5 * (s1 - s0) * (1.0 + 1e-9)
        mid_n, mid_e, _ = route.point_at(route.leg_starts + 0.5 * route.leg_lengths)
        self._leg_mid = np.stack([np.atleast_1d(mid_n), np.atleast_1d(mid_e)], axis=1)
        self._leg_radius = 0.5 * route.leg_lengths * (1.0 + 1e-9)
        self._geometry = None   # the compiled step's arrays (route_geometry), on first use
        self.reset()

    def reset(self):
        """Forget progress: the next update searches the whole route for every vessel."""
        n = self.n
        self.s = None
        self.k = np.zeros(n, dtype=int)
        self.prev = None
        self.integral = np.zeros(n)
        self.finished = np.zeros(n, dtype=bool)
        self._prev_owned = False

    # -- the closest point -------------------------------------------------------------------
    def _first_projection(self, north, east):
        """Guidance's first update: the closest point of the whole route. On a route of one
        smooth stretch that is all it does (and the end check), vectorised here with an upper
        bound from the legs' middle points; with corners, vessel by vessel as Guidance."""
        if self._n_stretch == 1:
            n = self.n
            zeros = np.zeros(n, dtype=int)
            lo, hi = np.zeros(n), np.full(n, self.route.length)
            upper = np.min(np.hypot(north[:, None] - self._block_mid[:, 0],
                                    east[:, None] - self._block_mid[:, 1]), axis=1)
            s, leg, fn, fe, gamma = self._closest_pruned(north, east, lo, hi, zeros,
                                                         zeros + self._n_legs - 1, upper)
            cross = -np.sin(gamma) * (north - fn) + np.cos(gamma) * (east - fe)
            self.k = zeros
            self.finished = self._reached_end(zeros, s, north, east)
            return s, leg, cross, gamma, self.route.curvatures[leg]
        g = self.template
        out = np.empty((6, self.n))
        for i, (pn, pe) in enumerate(zip(north.tolist(), east.tolist())):
            g.reset()
            o = g.update(pn, pe)
            out[:, i] = (o.s, o.leg_index, o.cross_track, o.path_angle, o.curvature, g._k)
            self.finished[i] = o.finished
        self.k = out[5].astype(int)
        return out[0], out[1].astype(int), out[2], out[3], out[4]

    def _project(self, pn, pe, hint, w, lo, hi):
        """Route.project(pn, pe, s_hint=hint, window=(w, w), bounds=(lo, hi)) per vessel:
        (s, leg, cross_track, path_angle, curvature) arrays."""
        route = self.route
        sh = np.minimum(np.maximum(hint, lo), hi)
        lo = np.maximum(lo, sh - w)
        hi = np.minimum(hi, sh + w)
        i0 = np.minimum(np.searchsorted(self._ends, lo, 'right'), self._n_legs - 1)
        span = np.maximum(np.searchsorted(self._starts, hi, 'left') - 1, i0) - i0
        if len(span) and span.max() >= FEW_COLUMNS:
            # Upper bound: the closest point of the leg at the hint.
            hint_leg = np.clip(np.searchsorted(self._ends, sh, 'right'), i0, i0 + span)
            c0 = route.cumulative[hint_leg]
            upper = route.closest_on_legs(hint_leg, pn, pe, lo - c0, hi - c0)[4]
            s, leg, fn, fe, gamma = self._closest_pruned(pn, pe, lo, hi, i0, i0 + span, upper)
        else:
            s, leg, fn, fe, gamma = self._closest_by_column(pn, pe, lo, hi, i0, span)
        cross = -np.sin(gamma) * (pn - fn) + np.cos(gamma) * (pe - fe)  # path.py, eq. 2
        return s, leg, cross, gamma, route.curvatures[leg]

    def _closest_by_column(self, pn, pe, lo, hi, i0, span):
        """The first candidate leg of every vessel, then the next ones only where a vessel's
        window reaches them; a later leg wins only if strictly closer (the first minimum, as
        Route.project)."""
        route = self.route
        c0 = route.cumulative[i0]
        t, fn, fe, gamma, dist = route.closest_on_legs(i0, pn, pe, lo - c0, hi - c0)
        s, leg = c0 + t, i0
        for j in range(1, int(span.max()) + 1 if len(span) else 1):
            rows = np.flatnonzero(span >= j)
            li = i0[rows] + j
            cj = route.cumulative[li]
            tj, fnj, fej, gj, dj = route.closest_on_legs(li, pn[rows], pe[rows],
                                                         lo[rows] - cj, hi[rows] - cj)
            b = dj < dist[rows]
            r = rows[b]
            if j == 1:
                leg = leg.copy()
            dist[r], s[r], leg[r] = dj[b], cj[b] + tj[b], li[b]
            fn[r], fe[r], gamma[r] = fnj[b], fej[b], gj[b]
        return s, leg, fn, fe, gamma

    def _closest_pruned(self, pn, pe, lo, hi, i0, i1, upper):
        """The same first minimum over legs i0..i1 for windows of many legs (dense curves),
        given an upper bound u on the distance (a point of the path): only blocks of BLOCK legs
        whose bounding circle (centre at the block's middle, radius half its arc length) comes
        within u (plus a rounding margin) can hold a point as close, then only their legs whose
        own bounding circle does, and only those are searched. Every leg that could tie or win
        is searched, so the result is the same."""
        route = self.route
        n = len(pn)
        upper = upper * (1.0 + 1e-9) + 1e-6
        b0, b1 = i0 // BLOCK, i1 // BLOCK
        nb = int((b1 - b0).max()) + 1
        blocks = np.minimum(b0[:, None] + np.arange(nb), b1[:, None])
        lower = (np.hypot(pn[:, None] - self._block_mid[blocks, 0],
                          pe[:, None] - self._block_mid[blocks, 1])
                 - self._block_radius[blocks])
        keep = lower <= upper[:, None]
        keep[:, 1:] &= blocks[:, 1:] != blocks[:, :-1]        # each block once
        v, col = np.nonzero(keep)                               # ordered by vessel, then block
        legs = blocks[v, col][:, None] * BLOCK + np.arange(BLOCK)
        ok = (legs >= i0[v, None]) & (legs <= i1[v, None])
        vf = np.broadcast_to(v[:, None], legs.shape)[ok]        # (vessel, leg) ascending
        lf = legs[ok]
        # The same test leg by leg (bounding circle of each leg) before the exact search.
        near = (np.hypot(pn[vf] - self._leg_mid[lf, 0], pe[vf] - self._leg_mid[lf, 1])
                - self._leg_radius[lf]) <= upper[vf]
        vf, lf = vf[near], lf[near]
        cf = route.cumulative[lf]
        t, fn, fe, gamma, dist = route.closest_on_legs(lf, pn[vf], pe[vf], lo[vf] - cf,
                                                       hi[vf] - cf)
        first = np.flatnonzero(np.r_[True, vf[1:] != vf[:-1]])
        best = np.minimum.reduceat(dist, first)
        hit = np.flatnonzero(dist == np.repeat(best, np.diff(np.r_[first, len(vf)])))
        pick = hit[np.r_[True, vf[hit][1:] != vf[hit][:-1]]]   # first minimum per vessel
        assert len(pick) == n
        return cf[pick] + t[pick], lf[pick], fn[pick], fe[pick], gamma[pick]

    def _reached_end(self, k, s, pn, pe):
        """Guidance._reached_end for vessels in stretches k at arc lengths s."""
        end_n, end_e = self._end_ne[k, 0], self._end_ne[k, 1]
        hi = self._hi[k]
        r_acc = self.acceptance_radius
        out = (np.hypot(pn - end_n, pe - end_e) <= r_acc) & (hi - s <= math.pi * r_acc)
        near = ~out & (s >= hi - self.route.s_tol)
        for i in np.flatnonzero(near).tolist():  # at the end of a stretch only (rare)
            leg = int(self._end_leg[k[i]])
            out[i] = self.route.along(leg, pn[i], pe[i]) >= self.route.leg_lengths[leg]
        return out

    # -- one step ----------------------------------------------------------------------------
    def update(self, north, east, dt=0.0):
        """One guidance step at NED positions (m, arrays of length N); dt (s) since the last."""
        pn = np.asarray(north, dtype=float)
        pe = np.asarray(east, dtype=float)
        if not (np.all(np.isfinite(pn)) and np.all(np.isfinite(pe))):
            raise ValueError('batch guidance update needs finite positions')
        if self.s is not None and kernels.compiled():
            return self._update_compiled(pn, pe, float(dt))
        self._prev_owned = False
        last = self._n_stretch - 1
        if self.s is None:
            s, leg, cross, gamma, kappa = self._first_projection(pn, pe)
        else:
            prev_n, prev_e = self.prev
            w = np.maximum(self.window, 3.0 * np.hypot(pn - prev_n, pe - prev_e))
            k = self.k
            s, leg, cross, gamma, kappa = self._project(pn, pe, self.s, w, self._lo[k],
                                                        self._hi[k])
            # Switch at corners: re-project only the vessels that reached a stretch's end.
            todo = np.flatnonzero(k < last)
            while len(todo):
                sw = todo[self._reached_end(k[todo], s[todo], pn[todo], pe[todo])]
                if not len(sw):
                    break
                k[sw] += 1
                if self.reset_integral_at_corners:
                    self.integral[sw] = 0.0
                lo, hi = self._lo[k[sw]], self._hi[k[sw]]
                s[sw], leg[sw], cross[sw], gamma[sw], kappa[sw] = self._project(
                    pn[sw], pe[sw], lo, w[sw], lo, hi)
                todo = sw[k[sw] < last]
            open_ = np.flatnonzero(~self.finished & (k == last))
            if len(open_):
                self.finished[open_] = self._reached_end(k[open_], s[open_], pn[open_],
                                                         pe[open_])
        self.s, self.prev = s, (pn, pe)
        d = self.lookahead
        if self.law == 'ilos':
            sigma, integral = self.integral_gain, self.integral
            y = cross + sigma * integral
            psi_c = gamma - np.arctan(y / d)
            rate = dt * d * cross / (y * y + d * d)
            self.integral = np.where(self.finished, integral, integral + rate)
        else:
            psi_c = gamma - np.arctan(cross / d)
        psi_c = wrap_angle(psi_c + self.lead * kappa)
        return BatchGuidanceOutput(psi_c, cross, gamma, kappa, s, leg, self.finished.copy(),
                                   self.integral.copy())

    def _update_compiled(self, pn, pe, dt):
        """``update`` after the first, compiled (batch_guidance_compiled; same steps per
        vessel). The state arrays are updated in place, so they are made this object's own."""
        if not self._prev_owned:
            self.prev = tuple(np.array(a, dtype=float) for a in self.prev)
            self.s = np.array(self.s, dtype=float)
            self.k = np.array(self.k, dtype=np.int64)
            self.integral = np.array(self.integral, dtype=float)
            self.finished = np.array(self.finished, dtype=np.bool_)
            self._prev_owned = True
        if self._geometry is None:
            self._geometry = route_geometry(self.route, self)
        n = self.n
        psi_c, cross, gamma, kappa = np.empty(n), np.empty(n), np.empty(n), np.empty(n)
        leg = np.empty(n, dtype=np.int64)
        guidance_step(*self._geometry, pn, pe, dt, self.law == 'ilos',
                      self.reset_integral_at_corners, self.lookahead, self.integral_gain,
                      self.lead, self.window, self.s, self.k, self.prev[0], self.prev[1],
                      self.integral, self.finished, psi_c, cross, gamma, kappa, leg)
        return BatchGuidanceOutput(psi_c, cross, gamma, kappa, self.s.copy(), leg,
                                   self.finished.copy(), self.integral.copy())
