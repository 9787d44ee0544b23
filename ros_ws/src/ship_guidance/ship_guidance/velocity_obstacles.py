"""Velocity obstacles (Fiorini and Shiller 1998) with the COLREGs constraints of Kuwata et al. 2014.

Candidates are the scenario grid's commanded velocities (course = nominal + offset, speed =
multiplier x nominal speed). Each is judged on the straight line of its course from the own
position, run at the speed the ship has on it: the commanded speed reached over the own-ship
model's speed time constant (``speed_response``). Fiorini and Shiller 1998 admit only velocities
the ship can reach; a ship with a shaft takes minutes to slow down, and judged at its commanded
speed a stop was admissible (it never meets a crosser) while the ship, still making way, ran
into the crosser's path (doc/results/failure_search.md). A course is taken as reached at once,
as in the velocity plane. Against each target, the target on its straight line:

- collision cone: a candidate is inadmissible when it brings the target within its d_safe (the
  cone of the target's disc inflated by the safe distance, widened by the target's position
  uncertainty: ColavParams.uncertainty_k) between now and the horizon;
- COLREGs (Kuwata et al. 2014): for a threat the own ship gives way to in head-on or crossing,
  the cone is widened to its port side: a closing candidate whose relative velocity points to
  port of the line of sight (it would pass with the target on its starboard side, i.e. cross
  ahead of it or pass starboard to starboard) is inadmissible too, so the choice passes astern
  / port to port.

The admissible candidate closest to the nominal is chosen (the deviation and change cost of
CollisionAvoidance, plus the port-turn penalty while a threat is head-on or crossing and SB-MPC's
Rule 8(b) penalty on a give-way alteration too small to be readily apparent: without it VO took
the smallest admissible 15 deg, marked not apparent in every single-target Imazu give-way case);
ties go to the fixed scenario order. With none admissible, the least bad (Fiorini and Shiller
1998 rank velocities inside the obstacles by their time to collision): the latest entry into a
target's collision disc (r_col, ``collision_m``) within the horizon, never being latest; among
equals the largest straight-line closest approach to any target within the horizon (the shallowest
intrusion into the cones); among equals the least cost. Ranking by the first entry into d_safe
instead (the choice before) is blind once the own ship is inside some target's d_safe: every
straight line then starts inside that cone, every entry time is 0, and the tie went to the
first scenario, the nominal, whatever it did to the other targets (Imazu cases 12, 13 and 17 on
the Mariner, doc/results/imazu.md). The shared last-resort check applies after either choice.
"""
import numpy as np

from ship_guidance import colregs
from ship_guidance.colav import CollisionAvoidance
from ship_guidance.cpa import cpa, velocity
from ship_guidance.own_ship_prediction import segment_min_distance, speed_response


class VelocityObstacles(CollisionAvoidance):
    method = 'vo'

    def _lines(self, sc):
        """((S, N+1, 2) own positions on each candidate's commanded course at its predicted
        straight-line speed (module doc), (S, M, N) m closest approach to each target on each
        prediction step)."""
        u = speed_response(sc.u[0, 0], sc.u_c, sc.t, self.ship)                  # (S, N+1)
        run = np.zeros_like(u)
        np.cumsum(0.5 * np.diff(sc.t) * (u[:, 1:] + u[:, :-1]), axis=1, out=run[:, 1:])
        own = np.empty(run.shape + (2,))   # x and y apart: a trailing axis of 2 broadcasts slowly
        own[..., 0] = sc.p_own0[0] + run * np.cos(sc.chi_c)[:, None]
        own[..., 1] = sc.p_own0[1] + run * np.sin(sc.chi_c)[:, None]
        return own, segment_min_distance(own, sc.p_tgt)[0]

    def _entry(self, sc, own, dist, radius):
        """(S, M) s until each target first comes within ``radius`` ((M,) m) of the ``own``
        positions (both moving linearly within a step) within the horizon, inf if it does
        not; 0 when already within it."""
        r = np.asarray(radius, float)[None, :]                                  # (1, M)
        inside = dist < r[..., None]                                            # (S, M, N)
        n = inside.argmax(axis=2)                                               # first step
        k, m = np.arange(dist.shape[0])[:, None], np.arange(dist.shape[1])[None, :]
        r0 = sc.p_tgt[m, n] - own[k, n]                                         # (S, M, 2)
        step = sc.p_tgt[m, n + 1] - sc.p_tgt[m, n] - (own[k, n + 1] - own[k, n])
        a = (step ** 2).sum(axis=-1)
        b = (r0 * step).sum(axis=-1)
        c = (r0 ** 2).sum(axis=-1) - r ** 2
        root = np.sqrt(np.maximum(b * b - a * c, 0.0))
        # the smaller root of a tau^2 + 2 b tau + c = 0; none needed when inside at the start
        into = np.where(c > 0.0, np.divide(-b - root, a, out=np.zeros_like(a), where=a > 0.0),
                        0.0)
        t = sc.t[n] + np.clip(into, 0.0, 1.0) * np.diff(sc.t)[n]
        return np.where(inside.any(axis=2), t, np.inf)

    def admissible(self, sc, lines=None):
        """((S,) bool, (S,) s until the first target enters d_safe, inf if none does);
        ``lines``: ``_lines(sc)`` if already made."""
        p = self.params
        own, dist = lines or self._lines(sc)
        t_in = self._entry(sc, own, dist, sc.d_safe)                             # (S, M)
        in_cone = np.isfinite(t_in)
        v_c = velocity(sc.chi_c, sc.u_c)[:, None, :]                            # (S, 1, 2)
        tcpa, _ = cpa(sc.p_own0, v_c, sc.p_tgt0[None], sc.v_tgt[None])          # (S, M)
        los = sc.p_tgt0[None] - sc.p_own0                                       # (1, M, 2)
        w = v_c - sc.v_tgt[None]                                                # own relative velocity
        to_port = los[..., 0] * w[..., 1] - los[..., 1] * w[..., 0] < 0.0
        give_way = sc.threat & np.isin(sc.codes, (colregs.HEAD_ON, colregs.CROSSING_GIVE_WAY))
        widened = give_way[None] & to_port & (tcpa > 0.0) & (tcpa < p.horizon_s)
        return ~(in_cone | widened).any(axis=1), t_in.min(axis=1)

    def least_bad(self, sc, lines=None):
        """((S,) s until the first target comes within ``collision_m`` on the lines, inf if none
        does within the horizon; (S,) m, the closest approach to any target on the lines within
        the horizon)."""
        own, dist = lines or self._lines(sc)
        t_col = self._entry(sc, own, dist, np.full(len(sc.p_tgt0), self.params.collision_m))
        return t_col.min(axis=1), dist.min(axis=(1, 2))

    def _choose(self, sc):
        lines = self._lines(sc)
        ok, _ = self.admissible(sc, lines)
        cost = self.deviation_cost(sc) + self.port_turn_penalty(sc) + self.not_apparent_penalty(sc)
        if ok.any():
            k = int(np.argmin(np.where(ok, cost, np.inf)))
            return k, float(cost[k])
        t_col, clearance = self.least_bad(sc, lines)
        return int(np.lexsort((cost, -clearance, -t_col))[0]), None
