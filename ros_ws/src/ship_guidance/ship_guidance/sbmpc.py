"""Scenario-based MPC collision avoidance (Johansen, Perez and Cristofaro 2016), vectorised.

Each scenario k (course offset x speed multiplier, held over the horizon) is predicted with the
own-ship model and scored, all scenarios x targets x steps at once:

    H_k = max_i [ max_t R_ik(t) + kappa mu_ik ] + G_k + port_k + apparent_k + f_k + change_k

- collision risk R (Johansen et al. 2016's C R): on every step where the predicted distance d to
  target i is below its d_safe (d_safe_m, widened by ``uncertainty_k`` times the target's
  position sigma: ColavParams), w_collision (|v_rel| / U)^2 (T_h / t)^p (d_safe / d)^q, with |v_rel|
  the relative speed on that step (floored at ``relative_speed_floor`` U, so a slow overtaking
  still costs), U the nominal speed, t the time of the closest point on the step (at least one
  step) and T_h the horizon;
- beyond the horizon: the same R at the straight-line closest approach (ship_guidance.cpa) of
  the own ship continuing with its velocity at the horizon's end (the scenario's course and
  speed, held) and the target on its line, if it falls within a second horizon (t <= 2 T_h).
  A scenario is a command held, and a meeting just past the horizon is still its consequence:
  without this term a slow-closing pair of beam crossers (Imazu 19, 21: 1.6 m/s closing, all
  ships meeting at 1200 s) looked safe with the 600 s horizon on a straight course and a slow
  turner (the MSS tanker) held it until the meeting entered the horizon and no turn could clear
  it. Beyond 2 T_h the targets' straight lines are not trusted;
- the risk every scenario shares is taken off: per target and step (and beyond the horizon)
  the smallest R over the scenarios. It is zero while one scenario keeps d_safe there, so
  this changes nothing until no scenario can; then it is the intrusion no choice avoids (a
  target already inside d_safe: the first steps intrude whatever the command), and with the
  weight T_h / t it outweighed every deeper intrusion later, so all scenarios cost the same
  and the least deviation won, even one turning back into the target (doc/colav.md);
- COLREGs (mu, for threats passing closer than d_close at their predicted closest point):
  head-on (Rule 14) passed with the target on the own starboard side, or crossing give-way
  (Rule 15) passed ahead of the target; ``port_k``: a port offset while a threat is head-on or
  crossing (Rules 14, 15, 17(c)); ``apparent_k``: a give-way alteration that is neither a course
  change of at least ``apparent_course_change`` nor predicted to bring the speed down to
  ``apparent_speed_ratio`` (half) of the nominal by the closest point (Rule 8(b));
- grounding G (when the decision maker has a ``land`` mask, ship_guidance.land_mask: a chart
  raster widened by ``grounding_clearance_m``): w_grounding (T_h / t)^p at the first predicted
  position on a blocked cell, t its time; as a collision at that time, so no intrusion on a
  target is traded for running aground. Like the risk, the part every scenario shares is taken
  off (a ship already inside the clearance);
- f and change: quadratic course deviation and linear speed reduction from the nominal, and the
  change from the previous decision, port weighted more (CollisionAvoidance.deviation_cost).

Johansen et al. also score the COLREGs situation along the prediction and a transitional cost;
here the situation is the one classified now (it does not flicker as the scenario turns).
"""
import numpy as np

from ship_guidance import colregs
from ship_guidance import sbmpc_compiled as _compiled
from ship_guidance.colav import CollisionAvoidance
from ship_sim import kernels


