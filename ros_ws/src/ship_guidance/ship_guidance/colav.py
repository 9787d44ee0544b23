"""Collision-avoidance decision (pure): the logic both methods share, and ``make_colav``.

A ``CollisionAvoidance`` object sits between guidance and autopilot. Each ``decide`` call takes
the own ship's state, the targets (position, course and speed over ground) and guidance's nominal
course and speed factor, and returns a ``Decision``: the command to follow, the chosen scenario
(course offset, speed multiplier) and per target CPA/TCPA (ship_guidance.cpa), COLREGs situation
and role (ship_guidance.colregs). The steps:

1. Every scenario (nominal course + offset, nominal speed factor x multiplier) is predicted with
   the own-ship model (ship_guidance.own_ship_prediction), targets in straight lines.
2. A target is a threat when the nominal scenario's prediction comes within ``threat_m`` of it.
   No threat: the nominal command is returned as given (the same objects, no arithmetic).
   A threat's COLREGs situation is latched when it becomes one (by target name) and kept while it
   stays one: the own ship's manoeuvre changes the bearings (a head-on target ends up on the
   port bow) but not the encounter's rules.
3. Stand-on (Rule 17(a)(i)): when every threat is one the own ship stands on for, the nominal is
   kept, unless the nominal prediction passes a stand-on threat closer than ``stand_on_dcpa_m``
   with its closest point at most ``stand_on_act_time_s`` ahead; then the own ship acts like a
   give-way ship (no turn to port, Rule 17(c)). The moment is Rule 17(a)(ii)'s: the stand-on
   ship may act alone "as soon as it becomes apparent" that the give-way ship is not taking
   appropriate action, and a give-way ship's action is due "early" (Rule 16), which the
   evaluator (colav_evaluation) fixes at ``early_s`` before the closest point; so the default
   equals ``early_s`` and the evaluator's stand-on window is the same. Acting at the first
   moment allowed rather than at Rule 17(b)'s last one keeps the most room for a slow turner;
   a ship that needs longer than that to open d_safe by its own manoeuvre cannot keep d_safe
   from a give-way ship that never acts (doc/colav.md). Rule 17(b) can come first for such a
   ship: it acts, too, as soon as its best own manoeuvre (no port turn) is predicted to pass the
   target closer than ``stand_on_dcpa_m`` (``Scenarios.must_act``), which depends on its turning
   ability through the own-ship model; the manoeuvre must keep that distance from every threat
   at once (a starboard turn that clears the stand-on target but closes another is no way out).
   The benchmark's evaluator widens its stand-on window to the same moment, computed with all
   the case's targets (scripts/imazu/evaluate.py).
   Standing on keeps the course and speed the ship has (Rule 17(a)(i)). On its route that is
   guidance's nominal; but when the threats left are stand-on ones while the ship is still off
   its route from an avoidance (e.g. it gave way to one ship and another, crossing from port,
   is still closing), guidance's nominal is a turn back towards the route, often towards that
   target and to port (what 17(c) forbids). Returning it let the ship swing into the target
   while "standing on", and Rule 17(b)'s moment (the best manoeuvre no longer keeps the
   distance) then came only when no manoeuvre could keep it. So a stand-on entered from an
   avoidance holds the avoidance's command (``Scenarios.held``), the anchor kept, and both
   moments of acting are judged on that held command. The turn back to guidance's command
   (predicted, ``Scenarios.back_min``) is taken once it passes every threat beyond
   ``threat_m`` or only opens it (its closest approach is now): neither holding until no
   threat is left (a threat is judged on the anchor's course, so a target the held course ran
   beside stayed one and the ship escorted it away from its route), nor until every stand-on
   threat is opening on the present course (the turn back itself can close one again), nor
   once the turn back is predicted to keep ``stand_on_dcpa_m`` (no room for a plant that turns
   slower than the course model; a Rule 17(b) action that then forbids continuing the port
   turn passes closer still). A held command beside which a threat stays (their relative speed
   too small to move it ``d_safe_m`` within a horizon, and the turn back would not be clear
   even after one or two more horizons of it) never gets back: the hold then takes the
   cheapest scenario no further to port and no faster, passing none closer, after which it
   would be (``_escort_way_out``), a turn further to starboard under a crosser's stern or a
   slower speed.
4. Otherwise the method (ship_guidance.sbmpc or ship_guidance.velocity_obstacles) picks a
   scenario; ties go to the first in a fixed order: the larger speed multiplier first, then
   offsets 0, +15, -15, +30, ... deg (smaller first, starboard before port).
5. Anchor: the scenarios are offsets from the nominal course at the moment the avoidance began,
   held until no threat is left (or the ship stands on). Guidance's nominal is not a fixed
   course: line-of-sight guidance steers back towards the track as the ship leaves it, so an
   offset added to the current nominal would shrink as the ship turns away (a 30 deg
   alteration became about 25 deg over ground, and the method kept raising the offset to make up
   for it). The decision's ``course_offset`` is the command relative to the nominal given now
   (what colav_node adds to heading_ref), ``scenario_offset`` the chosen scenario's.
6. Last resort: when no scenario keeps every target beyond ``collision_m``, hard starboard (the
   largest offset) and, where a shaft exists, stop (the smallest multiplier). Never a freeze.

Courses are NED (rad, clockwise from north); a positive offset turns to starboard.
"""
from dataclasses import dataclass

