"""Light traffic: target ships that move on given tracks, no dynamics (issue 13, item 1).

A light target is either constant course and speed from a start point, or a list of timed
waypoints joined by straight legs (position piecewise linear in time). Each target is stored as
its legs: leg j starts at time T[j] at position P[j] with the constant velocity V[j]; the state
at time t is P[k] + V[k] (t - T[k]) for the last leg with T[k] <= t, a closed form (no
integration, no drift). Before its first waypoint time a target moves on its first leg's
velocity, after the last one on its last leg's velocity (it keeps going, as a ship would).

Frames: NED (north, east, course clockwise from north) like every pure module (ship_sim.frames);
``parse_targets`` reads the scenario / node parameter form, which is ENU (x east, y north)
like the rest of a scenario, course clockwise from north like ``current.direction_deg``.

Behaviour (optional key ``behaviour``, issue 31 item 4): how a target reacts to the others,
one of BEHAVIOURS (default ``straight``), described with its trigger and rule breach in
ship_guidance.reacting_traffic. This module moves targets in closed form from the time alone,
so it takes only the behaviours that move so (``straight``, and ``no_alteration``: a head-on or
give-way target that never alters); the others need the other ships' states at every step and
are refused here with the reason (the in-process Imazu runner moves them).

Bounds (ship_sim.bounds): positions within MAX_COORDINATE_M of the origin and speeds (given, or
of each leg between waypoints) at most MAX_SPEED_MPS; a target beyond them is refused.
"""
import math

import numpy as np

from ship_sim.bounds import MAX_COORDINATE_M, MAX_SPEED_MPS
from ship_sim.safe_load import InputError, load_json, ros_name_problem


#: Target behaviours (ship_guidance.reacting_traffic documents each): the one list of names.
BEHAVIOURS = ('straight', 'reciprocal', 'turns_to_port', 'no_alteration')
#: Behaviours a light target moves by in closed form (no other ship's state needed).
CLOSED_FORM = ('straight', 'no_alteration')


def behaviour_problem(value):
    """None if ``value`` is a behaviour a light target can have here, else one line why not."""
    if value not in BEHAVIOURS:
        return f'behaviour {value!r} unknown; one of {", ".join(BEHAVIOURS)}'
    if value not in CLOSED_FORM:
        return (f'behaviour {value!r} needs the other ships\' states at every step, and light '
                'targets move in closed form from the clock alone (traffic_node); only '
                f'{", ".join(CLOSED_FORM)} here (scripts/imazu_behaviours.py runs the others)')
    return None


class LightTraffic:
    """N light targets; ``state(t)`` gives all of them at once (arrays of length N)."""

    def __init__(self, names, legs):
        """names: N distinct strings; legs: per target (T, P, V) with T (m,), P and V (m, 2),
        or (T, P, V, course) with the course (m,) of each leg given (a target at rest)."""
        if len(names) != len(legs):
            raise ValueError(f'{len(names)} names for {len(legs)} targets')
        if len(set(names)) != len(names):
            raise ValueError(f'target names must be distinct, got {list(names)}')
        self.names = list(names)
        m = max((len(leg[0]) for leg in legs), default=1)
        n = len(legs)
        self._t = np.full((n, m), np.inf)   # padding never becomes the current leg
        self._p = np.zeros((n, m, 2))
        self._v = np.zeros((n, m, 2))
        self._course = np.zeros((n, m))
        for i, leg in enumerate(legs):
            t, p, v = leg[:3]
            k = len(t)
            self._t[i, :k] = t
            self._p[i, :k] = p
            self._v[i, :k] = v
            self._course[i, :k] = _leg_courses(v) if len(leg) == 3 else leg[3]
        self._t[:, 0] = np.where(np.isfinite(self._t[:, 0]), self._t[:, 0], 0.0)

    def __len__(self):
        return len(self.names)

    def state(self, t):
        """(north, east, course, speed) arrays at time t (s): m, m, rad in [-pi, pi), m/s."""
        t = float(t)
        if not math.isfinite(t):
            raise ValueError(f'time must be finite, got {t}')
        rows = np.arange(len(self.names))
        k = np.maximum(np.sum(self._t <= t, axis=1) - 1, 0)
        t0 = self._t[rows, k]
        v = self._v[rows, k]
        pos = self._p[rows, k] + v * (t - t0)[:, None]
        speed = np.hypot(v[:, 0], v[:, 1])
        return pos[:, 0], pos[:, 1], self._course[rows, k], speed


def _leg_courses(v):
    """Course of each leg (rad, NED); a leg at rest keeps the course of the leg before it (or
    the first moving leg after it; 0 if the target never moves)."""
    speed = np.hypot(v[:, 0], v[:, 1])
    course = np.arctan2(v[:, 1], v[:, 0])
    moving = np.flatnonzero(speed > 0.0)
    if moving.size == 0:
        return np.zeros(len(v))
    out = np.empty(len(v))
    last = course[moving[0]]
    for j in range(len(v)):
        if speed[j] > 0.0:
            last = course[j]
        out[j] = last
    return (out + np.pi) % (2.0 * np.pi) - np.pi


def _finite(values, what):
    a = np.asarray(values, dtype=float)
    if not np.all(np.isfinite(a)):
        raise ValueError(f'{what} must be finite numbers, got {values!r}')
    return a


