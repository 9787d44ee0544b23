"""Target ships that react to the others (issue 31 item 4): behaviours, stepped in time (pure).

A light target (ship_sim.light_traffic) holds its course and speed. This module moves targets
that behave otherwise, step by step beside the own ship, each with one behaviour (the names
are ship_sim.light_traffic.BEHAVIOURS, the one list the scenario files are checked against):

``straight``
    Holds course and speed whatever happens (today's light target, in closed form). Trigger:
    none. Rule breach: whichever its role makes of keeping on (none for a stand-on ship).
``reciprocal``
    Runs its own collision avoidance: the same method, parameters and own-ship model as the
    own ship (what the caller's ``colav_factory`` builds), deciding at the same period on its
    own view of the others: every other ship (the own ship and the other targets) as a
    straight-line target, its own COLREGs situations latched by name. Its nominal course is
    line-of-sight guidance back to its straight track (the own ship's look-ahead), so after
    giving way it returns. Trigger: its method's (a threat within ``threat_m``). Rule breach:
    none intended; the same as the own ship's method makes.
``turns_to_port``
    A stand-on ship that turns to port into a crossing give-way vessel. Trigger: the first
    step at which some other ship is a crossing in which this target stands on (seen from the
    target: ship_guidance.colregs' crossing-stand-on, the other ship on its port side,
    approaching) within ``trigger_range_m``: the range at which the evaluator's stage 3 begins,
    where a stand-on ship may act alone (Rule 17(a)(ii); colav_evaluation.EvaluationParams
    .r_colregs_3_max_m). It then alters ``port_turn_deg`` to port (the evaluator's readily
    apparent course change, ``delta_course_app_deg``) and holds that course for good. Rule
    breach: Rule 17(c) (a stand-on ship that acts shall, if the circumstances admit, not alter
    course to port for a vessel on her own port side).
``no_alteration``
    A head-on or give-way target that never alters: the same motion as ``straight`` (closed
    form), named apart because it is applied only where the target's role requires action
    (``APPLIES``). Trigger: none. Rule breach: Rule 14 in a head-on encounter (both alter to
    starboard), Rules 15/16 as the give-way ship of a crossing (keep out of the way, early and
    substantial action), Rule 13 as an overtaking ship.

A reacting target (reciprocal, turns_to_port) moves as colav's own-ship model predicts a ship
under its autopilot (ship_guidance.own_ship_prediction: the course's first-order Nomoto
response under the PD heading loop, the speed's first-order response), one step of
``course_response`` / ``speed_response`` per call, its position by the trapezoidal rule: the
reciprocal target's decisions then rest on a model that is exact for it. Its speed command is
its start speed times the decision's speed multiplier (1 for a ship without a shaft).

Frames: NED, courses clockwise from north (rad), as every pure module.
"""
import math

import numpy as np

from ship_guidance import colregs
from ship_guidance.colav import ShipState, Target
from ship_guidance.colav_evaluation import EvaluationParams
from ship_guidance.own_ship_prediction import course_response, speed_response
from ship_sim.frames import wrap_angle
from ship_sim.light_traffic import BEHAVIOURS, CLOSED_FORM

STRAIGHT, RECIPROCAL, TURNS_TO_PORT, NO_ALTERATION = BEHAVIOURS
#: Situations (seen from the target, ship_guidance.colregs.SITUATIONS) in which a behaviour
#: means what its name says: a rule-breaking behaviour where its rule applies.
APPLIES = {
    STRAIGHT: colregs.SITUATIONS[1:],
    RECIPROCAL: colregs.SITUATIONS[1:],
    TURNS_TO_PORT: ('crossing-stand-on',),
    NO_ALTERATION: ('head-on', 'crossing-give-way', 'overtaking'),
}
#: The same encounter seen from the other ship.
MIRROR = {'none': 'none', 'overtaking': 'being-overtaken', 'being-overtaken': 'overtaking',
          'head-on': 'head-on', 'crossing-give-way': 'crossing-stand-on',
          'crossing-stand-on': 'crossing-give-way'}
