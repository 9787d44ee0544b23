"""What colav_node feeds the decision and makes of it (pure: no rclpy, no messages).

- ``ship_state`` / ``target_state``: odometry (already in NED/FRD, ship_sim.ros.conversions
  .odometry_to_ned) -> ``ShipState`` / ``Target`` with course and speed over ground
  (chi = psi + atan2(v, u), U = |(u, v)|; the heading keeps psi for the COLREGs sectors).
- ``TargetTracks``: per target the states received, keyed by stamp; ``at(t)`` gives each target's
  latest state with a stamp <= t, dead-reckoned in a straight line to t (``dead_reckon``), so
  a decision never sees a sample from the future, whatever order the messages arrived in.
  Lockstep targets (full vessels stepping with the own ship) must have a sample at or after t
  before a decision at t is taken (``waiting_for``). The table forgets a target once its newest
  state is stale at a decision, and holds at most ``max_targets`` (DEFAULT_MAX_TARGETS): a
  newcomer to a full table makes the farthest twentieth of it (EVICT_FRACTION, at least one;
  lockstep targets never) from the own ship (``reference``) leave at once, the newcomer among
  them if it is that far (counted in ``n_evicted``; one pass over the table per twentieth, not
  per newcomer, keeps a flood of names cheap), so the decision's cost depends on the targets
  around now, never on how many names were ever heard. A state that no ship can have is refused and
  counted by reason (``refused``): a non-finite number, a position beyond MAX_COORDINATE_M or a
  speed above MAX_SPEED_MPS (ship_sim.bounds).
- ``SyncedSource``: a many-target topic whose publisher announces after each step how many
  targets it published at that stamp (ais_node's ``targets_sync``): complete up to a stamp once
  every announced message up to it has come, so a lockstep decision can wait for it.
- ``DecisionSchedule``: a decision every ``period`` of sim time, on integer nanoseconds so the
  schedule is exact and identical on repeat.
- ``command_yaw``: the ENU yaw command from the nominal one and the last decision: the nominal
  value itself (bit for bit) when the decision keeps the nominal course, else the nominal
  course plus the decided offset.
- ``target_rows``: the documented per-target array of the ``colav_targets`` topic.
- ``RefHold``: a non-finite nominal heading (heading_ref) is refused and counted; the last good
  one is held in its place, the way autopilot_node holds its last heading_cmd.
"""
import bisect
import heapq
import math
from dataclasses import replace

import numpy as np

from ship_guidance import colregs
from ship_guidance.colav import ShipState, Target
from ship_guidance.cpa import range_and_bearing
from ship_sim.bounds import MAX_COORDINATE_M, MAX_SPEED_MPS
from ship_sim.frames import psi_to_yaw, wrap_angle, yaw_to_psi

NS_PER_S = 1_000_000_000

#: Columns of one target's row on colav_targets.
TARGET_COLUMNS = ('tcpa_s', 'dcpa_m', 'situation', 'role', 'range_m', 'bearing_rad')
#: Role codes (column 'role'); situation codes are ship_guidance.colregs' (index into SITUATIONS).
ROLE_CODES = {'none': 0, colregs.GIVE_WAY: 1, colregs.STAND_ON: 2}
#: Mode codes on colav_decision.
MODE_CODES = {'nominal': 0, 'stand-on': 1, 'avoid': 2, 'last-resort': 3}
#: colav_node's own parameters (config/colav.yaml lists them beside the decision's).
NODE_KEYS = frozenset({'method', 'decision_period_s', 'pairing', 'targets_topic', 'target_topics',
                       'target_stale_s', 'lockstep_target_timeout_s', 'targets_sync_topic',
                       'chart_topic', 'max_targets', 'heading_cmd_readers',
                       'speed_factor_cmd_readers'})
DECISION_COLUMNS = ('t_s', 'mode', 'course_offset_rad', 'speed_multiplier', 'threat',
                    'n_targets')