def constant_legs(north, east, course, speed, t0=0.0):
    """Legs of a target at (north, east) at time t0 (s), course (rad, NED), speed (m/s); the
    course is kept as given, also at speed 0."""
    north, east, course, speed, t0 = _finite([north, east, course, speed, t0],
                                             'start, course, speed and time')
    if not 0.0 <= speed <= MAX_SPEED_MPS:
        raise ValueError(f'speed must be in [0, {MAX_SPEED_MPS:g}] m/s, got {speed:g}')
    _check_positions([[north, east]])
    v = speed * np.array([[math.cos(course), math.sin(course)]])
    wrapped = (course + math.pi) % (2.0 * math.pi) - math.pi
    return np.array([t0]), np.array([[north, east]]), v, np.array([wrapped])


def waypoint_legs(times, north, east):
    """Legs through timed waypoints (times strictly increasing, at least two points)."""
    t = _finite(times, 'waypoint times')
    p = np.stack([_finite(north, 'waypoint north'), _finite(east, 'waypoint east')], axis=1)
    if t.ndim != 1 or len(t) < 2 or len(p) != len(t):
        raise ValueError(f'waypoints: at least two (t, position) points, got {len(t)}')
    dt = np.diff(t)
    if np.any(dt <= 0.0):
        j = int(np.argmax(dt <= 0.0))
        raise ValueError(f'waypoint times must increase strictly: t[{j + 1}] = {t[j + 1]} '
                         f'after t[{j}] = {t[j]}')
    _check_positions(p)
    v = np.diff(p, axis=0) / dt[:, None]
    speed = np.hypot(v[:, 0], v[:, 1])
    if not np.all(speed <= MAX_SPEED_MPS):
        j = int(np.argmax(~(speed <= MAX_SPEED_MPS)))
        raise ValueError(f'leg {j + 1} (waypoints {j} to {j + 1}) runs at {speed[j]:.3g} m/s; '
                         f'at most {MAX_SPEED_MPS:g} m/s is physical')
    v = np.vstack([v, v[-1:]])   # after the last waypoint: the last leg's velocity
    return t, p, v


def _check_positions(p):
    far = np.max(np.abs(np.asarray(p, dtype=float)), axis=1)
    if not np.all(far <= MAX_COORDINATE_M):
        j = int(np.argmax(~(far <= MAX_COORDINATE_M)))
        raise ValueError(f'position {j} is {far[j]:.6g} m from the origin; at most '
                         f'{MAX_COORDINATE_M:.0e} m is physical')


def make_traffic(targets):
    """LightTraffic from a list of target dicts (``parse_targets``'s schema)."""
    if not isinstance(targets, list):
        raise ValueError(f'light targets: a list of mappings, got {type(targets).__name__}')
    names, legs = [], []
    for i, d in enumerate(targets):
        where = f'light target {i}'
        if not isinstance(d, dict):
            raise ValueError(f'{where}: a mapping, got {d!r}')
        name = d.get('name')
        bad = ros_name_problem(name)       # the name makes the topic /<name>/odom
        if bad:
            raise ValueError(f'{where}: name {bad}')
        where = f'light target {name}'
        keys = set(d) - {'name', 'behaviour'}
        const = {'x_m', 'y_m', 'course_deg', 'speed_mps'}
        try:
            bad = behaviour_problem(d.get('behaviour', 'straight'))
            if bad:
                raise ValueError(bad)
            if keys == {'waypoints'}:
                w = d['waypoints']
                if not (isinstance(w, list) and all(isinstance(r, (list, tuple)) and len(r) == 3
                                                    for r in w)):
                    raise ValueError(f'waypoints: a list of [t_s, x_m, y_m], got {w!r}')
                t, x, y = zip(*w) if w else ((), (), ())
                legs.append(waypoint_legs(_numbers(t), _numbers(y), _numbers(x)))
            elif keys <= const and {'course_deg', 'speed_mps'} <= keys:
                x, y, c, v = _numbers([d.get('x_m', 0.0), d.get('y_m', 0.0),
                                       d['course_deg'], d['speed_mps']])
                leg = constant_legs(y, x, math.radians(c), v)
                legs.append(leg)
            else:
                raise ValueError(f'keys {sorted(keys)}: give either waypoints, or course_deg, '
                                 'speed_mps and optionally x_m, y_m')
        except ValueError as exc:
            raise ValueError(f'{where}: {exc}') from None
        names.append(name)
    return LightTraffic(names, legs)


def _numbers(values):
    """Floats of ``values``; booleans and text are refused (YAML 'yes' is not a number)."""
    out = []
    for v in values:
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise ValueError(f'a number, got {v!r}')
        out.append(float(v))
    return _finite(out, 'values')


def parse_targets(text):
    """LightTraffic from the JSON text of traffic_node's ``targets`` parameter: a list of
    ``{name, x_m, y_m, course_deg, speed_mps}`` (constant course and speed from (x_m, y_m) ENU
    at t = 0) or ``{name, waypoints: [[t_s, x_m, y_m], ...]}`` (ENU, times strictly
    increasing), either with an optional ``behaviour`` (``behaviour_problem``). Raises
    ValueError naming the target and the problem."""
    try:
        data = load_json(text)       # bounded: nesting, number length, keys given twice
    except InputError as exc:
        raise ValueError(f'light targets: {exc}') from None
    return make_traffic(data)