_EVAL = EvaluationParams()
#: turns_to_port's trigger range (m) and port turn (deg): see the module docstring.
TRIGGER_RANGE_M = _EVAL.r_colregs_3_max_m
PORT_TURN_DEG = _EVAL.delta_course_app_deg


def applies(behaviour, own_view_situation):
    """Whether ``behaviour`` applies to a target whose situation seen from the own ship is
    ``own_view_situation`` (e.g. turns_to_port to a crossing-give-way target)."""
    if behaviour not in APPLIES:
        raise ValueError(f'behaviour {behaviour!r} unknown; one of {", ".join(BEHAVIOURS)}')
    return MIRROR[own_view_situation] in APPLIES[behaviour]


def los_course(north, east, north0, east0, course0, lookahead_m):
    """Line-of-sight course (rad) back to the straight track through (north0, east0) on
    ``course0``: the track direction less atan(cross-track error / look-ahead)."""
    e = -(north - north0) * math.sin(course0) + (east - east0) * math.cos(course0)
    return float(wrap_angle(course0 - math.atan2(e, lookahead_m)))


class ReactingTraffic:
    """Targets of a LightTraffic with one behaviour each, stepped with the own ship.

    ``state(t)`` gives every target at time t (arrays like LightTraffic.state) and ``step(t,
    own, dt)`` advances the reacting ones from t to t + dt, deciding on the own ship's
    ``own`` (a colav ShipState, or None for no own ship) and the others at t. Closed-form
    targets are LightTraffic's numbers exactly; reacting ones start from its state at the first
    ``state`` call and need a target of constant course and speed."""

    def __init__(self, light, behaviours, ship, colav_factory=None, decision_period_s=1.0,
                 lookahead_m=1000.0, trigger_range_m=TRIGGER_RANGE_M,
                 port_turn_deg=PORT_TURN_DEG, own_name='own_ship'):
        """light: ship_sim.light_traffic.LightTraffic; behaviours: {name: behaviour} (absent
        names: straight); ship: the OwnShipModel the reacting targets move (and decide) with;
        colav_factory: a callable returning a new CollisionAvoidance (needed for reciprocal)."""
        unknown = sorted(set(behaviours) - set(light.names))
        if unknown:
            raise ValueError(f'behaviours for unknown targets {unknown}; targets: {light.names}')
        self.light, self.ship = light, ship
        self.behaviours = [behaviours.get(n, STRAIGHT) for n in light.names]
        for name, b in zip(light.names, self.behaviours):
            if b not in BEHAVIOURS:
                raise ValueError(f'{name}: behaviour {b!r} unknown; one of {", ".join(BEHAVIOURS)}')
        if RECIPROCAL in self.behaviours and colav_factory is None:
            raise ValueError('a reciprocal target needs a colav_factory')
        self.period_s = float(decision_period_s)
        self.lookahead_m = float(lookahead_m)
        self.trigger_range_m = float(trigger_range_m)
        self.port_turn = math.radians(port_turn_deg)
        self.own_name = own_name
        self.reacting = [i for i, b in enumerate(self.behaviours) if b not in CLOSED_FORM]
        self._colav = {i: colav_factory() for i in self.reacting
                       if self.behaviours[i] == RECIPROCAL}
        self._next_decision = {i: None for i in self._colav}
        self._decision = {i: None for i in self._colav}
        self.triggered = {}          # turns_to_port: name -> (time, other ship's name)
        self._kin = None             # reacting: index -> [north, east, course, speed, rate]
        self._start = None           # reacting: index -> (north0, east0, course0, speed0)

    @property
    def names(self):
        return self.light.names

    def __len__(self):
        return len(self.light)

    def _init(self, t):
        north, east, course, speed = self.light.state(t)
        self._start = {i: (float(north[i]), float(east[i]), float(course[i]), float(speed[i]))
                       for i in self.reacting}
        self._kin = {i: [*self._start[i], 0.0] for i in self.reacting}

    def state(self, t):
        """(north, east, course, speed) arrays at time t (the time of the last ``step``'s end)."""
        north, east, course, speed = (np.array(a, dtype=float) for a in self.light.state(t))
        if self.reacting and self._kin is None:
            self._init(t)
        for i in self.reacting:
            north[i], east[i], course[i], speed[i] = self._kin[i][:4]
        return north, east, course, speed

    def _others(self, i, t, own):
        """Target list of ship i's view: the own ship and every other target at time t."""
        north, east, course, speed = self.state(t)
        out = [] if own is None else [Target(own.north, own.east, own.course, own.speed,
                                             own.heading, name=self.own_name)]
        out += [Target(float(north[j]), float(east[j]), float(course[j]), float(speed[j]),
                       name=n) for j, n in enumerate(self.names) if j != i]
        return out

    def _command(self, i, t, own):
        """(course command rad, speed command m/s) of reacting target i at time t."""
        north, east, course, speed, rate = self._kin[i]
        n0, e0, c0, u0 = self._start[i]
        name, behaviour = self.names[i], self.behaviours[i]
        if behaviour == TURNS_TO_PORT:
            if name not in self.triggered:
                other = self._stand_on_crossing(i, t, own)
                if other is not None:
                    self.triggered[name] = (float(t), other)
            return (float(wrap_angle(c0 - self.port_turn)) if name in self.triggered else c0), u0
        nominal = los_course(north, east, n0, e0, c0, self.lookahead_m)
        t_ns = round(t * 1e9)
        if self._next_decision[i] is None or t_ns >= self._next_decision[i]:
            self._next_decision[i] = t_ns + round(self.period_s * 1e9)
            me = ShipState(north, east, course, speed, course, rate)
            self._decision[i] = self._colav[i].decide(t, me, self._others(i, t, own), nominal, 1.0)
        d = self._decision[i]
        if d is None or d.course_offset == 0.0:
            return nominal, u0
        return float(wrap_angle(nominal + d.course_offset)), u0 * d.speed_multiplier

    def _stand_on_crossing(self, i, t, own):
        """Name of the nearest ship within the trigger range that ship i stands on for in a
        crossing (seen from i), or None."""
        north, east, course, speed = self._kin[i][:4]
        others = self._others(i, t, own)
        if not others:
            return None
        p_t = np.array([[o.north, o.east] for o in others])
        h_t = np.array([o.heading if o.heading is not None else o.course for o in others])
        v_t = np.stack((np.array([o.speed for o in others]) * np.cos([o.course for o in others]),
                        np.array([o.speed for o in others]) * np.sin([o.course for o in others])),
                       axis=-1)
        p = np.array([north, east])
        v = speed * np.array([math.cos(course), math.sin(course)])
        codes = colregs.classify(p[None], np.array([course]), v[None], p_t, h_t, v_t)
        rng = np.hypot(*(p_t - p).T)
        hit = (codes == colregs.CROSSING_STAND_ON) & (rng < self.trigger_range_m)
        return others[int(np.argmin(np.where(hit, rng, np.inf)))].name if hit.any() else None

    def step(self, t, own, dt):
        """Advance the reacting targets from t to t + dt (s), deciding at t on ``own`` (the own
        ship's colav ShipState at t, or None) and the other targets at t."""
        if not self.reacting:
            return
        if self._kin is None:
            self._init(t)
        commands = {i: self._command(i, t, own) for i in self.reacting}   # all at time t
        grid = np.array([0.0, float(dt)])
        for i, (chi_c, u_c) in commands.items():
            north, east, course, speed, rate = self._kin[i]
            chi, r = course_response(course, np.array([chi_c]), grid, self.ship, rate,
                                     with_rate=True)
            u = speed_response(speed, np.array([u_c]), grid, self.ship, chi)
            v = np.stack((u * np.cos(chi), u * np.sin(chi)), axis=-1)[0]
            north += 0.5 * dt * (v[0, 0] + v[1, 0])
            east += 0.5 * dt * (v[0, 1] + v[1, 1])
            self._kin[i] = [float(north), float(east), float(wrap_angle(chi[0, 1])),
                            float(u[0, 1]), float(r[0])]