#: Targets a decision considers at most (colav_node's ``max_targets``): SB-MPC's cost grows
#: with each target, and a decision must fit well within its period; far more than a crowded
#: port shows within the few nautical miles that matter.
DEFAULT_MAX_TARGETS = 200
#: States kept per target at most (the oldest go first): a lockstep target may run this many
#: steps ahead of the own ship (colav_node's queue depth for it), and a sender of ever newer
#: stamps for one name cannot grow the table beyond it.
MAX_SAMPLES_PER_TARGET = 20000
#: Share of a full target table left out at once (the farthest; see the module docstring).
EVICT_FRACTION = 0.05
#: Reasons a target state is refused (TargetTracks.refused).
REFUSED_REASONS = ('non_finite', 'out_of_range')


def to_ns(t_s):
    """Seconds -> integer nanoseconds (rounded)."""
    return int(round(t_s * NS_PER_S))


def _course_speed(psi, u, v):
    return float(wrap_angle(psi + math.atan2(v, u))), math.hypot(u, v)


def ship_state(north, east, psi, u, v, r=0.0):
    """Own ship: NED position (m), heading psi (rad), FRD velocity over ground (m/s), yaw
    rate r (rad/s, FRD: + turning to starboard)."""
    course, speed = _course_speed(psi, u, v)
    return ShipState(float(north), float(east), course, speed, float(psi), float(r))


def target_state(name, north, east, psi, u, v, position_sigma_m=0.0):
    course, speed = _course_speed(psi, u, v)
    return Target(float(north), float(east), course, speed, float(psi), name=name,
                  position_sigma_m=float(position_sigma_m))


def position_sigma(covariance):
    """Square root of the largest eigenvalue of the x-y block of a pose covariance (the 36
    row-major numbers of a geometry_msgs PoseWithCovariance), m: the target's position
    uncertainty along its worst axis, the same in ENU and NED. 0 for an all-zero covariance
    (unknown: the publisher gives none, as ais_node and the simulators); a negative
    eigenvalue (not a covariance) counts as 0; nan if any of the four numbers is not finite
    (refused: target_problem)."""
    a, b, c, d = (float(covariance[i]) for i in (0, 1, 6, 7))
    if not all(map(math.isfinite, (a, b, c, d))):
        return math.nan
    half_trace, half_diff = 0.5 * (a + d), 0.5 * (a - d)
    largest = half_trace + math.sqrt(half_diff ** 2 + (0.5 * (b + c)) ** 2)
    return math.sqrt(max(largest, 0.0))


def dead_reckon(state, dt):
    """``state`` moved on ``dt`` s along its course at its speed (course, speed kept)."""
    if dt == 0.0:
        return state
    return replace(state, north=state.north + state.speed * math.cos(state.course) * dt,
                   east=state.east + state.speed * math.sin(state.course) * dt)


def target_problem(state):
    """None if a Target's numbers are those of a ship, else (reason, text): REFUSED_REASONS."""
    values = (state.north, state.east, state.course, state.speed, state.heading)
    if not all(v is None or math.isfinite(v) for v in values):
        return 'non_finite', f'non-finite state (north, east, course, speed) = {values[:4]}'
    if not math.isfinite(state.position_sigma_m):
        return 'non_finite', 'non-finite position covariance'
    if state.position_sigma_m > MAX_COORDINATE_M:
        return 'out_of_range', (f'position sigma {state.position_sigma_m:.3g} m beyond '
                                f'{MAX_COORDINATE_M:.0e} m')
    if max(abs(state.north), abs(state.east)) > MAX_COORDINATE_M:
        return 'out_of_range', (f'position ({state.north:.3g}, {state.east:.3g}) m beyond '
                                f'{MAX_COORDINATE_M:.0e} m from the origin')
    if state.speed > MAX_SPEED_MPS:
        return 'out_of_range', f'speed {state.speed:.3g} m/s above {MAX_SPEED_MPS:g} m/s'
    return None


