"""Velocity obstacles (Fiorini and Shiller 1998) with the COLREGs constraints of Kuwata et al. 2014.

Candidates are the scenario grid's commanded velocities (course = nominal + offset, speed =
multiplier x nominal speed). Against each target, with the relative motion a straight line:

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
from ship_guidance.cpa import cpa, disc_window, velocity


class VelocityObstacles(CollisionAvoidance):
    method = 'vo'

    def admissible(self, sc):
        """((S,) bool, (S,) s until the first target enters d_safe, inf if none does)."""
        p = self.params
        v_c = velocity(sc.chi_c, sc.u_c)[:, None, :]                            # (S, 1, 2)
        tcpa, _ = cpa(sc.p_own0, v_c, sc.p_tgt0[None], sc.v_tgt[None])          # (S, M)
        t_in, t_out = disc_window(sc.p_own0, v_c, sc.p_tgt0[None], sc.v_tgt[None], sc.d_safe)
        in_cone = (t_in < p.horizon_s) & (t_out > 0.0)
        los = sc.p_tgt0[None] - sc.p_own0                                       # (1, M, 2)
        w = v_c - sc.v_tgt[None]                                                # own relative velocity
        to_port = los[..., 0] * w[..., 1] - los[..., 1] * w[..., 0] < 0.0
        give_way = sc.threat & np.isin(sc.codes, (colregs.HEAD_ON, colregs.CROSSING_GIVE_WAY))
        widened = give_way[None] & to_port & (tcpa > 0.0) & (tcpa < p.horizon_s)
        first_entry = np.where(in_cone, np.maximum(t_in, 0.0), np.inf).min(axis=1)
        return ~(in_cone | widened).any(axis=1), first_entry

    def least_bad(self, sc):
        """((S,) s until the first target comes within ``collision_m`` on the straight lines, inf
        if none does within the horizon; (S,) m, the closest straight-line approach to any target
        within the horizon)."""
        p = self.params
        v_c = velocity(sc.chi_c, sc.u_c)[:, None, :]                            # (S, 1, 2)
        tcpa, _ = cpa(sc.p_own0, v_c, sc.p_tgt0[None], sc.v_tgt[None])          # (S, M)
        t_in, t_out = disc_window(sc.p_own0, v_c, sc.p_tgt0[None], sc.v_tgt[None], p.collision_m)
        hits = (t_in < p.horizon_s) & (t_out > 0.0)
        t_col = np.where(hits, np.maximum(t_in, 0.0), np.inf).min(axis=1)
        t_c = np.clip(tcpa, 0.0, p.horizon_s)[..., None]
        rel = sc.p_tgt0[None] + (sc.v_tgt[None] - v_c) * t_c - sc.p_own0        # (S, M, 2)
        return t_col, np.hypot(rel[..., 0], rel[..., 1]).min(axis=1)

    def _choose(self, sc):
        ok, _ = self.admissible(sc)
        cost = self.deviation_cost(sc) + self.port_turn_penalty(sc) + self.not_apparent_penalty(sc)
        if ok.any():
            k = int(np.argmin(np.where(ok, cost, np.inf)))
            return k, float(cost[k])
        t_col, clearance = self.least_bad(sc)
        return int(np.lexsort((cost, -clearance, -t_col))[0]), None