class SBMPC(CollisionAvoidance):
    method = 'sbmpc'

    def __init__(self, params=None, ship=None):
        super().__init__(params, ship)
        if kernels.compiled():      # the risk kernel too, before the first decision
            _compiled.warm_up()

    def costs(self, sc):
        """(S,) total cost of every scenario: the sum of ``cost_terms``."""
        t = self.cost_terms(sc)
        return t['risk'] + t['grounding'] + t['port_turn'] + t['not_apparent'] + t['deviation']

    def cost_terms(self, sc):
        """The parts of every scenario's cost (module doc), each (S,) or a scalar 0: 'risk'
        (the largest over the targets of the collision risk and the wrong-side penalty),
        'grounding', 'port_turn', 'not_apparent', 'deviation'; and 'per_target' (S, M), the
        risk and wrong-side penalty per target. What a trace prints (trace_sbmpc.py)."""
        p = self.params
        if kernels.compiled() and _compiled.exact_for(p):   # _step_risk, compiled
            risk = _compiled.step_risk_max(sc.dist, sc.frac, sc.step, sc.d_safe, sc.t, p.dt_s,
                                           sc.u_ref, p.relative_speed_floor, p.horizon_s,
                                           p.risk_time_exponent, p.risk_distance_exponent,
                                           p.w_collision)
        else:
            risk = self._step_risk(sc).max(axis=2)
        beyond = self._risk_beyond_horizon(sc)
        risk = np.maximum(risk, beyond - beyond.min(axis=0))
        per_target = risk + p.w_wrong_side * self._wrong_side(sc)
        return {'risk': per_target.max(axis=1), 'grounding': self._grounding(sc),
                'port_turn': self.port_turn_penalty(sc),
                'not_apparent': self.not_apparent_penalty(sc),
                'deviation': self.deviation_cost(sc), 'per_target': per_target}

    def _step_risk(self, sc):
        """(S, M, N) risk on every prediction step, less what no scenario avoids (module doc)."""
        p = self.params
        risk = np.zeros(sc.dist.shape)
        d_safe = np.broadcast_to(sc.d_safe[None, :, None], sc.dist.shape)   # per target
        inside = sc.dist < d_safe                      # usually a small part: score only it
        if inside.any():
            t_step = sc.t[:-1][np.nonzero(inside)[2]] + sc.frac[inside] * p.dt_s
            speed = np.maximum(sc.step[inside] / (p.dt_s * sc.u_ref), p.relative_speed_floor) ** 2
            when = (p.horizon_s / np.maximum(t_step, p.dt_s)) ** p.risk_time_exponent
            depth = (d_safe[inside] / np.maximum(sc.dist[inside], 1e-3)) ** p.risk_distance_exponent
            risk[inside] = p.w_collision * speed * when * depth
            risk -= risk.min(axis=0)                   # what no scenario avoids (module doc)
        return risk

    def _grounding(self, sc):
        """(S,) grounding cost (module doc); 0 without a land mask."""
        if self.land is None:
            return 0.0
        p = self.params
        hit = self.land.hits(sc.p_own[:, 1:])                                  # (S, N)
        t_hit = sc.t[1:][hit.argmax(axis=1)]
        cost = np.where(hit.any(axis=1), p.w_grounding
                        * (p.horizon_s / np.maximum(t_hit, p.dt_s)) ** p.risk_time_exponent, 0.0)
        return cost - cost.min()

    def _risk_beyond_horizon(self, sc):
        """(S, M) risk of the straight-line closest approach after the horizon (module doc)."""
        p = self.params
        if sc.dcpa_beyond is None:
            return np.zeros(sc.dist.shape[:2])
        hit = sc.dcpa_beyond < sc.d_safe[None]
        speed = np.maximum(sc.v_rel_beyond / sc.u_ref, p.relative_speed_floor) ** 2
        when = (p.horizon_s / (p.horizon_s + sc.tcpa_beyond)) ** p.risk_time_exponent
        depth = (sc.d_safe[None] / np.maximum(sc.dcpa_beyond, 1e-3)) ** p.risk_distance_exponent
        return np.where(hit, p.w_collision * speed * when * depth, 0.0)

    def _choose(self, sc):
        cost = self.costs(sc)
        k = int(np.argmin(cost))
        return k, float(cost[k])

    def _wrong_side(self, sc):
        """(S, M) 1 where a close head-on / crossing give-way threat is passed on the wrong side."""
        n = sc.dist.argmin(axis=2)                                             # (S, M)
        s_idx, m_idx = np.indices(n.shape)
        close = sc.dist[s_idx, m_idx, n] < self.params.d_close_m
        p_o, chi = sc.p_own[s_idx, n], sc.chi[s_idx, n]                        # (S, M, 2), (S, M)
        p_t = sc.p_tgt[m_idx, n]
        los = p_t - p_o
        # target on the own starboard side: its bearing minus the own course in (0, pi)
        starboard = np.sin(np.arctan2(los[..., 1], los[..., 0]) - chi) > 0.0
        # own ship ahead of the target: in front of the line through the target across its track
        ahead = np.einsum('...i,...i->...', -los, sc.v_tgt[None]) > 0.0
        wrong = np.where(sc.codes == colregs.HEAD_ON, starboard,
                         np.where(sc.codes == colregs.CROSSING_GIVE_WAY, ahead, False))
        return (wrong & close & sc.threat).astype(float)