class TargetTracks:
    """Targets by name: stamped states, the lockstep ones, silence and staleness (bounded: see
    the module docstring)."""

    def __init__(self, stale_after_s, max_targets=DEFAULT_MAX_TARGETS):
        if not (isinstance(max_targets, int) and max_targets >= 1):
            raise ValueError(f'max_targets must be an integer >= 1, got {max_targets!r}')
        self.stale_ns = to_ns(stale_after_s)
        self.max_targets = max_targets
        self._stamps = {}      # name -> sorted stamps (ns)
        self._states = {}      # name -> states in the same order
        self.lockstep = set()  # names that must be heard up to a decision's stamp
        self.last_heard = {}   # name -> monotonic wall time of the last message (node's clock)
        self.reference = (0.0, 0.0)   # own ship (north, east): the farthest target goes first
        self.refused = dict.fromkeys(REFUSED_REASONS, 0)
        self.last_refused = None      # (name, text) of the latest refusal, for warnings
        self.n_evicted = 0

    def __len__(self):
        return len(self._stamps)

    def _distance(self, state):
        return math.hypot(state.north - self.reference[0], state.east - self.reference[1])

    def _make_room(self, state):
        """Whether a new target at ``state`` gets a place: when the table is full, the farthest
        EVICT_FRACTION of it and the newcomer (lockstep targets excepted) leave, at least one,
        each counted in n_evicted; the newcomer stays if it is not among them."""
        if len(self._stamps) < self.max_targets:
            return True
        k = max(1, int(self.max_targets * EVICT_FRACTION))
        candidates = [(self._distance(states[-1]), name) for name, states in self._states.items()
                      if name not in self.lockstep]
        candidates.append((self._distance(state), None))
        far = heapq.nlargest(k, candidates, key=lambda c: c[0])
        self.n_evicted += len(far)
        for _, name in far:
            if name is not None:
                self.forget(name)
        return all(name is not None for _, name in far)

    def add(self, name, t_ns, state, wall=0.0, lockstep=False):
        """Keep ``state`` (a Target) stamped ``t_ns``; a repeated stamp replaces the earlier.
        Returns None if kept, else the reason (REFUSED_REASONS, counted in ``refused``, or
        'evicted': no place for a new target farther than every kept one)."""
        problem = target_problem(state)
        if problem is not None:
            self.refused[problem[0]] += 1
            self.last_refused = (name, problem[1])
            return problem[0]
        if name not in self._stamps and not lockstep and not self._make_room(state):
            return 'evicted'
        stamps = self._stamps.setdefault(name, [])
        states = self._states.setdefault(name, [])
        i = bisect.bisect_left(stamps, t_ns)
        if i < len(stamps) and stamps[i] == t_ns:
            states[i] = state
        else:
            stamps.insert(i, t_ns)
            states.insert(i, state)
            if len(stamps) > MAX_SAMPLES_PER_TARGET:
                del stamps[0], states[0]
        self.last_heard[name] = wall
        if lockstep:
            self.lockstep.add(name)
        return None

    def names(self):
        return sorted(self._stamps)

    def newest_ns(self, name):
        stamps = self._stamps.get(name)
        return stamps[-1] if stamps else None

    def waiting_for(self, t_ns, expected=()):
        """Lockstep targets (and ``expected`` names not heard yet) without a sample at or after
        ``t_ns``, sorted."""
        names = self.lockstep | set(expected)
        newest = {n: self.newest_ns(n) for n in names}
        return sorted(n for n in names if newest[n] is None or newest[n] < t_ns)

    def at(self, t_ns):
        """Targets (sorted by name) at ``t_ns``: each one's latest state stamped <= t_ns,
        dead-reckoned to t_ns; a target whose latest such state is older than the staleness
        limit, or that has none, is left out. Older states than the one used are forgotten, and
        so is a target whose newest state is stale (decisions go forward in time)."""
        out = []
        for name in self.names():
            stamps, states = self._stamps[name], self._states[name]
            if t_ns - stamps[-1] > self.stale_ns:
                self.forget(name)
                continue
            i = bisect.bisect_right(stamps, t_ns) - 1
            if i < 0:
                continue
            if i > 0:   # nothing older is needed again: decisions go forward in time
                del stamps[:i], states[:i]
            if t_ns - stamps[0] > self.stale_ns:
                continue
            out.append(dead_reckon(states[0], (t_ns - stamps[0]) / NS_PER_S))
        return out

    def forget(self, name):
        """Drop every trace of target ``name`` (stale, or shed from a full table)."""
        for table in (self._stamps, self._states, self.last_heard):
            table.pop(name, None)
        self.lockstep.discard(name)