import numpy as np

from ship_guidance import colregs, own_ship_prediction_compiled
from ship_guidance.colav_params import ColavParams
from ship_guidance.cpa import cpa, velocity
from ship_guidance.own_ship_prediction import (OwnShipModel, predict_own, predict_targets,
                                               segment_min_distance, time_grid)
from ship_sim import kernels
from ship_sim.frames import wrap_angle


@dataclass(frozen=True)
class ShipState:
    """Position (m, NED), course and speed over ground (rad, m/s); heading (rad) defaults to
    course; yaw rate (rad/s, + to starboard): the own ship's prediction starts turning at it."""
    north: float
    east: float
    course: float
    speed: float
    heading: float | None = None
    yaw_rate: float = 0.0


@dataclass(frozen=True)
class Target(ShipState):
    """A target's state; ``name`` (unique, e.g. the odometry's child_frame_id) keys its latched
    situation; without one the target's index in the list is the key. ``position_sigma_m``:
    the square root of the largest eigenvalue of its position covariance (0: exact); the
    decision widens the target's safe distance by ``uncertainty_k`` times it."""
    name: str = ''
    position_sigma_m: float = 0.0


@dataclass(frozen=True)
class TargetAssessment:
    name: str
    tcpa_s: float            # straight-line, current velocities
    dcpa_m: float
    situation: str           # colregs.SITUATIONS
    role: str                # 'give-way', 'stand-on' or 'none'
    threat: bool
    nominal_min_distance_m: float   # over the horizon, own ship under the nominal command


@dataclass(frozen=True)
class Decision:
    course: float            # commanded course (rad, NED)
    speed_factor: float
    mode: str                # 'nominal' (no threat), 'stand-on', 'avoid' or 'last-resort'
    course_offset: float     # course minus the nominal course given (rad, + starboard, wrapped)
    speed_multiplier: float  # of the chosen scenario (x nominal speed factor)
    threat: bool             # whether any target was a threat
    targets: tuple           # TargetAssessment per target, in input order
    cost: float | None = None
    scenario_offset: float = 0.0   # the chosen scenario's offset from the anchor (rad)


GIVE_WAY_CODES = (colregs.OVERTAKING, colregs.HEAD_ON, colregs.CROSSING_GIVE_WAY)
STAND_ON_CODES = (colregs.BEING_OVERTAKEN, colregs.CROSSING_STAND_ON)
NO_PORT_TURN_CODES = (colregs.HEAD_ON, colregs.CROSSING_GIVE_WAY, colregs.CROSSING_STAND_ON)


