"""Encounter parameterisation of the failure search, and its geometry.

A parameter vector ``x`` lies in the unit box [0, 1]^D (the samplers work there); ``decode``
maps it onto the physical box ``BOX``:

- ``n_targets`` 1-3 (a categorical parameter, kept apart from ``x``);
- ``meeting_s`` T: the time of the meeting, common to all targets (300-900 s, so a run is short);
- per target slot j (the slots beyond n_targets are ignored):
  ``course_rel_deg`` the target's course relative to the own course (circular),
  ``speed_ratio`` its speed over the own speed,
  ``cpa_m`` d, its signed unmanoeuvred CPA offset.

Geometry (NED; the own ship of the Imazu set: at the origin on course 000 at 12 kn, straight):
with own velocity v_o and target velocity v_t, the relative velocity w = v_t - v_o and its unit
vector u = w / |w|. The target is placed so that, unmanoeuvred, it is at

    p_o(T) + d n,    n = (u_e, -u_n)  (the bearing of w minus 90 deg)

at time T, and starts at p_t(0) = p_o(T) + d n - v_t T. Its position relative to the own ship is
then r(t) = w (t - T) + d n, and n is perpendicular to w: the closest approach is at T, at
distance |d|. This is the miss shift scripts/montecarlo/encounters.py applies to a perturbed
Imazu case (d > 0 puts the target to starboard in head-on and overtaking, astern of the own
ship for one crossing from starboard). With d = 0 the target stays on a constant bearing, the
direction of -w from the own bow: the ``approach_bearing_deg`` recorded with every encounter
(the relative bearing at the meeting follows from course and speed, so it is derived, not a
parameter of its own).

A target that starts within ``MIN_START_RANGE_M`` of the own ship (course and speed close to
the own ship's: the relative speed times T is short) is no encounter; such vectors are outside
the search's region and both samplers draw again (rejection), so both search the same region.
"""
import math
from dataclasses import dataclass

import numpy as np

#: The own ship of every encounter: the Imazu set's (imazu/imazu22_cases.json).
OWN = {'north_m': 0.0, 'east_m': 0.0, 'course_deg': 0.0, 'speed_mps': 6.1733}
MAX_TARGETS = 3
TARGET_COUNTS = (1, 2, 3)
#: (name, low, high, circular) of the meeting time and of each target slot's parameters.
MEETING = ('meeting_s', 300.0, 900.0, False)
PER_TARGET = (('course_rel_deg', -180.0, 180.0, True),
              ('speed_ratio', 0.3, 1.6, False),
              ('cpa_m', -1000.0, 1000.0, False))
#: A target starting closer than this (1 NM) is not an encounter (module docstring).
MIN_START_RANGE_M = 1852.0
#: Dimension of x: the meeting time, then the slots' parameters.
DIM = 1 + MAX_TARGETS * len(PER_TARGET)


def circular_dims():
    """Boolean mask of the circular dimensions of x (the relative courses)."""
    return np.array([MEETING[3]] + [p[3] for _ in range(MAX_TARGETS) for p in PER_TARGET])


def slot_dims(j):
    """Indices into x of target slot ``j``'s parameters."""
    return list(range(1 + j * len(PER_TARGET), 1 + (j + 1) * len(PER_TARGET)))


def _scale(u, spec):
    _, low, high, _ = spec
    return low + float(u) * (high - low)


@dataclass(frozen=True)
class Target:
    course_rel_deg: float
    speed_ratio: float
    cpa_m: float


@dataclass(frozen=True)
class Encounter:
    meeting_s: float
    targets: tuple     # of Target


def decode(n_targets, x):
    """The Encounter of target count ``n_targets`` and unit vector ``x`` (length DIM)."""
    x = np.asarray(x, dtype=float)
    targets = tuple(Target(*(_scale(x[i], spec) for i, spec in zip(slot_dims(j), PER_TARGET)))
                    for j in range(int(n_targets)))
    return Encounter(_scale(x[0], MEETING), targets)


def _velocity(course_deg, speed):
    c = math.radians(course_deg)
    return np.array([math.cos(c), math.sin(c)]) * speed


def target_state(encounter, target, own=OWN):
    """(start north, east, course deg, speed m/s, approach bearing deg) of ``target``."""
    v_o = _velocity(own['course_deg'], own['speed_mps'])
    course = (own['course_deg'] + target.course_rel_deg) % 360.0
    speed = target.speed_ratio * own['speed_mps']
    v_t = _velocity(course, speed)
    w = v_t - v_o
    u = w / np.hypot(*w)
    n = np.array([u[1], -u[0]])
    T = encounter.meeting_s
    p = np.array([own['north_m'], own['east_m']]) + v_o * T + target.cpa_m * n - v_t * T
    bearing = (math.degrees(math.atan2(-w[1], -w[0])) - own['course_deg']) % 360.0
    return float(p[0]), float(p[1]), course, speed, bearing


def start_range(encounter, target, own=OWN):
    north, east, *_ = target_state(encounter, target, own)
    return math.hypot(north - own['north_m'], east - own['east_m'])


def feasible(n_targets, x):
    """True if every target of the encounter starts at least MIN_START_RANGE_M away."""
    e = decode(n_targets, x)
    return all(start_range(e, t) >= MIN_START_RANGE_M for t in e.targets)


def situation(north, east, course_deg, speed, own=OWN):
    """The COLREGs situation of a target at the start, seen from the own ship (colregs.classify
    on the first sample, as the evaluator classifies it)."""
    from ship_guidance import colregs
    p_o = np.array([own['north_m'], own['east_m']])
    c_o = math.radians(own['course_deg'])
    c_t = math.radians(course_deg)
    code = colregs.classify(p_o, c_o, _velocity(own['course_deg'], own['speed_mps']),
                            np.array([north, east]), c_t, _velocity(course_deg, speed))
    return colregs.SITUATIONS[int(code)]


def case_of(n_targets, x, own=OWN):
    """The encounter as a case dict (imazu.runner.case_scenario's ``case``: own, targets with
    name ts1.., start, course, speed, colregs), each target with its approach bearing."""
    e = decode(n_targets, x)
    targets = []
    for j, t in enumerate(e.targets):
        north, east, course, speed, bearing = target_state(e, t, own)
        targets.append({'name': f'ts{j + 1}', 'north_m': north, 'east_m': east,
                        'course_deg': course, 'speed_mps': speed,
                        'colregs': situation(north, east, course, speed, own),
                        'approach_bearing_deg': bearing})
    return {'own': dict(own), 'targets': targets}


def describe(n_targets, x):
    """A dict of the physical parameters (for the results file)."""
    e = decode(n_targets, x)
    case = case_of(n_targets, x)
    return {'n_targets': int(n_targets), 'meeting_s': e.meeting_s,
            'targets': [{'course_rel_deg': t.course_rel_deg, 'speed_ratio': t.speed_ratio,
                         'cpa_m': t.cpa_m, 'approach_bearing_deg': c['approach_bearing_deg'],
                         'situation': c['colregs']}
                        for t, c in zip(e.targets, case['targets'])]}