class SyncedSource:
    """Completeness of a many-target topic with per-step announcements (``[stamp, count]``).

    Messages on one topic from one publisher arrive in order, and so do the announcements, but
    the two topics are not ordered against each other: a stamp is complete once its
    announcement has come and as many messages with that stamp as it announces, and every
    announced stamp before it is complete too."""

    def __init__(self):
        self._received = {}      # stamp (ns) -> messages received with it, not yet complete
        self._announced = []     # [(stamp ns, count)] in arrival (= stamp) order, not complete
        self.complete_ns = None  # every message stamped at or before this has arrived

    def received(self, t_ns):
        self._received[t_ns] = self._received.get(t_ns, 0) + 1
        self._advance()

    def announced(self, t_ns, count):
        self._announced.append((t_ns, count))
        self._advance()

    def _advance(self):
        done = 0
        for t_ns, count in self._announced:
            if self._received.get(t_ns, 0) < count:
                break
            self._received.pop(t_ns, None)
            self.complete_ns = t_ns
            done += 1
        del self._announced[:done]
        if self.complete_ns is not None and self._received:   # messages of completed stamps
            for t_ns in [t for t in self._received if t <= self.complete_ns]:
                del self._received[t_ns]

    def ready(self, t_ns):
        """Whether every message stamped at or before ``t_ns`` has arrived."""
        return self.complete_ns is not None and self.complete_ns >= t_ns


class DecisionSchedule:
    """Decide at the first stamp and then at the first stamp at least ``period_s`` after the
    previous decision."""

    def __init__(self, period_s):
        self.period_ns = to_ns(period_s)
        self.next_ns = None

    def due(self, t_ns):
        return self.next_ns is None or t_ns >= self.next_ns

    def decided(self, t_ns):
        self.next_ns = t_ns + self.period_ns


def keeps_nominal_course(decision):
    return decision is None or decision.course_offset == 0.0


def command_yaw(nominal_yaw, decision):
    """ENU yaw command: ``nominal_yaw`` itself when the decision keeps the nominal course, else
    the nominal course (NED) plus the decision's offset (+ starboard), wrapped, in ENU."""
    if keeps_nominal_course(decision):
        return nominal_yaw
    return float(psi_to_yaw(wrap_angle(yaw_to_psi(nominal_yaw) + decision.course_offset)))


def speed_factor(nominal, decision):
    return nominal if decision is None or decision.speed_multiplier == 1.0 else \
        decision.speed_multiplier * nominal


def target_rows(own, targets, decision):
    """Flat list, one row of TARGET_COLUMNS per target (input order): TCPA (s), DCPA (m),
    situation code (colregs), role code (ROLE_CODES), range (m) and relative bearing (rad,
    [0, 2 pi), clockwise from the own bow)."""
    if not targets:
        return []
    p_own = np.array([own.north, own.east])
    p_tgt = np.array([[tg.north, tg.east] for tg in targets])
    rng, _ = range_and_bearing(p_own, p_tgt)
    heading = own.course if own.heading is None else own.heading
    beta = colregs.relative_bearing(p_own, heading, p_tgt)
    rows = []
    for i, a in enumerate(decision.targets):
        rows += [a.tcpa_s, a.dcpa_m, float(colregs.SITUATIONS.index(a.situation)),
                 float(ROLE_CODES[a.role]), float(rng[i]), float(beta[i])]
    return rows


class RefHold:
    """The nominal heading to use: a finite ``heading_ref`` itself, else the last finite one
    (None before any), the refusal counted in ``n_refused``."""

    def __init__(self):
        self.last = None
        self.n_refused = 0

    def update(self, ref):
        """``ref`` if finite (and kept), else the last finite one (None if none yet)."""
        if math.isfinite(ref):
            self.last = ref
            return ref
        self.n_refused += 1
        return self.last


def decision_row(t_s, decision, n_targets):
    return [t_s, float(MODE_CODES[decision.mode]), decision.course_offset,
            decision.speed_multiplier, float(decision.threat), float(n_targets)]