@dataclass
class Scenarios:
    """Everything a method needs for one decision (arrays over S scenarios, M targets, N steps)."""
    offsets: np.ndarray      # (S,) rad
    multipliers: np.ndarray  # (S,)
    chi_c: np.ndarray        # (S,) commanded course, rad
    u_c: np.ndarray          # (S,) commanded speed, m/s
    u_ref: float             # nominal speed, m/s (> 0)
    t: np.ndarray            # (N+1,) s
    p_own: np.ndarray        # (S, N+1, 2)
    chi: np.ndarray          # (S, N+1)
    p_own0: np.ndarray       # (2,)
    p_tgt: np.ndarray        # (M, N+1, 2)
    p_tgt0: np.ndarray       # (M, 2)
    v_tgt: np.ndarray        # (M, 2)
    dist: np.ndarray         # (S, M, N) closest approach on each step
    frac: np.ndarray         # (S, M, N)
    step: np.ndarray         # (S, M, N) relative displacement over each step, m
    codes: np.ndarray        # (M,) situation codes now
    threat: np.ndarray       # (M,) bool
    acting_stand_on: bool    # Rule 17(b) in force
    v_own_end: np.ndarray = None   # (S, 2) own NED velocity at the horizon's end (m/s)
    # Straight-line closest approach after the horizon (the scenario held, the target on its
    # line), within one more horizon: time after the horizon's end (s), distance (m, inf when
    # not within it) and relative speed (m/s), (S, M) each.
    tcpa_beyond: np.ndarray = None
    dcpa_beyond: np.ndarray = None
    v_rel_beyond: np.ndarray = None
    must_act: np.ndarray = None    # (M,) bool: Rule 17(b) moment for a stand-on target (step 3)
    u: np.ndarray = None           # (S, N+1) predicted speed through the water, m/s
    d_safe: np.ndarray = None      # (M,) each target's safe distance, m (d_safe_m widened)
    held: int = 0                  # the scenario a stand-on keeps: the nominal, or while avoiding
    #                                the command in force (step 3)
    back_min: np.ndarray = None    # (M,) closest approach of the turn back to guidance's command


class CollisionAvoidance:
    """Stateful decision maker; subclasses implement ``_choose(sc) -> (index, cost)``."""

    method = ''

    def __init__(self, params=None, ship=None):
        self.params = params or ColavParams()
        self.ship = ship or OwnShipModel()
        p = self.params
        mults = sorted(set(p.speed_factors) if self.ship.has_shaft else {1.0}, reverse=True)
        offs = sorted(set(p.course_offsets), key=lambda o: (abs(o), o < 0))
        self._offsets = np.array([o for _ in mults for o in offs])
        self._multipliers = np.array([m for m in mults for _ in offs])
        self._t = time_grid(p.horizon_s, p.dt_s)
        self._latched = {}
        # ship_guidance.land_mask.LandMask or None; SB-MPC scores grounding against it.
        self.land = None
        self.reset()
        if kernels.compiled():      # compile the prediction kernels before the first decision
            own_ship_prediction_compiled.warm_up()

    def reset(self):
        """Forget the previous decision (the change penalty's reference) and the anchor."""
        self.last_offset, self.last_multiplier = 0.0, 1.0
        self.anchor = None

    def _latch(self, targets, codes, threat):
        """Situation codes with each threat's code as it was when it became one."""
        keys = [tg.name or i for i, tg in enumerate(targets)]
        for i, key in enumerate(keys):
            if threat[i]:
                codes[i] = self._latched.setdefault(key, int(codes[i]))
        self._latched = {k: c for k, c in self._latched.items() if k in
                         {key for key, th in zip(keys, threat) if th}}
        return codes

    def decide(self, t, own_state, targets, nominal_course, nominal_speed_factor):
        """The ``Decision`` at time ``t`` (s; kept for the node's bookkeeping, the decision
        depends only on the states)."""
        del t
        targets = tuple(targets)
        base = nominal_course if self.anchor is None else self.anchor
        sc = self.scenarios(own_state, targets, base, nominal_speed_factor, nominal_course)
        assessments = self._assess(own_state, targets, sc)
        if sc is None or not sc.threat.any():
            self.reset()
            return Decision(nominal_course, nominal_speed_factor, 'nominal', 0.0, 1.0, False,
                            assessments)
        if self._hold_as_stand_on(sc):
            if self.anchor is None or self._turn_back_clear(sc):
                self.reset()
                return Decision(nominal_course, nominal_speed_factor, 'stand-on', 0.0, 1.0, True,
                                assessments)
            # still off the route from an avoidance: keep its course and speed (module doc, 3),
            # or, beside a target that the held command never passes, draw clear of it
            k = self._escort_way_out(sc, nominal_course)
            self.last_offset, self.last_multiplier = float(sc.offsets[k]), float(sc.multipliers[k])
            course, mult = float(sc.chi_c[k]), float(sc.multipliers[k])
            return Decision(course, mult * nominal_speed_factor, 'stand-on',
                            float(wrap_angle(course - nominal_course)), mult, True, assessments,
                            None, float(sc.offsets[k]))
        k, cost = self._choose(sc)
        mode = 'avoid'
        if sc.dist.min(axis=(1, 2)).max() < self.params.collision_m:
            k = self._last_resort_index()
            mode, cost = 'last-resort', None
        off, mult = float(sc.offsets[k]), float(sc.multipliers[k])
        self.last_offset, self.last_multiplier = off, mult
        if off == 0.0 and mult == 1.0 and self.anchor is None:
            return Decision(nominal_course, nominal_speed_factor, mode, 0.0, 1.0, True, assessments,
                            cost)
        self.anchor = base
        course = float(sc.chi_c[k])
        return Decision(course, mult * nominal_speed_factor, mode,
                        float(wrap_angle(course - nominal_course)), mult, True, assessments, cost,
                        off)

    def _turn_back_clear(self, sc):
        """Whether a stand-on held after an avoidance may turn back to guidance's command (module
        doc, 3): the turn back, as predicted, makes no threat of any threat left (passes it
        beyond ``threat_m``) or only opens it (its closest approach is now, to a metre).
        Keeping ``stand_on_dcpa_m`` is not enough: a release on a prediction just beyond it
        leaves no room for the plant turning slower than the course model, and a Rule 17(b)
        action that then forbids continuing the port turn back can pass closer still."""
        return self._back_passes(sc.back_min, np.hypot(*(sc.p_tgt0 - sc.p_own0).T), sc.threat)

    def _back_passes(self, back_min, d_start, threat):
        """The release rule on a predicted turn back: its closest approach to every threat
        beyond ``threat_m`` or no closer than at its start (to a metre)."""
        ok = back_min >= np.minimum(self.params.threat_m, d_start - 1.0)
        return bool(ok[threat].all())

    def _escort_way_out(self, sc, guidance_course):
        """The scenario a stand-on held after an avoidance keeps (module doc, 3): the held one,
        unless a threat runs beside it and the turn back to ``guidance_course`` would not be
        clear (``_turn_back_clear``'s rule) from where the held command leaves the ship after
        one or two horizons: the turn back would never come. Beside: its relative speed at the
        horizon's end below ``d_safe_m / horizon_s`` (within a horizon it would not move even
        ``d_safe_m`` as seen from the own ship, range and bearing frozen), as in Imazu case 4,
        where a 45 deg turn from a crosser at the own ship's speed put the two on one course to
        the run's limit. Then the cheapest scenario (``deviation_cost``) that turns no further
        to port, is no faster, passes no target closer than the held one does (or than
        ``threat_m``) and after one or two horizons has a clear turn back: a ship handler's
        turn further to starboard under the crosser's stern, or a slower speed where a shaft
        exists. None such: the held one. A target that is not beside is left to the held
        command even when the turn back is not yet clear: it is still closing or passing, and
        turning away from it only lengthens the way back (Imazu 13 and 16)."""
        held = sc.held
        beside = sc.v_rel_beyond[held, sc.threat] < self.params.d_safe_m / self._t[-1]
        if not beside.any():
            return held
        later = self._targets_later(sc)
        if self._back_clear_after(sc, held, guidance_course, later):
            return held
        # every target, not only the threats: the turn away must not make a new one
        d_min = np.minimum(sc.dist.min(axis=2), sc.dcpa_beyond)                   # (S, M)
        keep = np.minimum(d_min[held], self.params.threat_m)
        ok = ((sc.offsets >= sc.offsets[held]) & (sc.multipliers <= sc.multipliers[held])
              & (d_min >= keep).all(axis=1))
        ok[held] = False
        cost = self.deviation_cost(sc)
        for k in sorted(np.flatnonzero(ok), key=lambda k: cost[k]):
            if self._back_clear_after(sc, k, guidance_course, later):
                return int(k)
        return held

    def _targets_later(self, sc):
        """The targets' predicted tracks from the horizon's end and from one horizon after it,
        the same for every scenario: [(start positions (M, 2), tracks (M, N+1, 2))]."""
        starts = (sc.p_tgt[:, -1], sc.p_tgt[:, -1] + sc.v_tgt * self._t[-1])
        return [(p0, predict_targets(p0, sc.v_tgt, self._t)) for p0 in starts]

    def _back_clear_after(self, sc, k, guidance_course, later):
        """Whether the turn back to ``guidance_course`` (at the nominal speed, the targets on
        their lines) passes every threat beyond ``threat_m`` or only opens it, started after
        one horizon of scenario ``k`` or after two (the second one straight on at the
        horizon's end velocity, as ``dcpa_beyond`` continues a scenario): a target that the
        held command passes slowly is let pass, not turned away from. ``later``:
        ``_targets_later(sc)``."""
        v_end = velocity(sc.chi[k, -1], sc.u[k, -1])
        for wait, (p_tgt0, p_tgt) in zip((0.0, self._t[-1]), later):
            p_start = sc.p_own[k, -1] + v_end * wait
            p_back, _ = predict_own(p_start[0], p_start[1], float(sc.chi[k, -1]),
                                    float(sc.u[k, -1]), np.array([guidance_course]),
                                    np.array([sc.u_ref]), self._t, self.ship)
            back_min = segment_min_distance(p_back, p_tgt)[0][0].min(axis=1)
            if self._back_passes(back_min, np.hypot(*(p_tgt0 - p_start).T), sc.threat):
                return True
        return False

    # --- shared pieces -------------------------------------------------------------------

    def scenarios(self, own, targets, nominal_course, nominal_speed_factor, guidance_course=None):
        """The predicted ``Scenarios`` for these inputs (None without targets); it latches the
        situations of new threats, as ``decide`` does. ``guidance_course``: guidance's nominal
        now when ``nominal_course`` is an avoidance's anchor (step 5): the command a stand-on
        would turn back to (``Scenarios.back_min``); None: ``nominal_course`` itself."""
        if not targets:
            return None
        p = self.params
        u_one = self.ship.speed_at_factor_one_mps
        u_nom = own.speed if u_one is None else nominal_speed_factor * u_one
        chi_c = nominal_course + self._offsets
        u_c = self._multipliers * u_nom
        p_own0 = np.array([own.north, own.east], dtype=float)
        p_own, chi, u = predict_own(own.north, own.east, own.course, own.speed, chi_c, u_c,
                                    self._t, self.ship, own.yaw_rate,
                                    self.ship.turn_authority(self._multipliers), with_speed=True)
        v_own_end = velocity(chi[:, -1], u[:, -1])
        p_tgt0 = np.array([[tg.north, tg.east] for tg in targets], dtype=float)
        v_tgt = velocity(np.array([tg.course for tg in targets]), np.array([tg.speed for tg in targets]))
        p_tgt = predict_targets(p_tgt0, v_tgt, self._t)
        dist, frac, step = segment_min_distance(p_own, p_tgt)
        heading = own.course if own.heading is None else own.heading
        t_heads = np.array([tg.course if tg.heading is None else tg.heading for tg in targets])
        codes = colregs.classify(p_own0, heading, velocity(own.course, own.speed), p_tgt0, t_heads, v_tgt)
        d_nom = dist[0].min(axis=1)
        threat = d_nom < p.threat_m
        codes = self._latch(targets, codes, threat)
        tcpa_b, dcpa_b = cpa(p_own[:, None, -1], v_own_end[:, None], p_tgt[None, :, -1],
                             v_tgt[None])
        beyond = (tcpa_b > 0.0) & (tcpa_b <= p.horizon_s)
        dcpa_b = np.where(beyond, dcpa_b, np.inf)
        v_rel_b = np.hypot(*(v_tgt[None] - v_own_end[:, None]).transpose(2, 0, 1))
        # the command a stand-on keeps (module doc, 3): the nominal, or the avoidance's in force
        held = 0 if self.anchor is None else self._index(self.last_offset, self.last_multiplier)
        d_held = dist[held].min(axis=1)
        n_min = dist[held].argmin(axis=1)                                      # (M,)
        m_idx = np.arange(len(targets))
        t_min = self._t[n_min] + frac[held, m_idx, n_min] * p.dt_s  # its closest point, s
        stand_on = threat & np.isin(codes, STAND_ON_CODES)
        # Rule 17(b): the best manoeuvre of the own ship alone (no turn to port of the course
        # kept, 17(c)) can no longer keep stand_on_dcpa_m from every threat at once, counting
        # the pass beyond the horizon too (one manoeuvre must clear them all: judged per
        # target, a starboard turn that clears the stand-on target but runs into another threat
        # counted as a way out)
        starboard = self._offsets >= self._offsets[held]
        clear = np.minimum(dist.min(axis=2), dcpa_b)[starboard]                  # (S', M)
        joint = clear[:, threat].min(axis=1).max() if threat.any() else np.inf
        must = stand_on & (joint < p.stand_on_dcpa_m)
        late = stand_on & (d_held < p.stand_on_dcpa_m) & (t_min <= p.stand_on_act_time_s)
        acting = bool((late | must).any())
        d_safe = p.safe_distance(np.array([tg.position_sigma_m for tg in targets]))
        if guidance_course is None or guidance_course == nominal_course:
            back_min = d_nom
        else:               # the turn back to guidance's command, predicted (module doc, 3)
            p_back, _ = predict_own(own.north, own.east, own.course, own.speed,
                                    np.array([guidance_course]), np.array([u_nom]), self._t,
                                    self.ship, own.yaw_rate)
            back_min = segment_min_distance(p_back, p_tgt)[0][0].min(axis=1)
        return Scenarios(self._offsets, self._multipliers, chi_c, u_c, max(float(u_nom), 0.1),
                         self._t, p_own, chi, p_own0, p_tgt, p_tgt0, v_tgt, dist, frac, step,
                         codes, threat, acting, v_own_end, tcpa_b, dcpa_b, v_rel_b, must, u,
                         d_safe, held, back_min)

    def _index(self, offset, multiplier):
        """Index of the scenario (offset, multiplier)."""
        return int(np.flatnonzero((self._offsets == offset) & (self._multipliers == multiplier))[0])

    def _assess(self, own, targets, sc):
        if sc is None:
            return ()
        tcpa, dcpa = cpa(sc.p_own0, velocity(own.course, own.speed), sc.p_tgt0, sc.v_tgt)
        d_nom = sc.dist[0].min(axis=1)
        return tuple(TargetAssessment(tg.name, float(tcpa[i]), float(dcpa[i]),
                                      colregs.SITUATIONS[sc.codes[i]], colregs.role(sc.codes[i]),
                                      bool(sc.threat[i]), float(d_nom[i]))
                     for i, tg in enumerate(targets))

    @staticmethod
    def _hold_as_stand_on(sc):
        return bool(np.isin(sc.codes[sc.threat], STAND_ON_CODES).all()) and not sc.acting_stand_on

    def _last_resort_index(self):
        hard = (self._offsets == self._offsets.max()) & (self._multipliers == self._multipliers.min())
        return int(np.flatnonzero(hard)[0])

    def deviation_cost(self, sc):
        """(S,) deviation from the nominal plus change from the previous decision (Johansen
        et al. 2016's f and its change terms; port weighted more than starboard)."""
        p = self.params
        off = sc.offsets
        dev = np.where(off >= 0.0, p.w_course_starboard, p.w_course_port) * off ** 2
        dev = dev + p.w_speed * (1.0 - sc.multipliers)
        d_off = off - self.last_offset
        change = np.where(d_off >= 0.0, p.w_change_course_starboard, p.w_change_course_port) * d_off ** 2
        return dev + change + p.w_change_speed * np.abs(sc.multipliers - self.last_multiplier)

    def port_turn_penalty(self, sc):
        """(S,) ``w_port_turn`` for port offsets while a threat is head-on or crossing (Rules 14,
        15; 17(c) for a stand-on ship that acts)."""
        if not np.isin(sc.codes[sc.threat], NO_PORT_TURN_CODES).any():
            return np.zeros_like(sc.offsets)
        return np.where(sc.offsets < 0.0, self.params.w_port_turn, 0.0)

    def not_apparent_penalty(self, sc):
        """(S,) ``w_not_apparent`` for give-way alterations that are neither a course change of
        at least ``apparent_course_change`` nor predicted to bring the speed down to
        ``apparent_speed_ratio`` x the nominal by the closest point of every give-way threat,
        while a threat is one the own ship gives way to (Rule 8(b): "large enough to be readily
        apparent"). The predicted speed, not the commanded factor: the tanker's surge lag
        (793 s) keeps it above half speed long after a halved or stopped shaft."""
        p = self.params
        give_way = sc.threat & np.isin(sc.codes, GIVE_WAY_CODES)
        if not give_way.any():
            return np.zeros_like(sc.offsets)
        n = sc.dist[:, give_way].argmin(axis=2)                               # (S, G) steps
        u_cpa = np.take_along_axis(sc.u, n, axis=1)                           # speed then
        slow = (u_cpa <= p.apparent_speed_ratio * sc.u_ref + 1e-9).all(axis=1)
        acted = (sc.offsets != 0.0) | (sc.multipliers < 1.0)
        small = np.abs(sc.offsets) < p.apparent_course_change - 1e-9
        return np.where(acted & small & ~slow, p.w_not_apparent, 0.0)

    def _choose(self, sc):
        raise NotImplementedError

