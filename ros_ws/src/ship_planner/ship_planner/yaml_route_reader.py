"""Read a route from a YAML route file into a RoutePlan (ship_guidance.path.Route in NED + metadata).

The schema (a commented example: ship_planner/config/routes/example_enu.yaml):

    name: harbour_approach            # required, text
    source: "where it comes from"     # required, text: a citation or "designed for ..., by ..."
    description: "..."                # optional, text
    frame: enu                        # required: enu | wgs84
    origin: {lat_deg: 59.9, lon_deg: 10.7}   # required for wgs84; optional for enu (geo-reference only)
    fillet_radius_m: 1000             # optional, >= 0: round every corner between two straight legs
    turn_rudder_deg: 20               # optional, instead of fillet_radius_m: every corner's radius is
    turn_model: mariner               #   the steady turning radius of this plant model (ship_sim.models,
                                      #   default parameters) at this rudder angle, per turn direction
                                      #   (Lee 2004, Fig. 4.5; ship_planner.fillets.rudder_turn_radius)
    arc_tolerance_m: 0.1              # optional, > 0: how far an arc's end may be off its circle

    # the geometry: exactly one of `waypoints`, `start` + `legs`, `curve`
    waypoints:                        # straight legs through >= 2 points
      - [0, 0]                        # enu: [x_m (east), y_m (north)];  wgs84: [lat_deg, lon_deg]
      - {x_m: 1000, y_m: 0, fillet_radius_m: 500, name: buoy A}  # mapping form, per-corner fillet
    start: [0, 0]                     # first point of `legs`
    legs:
      - {to: [1000, 0]}                         # straight leg to a point (type: line is the default)
      - {course_deg: 45, length_m: 800}         # straight leg by course (clockwise from north) and length
      - type: arc
        center: [1500, 1000]                    # point
        direction: counterclockwise             # seen from above: clockwise (= starboard) | counterclockwise (= port)
        to: [2000, 1500]                        # end point on the circle, or instead:
        # sweep_deg: 90                         # angle turned (> 0, < 360)
    curve:                            # a parametric curve, sampled densely (ship_guidance.curves)
      type: sine                      # sine | circle | spline
      # sine:   start (point, default origin), course_deg (base line, default 0), length_m,
      #         amplitude_m (offset to starboard of the base line), wavelength_m, phase_deg (0), step_m (10)
      # circle: center, radius_m, start_bearing_deg (start point's bearing from the centre),
      #         sweep_deg (> 0; more than 360 makes several turns), direction
      # spline: points (>= 2), step_m (10)

Points: in frame enu a point is [x_m, y_m] or {x_m, y_m} (x east, y north, metres from the local
origin); in frame wgs84 it is [lat_deg, lon_deg] or {lat_deg, lon_deg}, converted to the tangent
plane at `origin` (ship_sim.geodetic). Every waypoint or leg may carry
`name` (used in messages). A leg's `fillet_radius_m` (or a waypoint's) applies to the corner at
its end and overrides the global one (0 keeps that corner sharp).

Errors raise RouteError "<file>:<line>: <what>", with the line of the offending YAML node (from
PyYAML's node marks): unknown or missing keys, wrong types, NaN/inf, fewer than 2 points,
zero-length legs, arcs whose end is not on their circle (both distances given), fillets that
do not fit (the corner and the largest radius that fits), points beyond MAX_COORDINATE_M
(1e7 m) from the origin, routes or curves beyond MAX_ROUTE_LENGTH_M / MAX_ROUTE_SAMPLES, and
files that are not regular files, too large or not UTF-8 (ship_planner.route_data).

Numbers: YAML 1.1 (PyYAML) reads ``1e9`` (no dot) as text; ``Loader`` (ship_sim.safe_load, the
bounded reader of every input file: nesting, aliases, number length, duplicate keys) reads it
as the number YAML 1.2 and every reader would see.

Frames: files are ENU (x east, y north) like the ROS topics; the Route is NED (north, east)
like every pure module (conversion by ship_sim.frames.enu_to_ned_xy).
"""
import difflib
import math

import numpy as np
import yaml

from ship_guidance import curves
from ship_planner.fillets import (ArcSpec, FilletError, LineSpec, fillet_segments, rudder_turn_radius,
                                  segments_to_route)
from ship_sim.geodetic import geodetic_to_ned
from ship_planner.route_data import RouteError, RoutePlan, check_point, check_route_size
from ship_sim.frames import enu_to_ned_xy
# The bounded reader of every input file (Loader: ``1e9`` is a number; bounds on depth,
# aliases, number length and duplicate keys).
from ship_sim.safe_load import InputError, Loader, TextFileError, compose_yaml, read_text_file  # noqa: F401

FRAMES = ('enu', 'wgs84')
TOP_KEYS = ('name', 'source', 'description', 'frame', 'origin', 'fillet_radius_m', 'turn_rudder_deg',
            'turn_model', 'arc_tolerance_m', 'waypoints', 'start', 'legs', 'curve')
LEG_KEYS = ('type', 'name', 'to', 'course_deg', 'length_m', 'center', 'direction', 'sweep_deg',
            'fillet_radius_m')
DIRECTIONS = {'clockwise': True, 'starboard': True, 'counterclockwise': False, 'port': False}
CURVE_KEYS = {
    'sine': ('type', 'start', 'course_deg', 'length_m', 'amplitude_m', 'wavelength_m', 'phase_deg', 'step_m'),
    'circle': ('type', 'center', 'radius_m', 'start_bearing_deg', 'sweep_deg', 'direction'),
    'spline': ('type', 'points', 'step_m'),
}
CURVE_REQUIRED = {
    'sine': ('length_m', 'amplitude_m', 'wavelength_m'),
    'circle': ('center', 'radius_m', 'start_bearing_deg', 'sweep_deg', 'direction'),
    'spline': ('points',),
}
DEFAULT_ARC_TOLERANCE_M = 0.1
DEFAULT_STEP_M = 10.0
_SAME_POINT_M = 1e-6          # consecutive points closer than this make a zero-length leg


_CONSTRUCTOR = yaml.constructor.SafeConstructor()


def load_route_yaml(path):
    """Read and validate a YAML route file. Returns a RoutePlan; raises RouteError."""
    path = str(path)
    try:
        text = read_text_file(path)
    except TextFileError as exc:
        raise RouteError(f'cannot read the route file: {exc.detail}', file=path, line=exc.line) from None
    plan = parse_route_yaml(text, path)
    plan.file = path
    return plan


def parse_route_yaml(text, filename='<string>'):
    """Validate YAML route text (see the module docstring). filename is used in messages."""
    return _Reader(filename).read(text)


class _Reader:
    """One pass over the composed YAML node tree; keeps the file name for error messages."""

    def __init__(self, filename):
        self.file = filename
        self.frame = None                          # 'enu' | 'wgs84', set from the file
        self.origin = None                         # (lat_deg, lon_deg) or None
        self.description = None
        self.fillet = 0.0                          # global fillet radius (m); 0 = sharp corners
        self.turn = None                           # (model name, rudder deg): radius from the steady turn
        self.arc_tol = DEFAULT_ARC_TOLERANCE_M

    # ---- low-level node access -------------------------------------------------------------
    def err(self, node, detail):
        line = node.start_mark.line + 1 if node is not None else None
        return RouteError(detail, file=self.file, line=line)

    def mapping(self, node, what, required=(), allowed=()):
        """{key: value node} of a YAML mapping, checking required and unknown keys."""
        if not isinstance(node, yaml.MappingNode):
            raise self.err(node, f'{what} must be a mapping of "key: value" entries, got {_kind(node)}')
        out = {}
        for knode, vnode in node.value:
            key = _CONSTRUCTOR.construct_object(knode) if isinstance(knode, yaml.ScalarNode) else None
            if not isinstance(key, str):
                raise self.err(knode, f'{what}: keys must be words, got {_kind(knode)}')
            if key in out:
                raise self.err(knode, f'{what}: key "{key}" is given twice')
            if key not in allowed:
                hint = difflib.get_close_matches(key, allowed, n=1)
                hint = f' (did you mean "{hint[0]}"?)' if hint else ''
                raise self.err(knode, f'{what}: unknown key "{key}"{hint}; allowed keys: {", ".join(allowed)}')
            out[key] = vnode
        for key in required:
            if key not in out:
                raise self.err(node, f'{what}: missing required key "{key}"')
        return out

    def sequence(self, node, what):
        if not isinstance(node, yaml.SequenceNode):
            raise self.err(node, f'{what} must be a list, got {_kind(node)}')
        return node.value

    def scalar(self, node, what):
        if not isinstance(node, yaml.ScalarNode):
            raise self.err(node, f'{what} must be a single value, got {_kind(node)}')
        return _CONSTRUCTOR.construct_object(node)

    def text(self, node, what):
        v = self.scalar(node, what)
        if not isinstance(v, str) or not v.strip():
            raise self.err(node, f'{what} must be non-empty text, got {v!r} (quote it if needed)')
        return v.strip()

    def number(self, node, what, minimum=None, positive=False, maximum=None):
        v = self.scalar(node, what)
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise self.err(node, f'{what} must be a number, got {v!r}')
        v = float(v)
        if not math.isfinite(v):
            raise self.err(node, f'{what} must be finite, got {v}')
        if positive and v <= 0.0:
            raise self.err(node, f'{what} must be > 0, got {v:g}')
        if minimum is not None and v < minimum:
            raise self.err(node, f'{what} must be >= {minimum:g}, got {v:g}')
        if maximum is not None and v > maximum:
            raise self.err(node, f'{what} must be <= {maximum:g}, got {v:g}')
        return v

    def choice(self, node, what, options):
        v = self.scalar(node, what)
        if not isinstance(v, str) or v not in options:
            raise self.err(node, f'{what} must be one of {", ".join(options)}, got {v!r}')
        return v

    # ---- points ----------------------------------------------------------------------------
    def point(self, node, what, extra=()):
        """A point in the file's frame -> ((north, east) NED m, {extra key: node})."""
        keys = ('x_m', 'y_m') if self.frame == 'enu' else ('lat_deg', 'lon_deg')
        if isinstance(node, yaml.SequenceNode):
            items = node.value
            if len(items) != 2:
                raise self.err(node, f'{what} must be [{keys[0]}, {keys[1]}], got a list of {len(items)} values')
            a = self.number(items[0], f'{what} {keys[0]}')
            b = self.number(items[1], f'{what} {keys[1]}')
            extras = {}
        elif isinstance(node, yaml.MappingNode):
            m = self.mapping(node, what, required=keys, allowed=keys + tuple(extra))
            a = self.number(m[keys[0]], f'{what} {keys[0]}')
            b = self.number(m[keys[1]], f'{what} {keys[1]}')
            extras = {k: v for k, v in m.items() if k not in keys}
        else:
            raise self.err(node, f'{what} must be [{keys[0]}, {keys[1]}] or a mapping with {keys[0]} and {keys[1]}, '
                                 f'got {_kind(node)}')
        if self.frame == 'enu':
            north, east = enu_to_ned_xy(a, b)
            bad = check_point(north, east, what)
            if bad:
                raise self.err(node, bad)
        else:
            if not -90.0 <= a <= 90.0:
                raise self.err(node, f'{what} lat_deg must be within [-90, 90], got {a:g}')
            if not -180.0 <= b <= 360.0:
                raise self.err(node, f'{what} lon_deg must be within [-180, 360], got {b:g}')
            north, east = geodetic_to_ned(a, b, *self.origin)
            if math.hypot(north, east) > 60e3:
                raise self.err(node, f'{what} is {math.hypot(north, east) / 1e3:.0f} km from the origin; '
                                     'the local tangent plane is good to < 1 m only within ~60 km')
        return (float(north), float(east)), extras

    # ---- document --------------------------------------------------------------------------
    def read(self, text):
        try:
            root = compose_yaml(text)
        except InputError as exc:
            raise RouteError(exc.detail, file=self.file, line=exc.line) from None
        if root is None:
            raise RouteError('the route file is empty', file=self.file)
        top = self.mapping(root, 'route file', required=('name', 'source', 'frame'), allowed=TOP_KEYS)
        name = self.text(top['name'], 'name')
        source = self.text(top['source'], 'source')
        self.frame = self.choice(top['frame'], 'frame', FRAMES)
        self.description = self.text(top['description'], 'description') if 'description' in top else None
        if 'origin' in top:
            keys = ('lat_deg', 'lon_deg')
            o = self.mapping(top['origin'], 'origin', required=keys, allowed=keys)
            lat = self.number(o['lat_deg'], 'origin lat_deg', minimum=-89.0, maximum=89.0)
            lon = self.number(o['lon_deg'], 'origin lon_deg', minimum=-180.0, maximum=360.0)
            self.origin = (lat, lon)
        elif self.frame == 'wgs84':
            raise self.err(top['frame'], 'frame wgs84 needs an "origin: {lat_deg: .., lon_deg: ..}" '
                                         'for the local plane')
        self.fillet = self.number(top['fillet_radius_m'], 'fillet_radius_m', minimum=0.0) \
            if 'fillet_radius_m' in top else 0.0
        self.arc_tol = self.number(top['arc_tolerance_m'], 'arc_tolerance_m', positive=True) \
            if 'arc_tolerance_m' in top else DEFAULT_ARC_TOLERANCE_M
        self.read_turn(top)

        forms = [k for k in ('waypoints', 'legs', 'curve') if k in top]
        if len(forms) != 1:
            raise self.err(root, 'give the geometry as exactly one of "waypoints", "start" + "legs", or "curve"'
                                 + (f' (found {", ".join(forms)})' if forms else ''))
        form = forms[0]
        if ('start' in top) != (form == 'legs'):
            raise self.err(top.get('start', top[form]), '"start" goes with "legs" (and only with it)'
                           if 'start' in top else '"legs" needs a "start" point')
        if form == 'curve' and 'fillet_radius_m' in top:
            raise self.err(top['fillet_radius_m'], 'fillet_radius_m applies to corners between straight legs, '
                                                  'not to a curve')
        if form == 'waypoints':
            segments, radii, labels, corner_lines, points = self.waypoints(top['waypoints'])
        elif form == 'legs':
            segments, radii, labels, corner_lines, points = self.legs(top['start'], top['legs'])
        else:
            route, points = self.curve(top['curve'])
            return self.plan(route, name, source, points, top['curve'])
        if self.turn is not None:
            radii = self.turn_radii(segments, radii, top['turn_rudder_deg'])
        try:
            segments = fillet_segments(segments, radii, labels)
        except FilletError as exc:
            raise RouteError(str(exc), file=self.file, line=corner_lines[exc.corner]) from None
        return self.plan(self.build(segments, top[form]), name, source, points, top[form])

    def read_turn(self, top):
        """turn_rudder_deg + turn_model: corners rounded with the model's steady turning radius."""
        given = [k for k in ('turn_rudder_deg', 'turn_model') if k in top]
        if not given:
            return
        if len(given) == 1:
            other = 'turn_model' if given[0] == 'turn_rudder_deg' else 'turn_rudder_deg'
            raise self.err(top[given[0]], f'{given[0]} needs {other} too (the radius is the steady turn of '
                                          'that model at that rudder angle)')
        for clash in ('fillet_radius_m', 'curve'):
            if clash in top:
                raise self.err(top['turn_rudder_deg'], f'turn_rudder_deg sets the corners\' radius; it cannot go '
                                                       f'with {clash}')
        from ship_sim.models import MODEL_NAMES
        model = self.choice(top['turn_model'], 'turn_model', MODEL_NAMES)
        rudder = self.number(top['turn_rudder_deg'], 'turn_rudder_deg', positive=True)
        self.turn = (model, rudder)
        self.fillet = None                          # marks corners without their own radius

    def turn_radii(self, segments, radii, node):
        """Each unset corner's radius: the steady turn to its side at the chosen rudder."""
        model, rudder = self.turn
        out = []
        for j, r in enumerate(radii):
            a, b = segments[j], segments[j + 1]
            if r is not None or not (isinstance(a, LineSpec) and isinstance(b, LineSpec)):
                out.append(r)
                continue
            ua = math.atan2(a.end[1] - a.start[1], a.end[0] - a.start[0])
            ub = math.atan2(b.end[1] - b.start[1], b.end[0] - b.start[0])
            turn = math.remainder(ub - ua, 2.0 * math.pi)
            if abs(turn) < 1e-9:
                out.append(0.0)
                continue
            try:
                out.append(rudder_turn_radius(model, rudder, turn > 0.0))
            except ValueError as exc:
                raise self.err(node, f'turn_rudder_deg: {exc}') from None
        return out

    def plan(self, route, name, source, points, node):
        bad = check_route_size(route)
        if bad:
            raise self.err(node, bad)
        lat, lon = self.origin if self.origin is not None else (None, None)
        return RoutePlan(route=route, name=name, source=source, frame=self.frame, origin_lat_deg=lat,
                         origin_lon_deg=lon, waypoints_ned=np.asarray(points, dtype=float).reshape(-1, 2),
                         file=None if self.file == '<string>' else self.file,
                         extras={'description': self.description} if self.description else {})

    def build(self, segments, node):
        try:
            return segments_to_route(segments)
        except ValueError as exc:
            raise self.err(node, f'the route could not be built: {exc}') from None

    # ---- geometry forms --------------------------------------------------------------------
    def waypoints(self, node):
        items = self.sequence(node, 'waypoints')
        if len(items) < 2:
            raise self.err(node, f'a route needs at least 2 waypoints, got {len(items)}')
        pts, labels, lines, radii = [], [], [], []
        for i, item in enumerate(items):
            what = f'waypoint {i + 1}'
            p, extra = self.point(item, what, extra=('name', 'fillet_radius_m'))
            label = self.label(what, extra, item)
            if pts and _same(p, pts[-1]):
                raise self.err(item, f'{label} repeats the previous waypoint {_fmt_point(self, p)}: zero-length leg')
            r = None
            if 'fillet_radius_m' in extra:
                r = self.number(extra['fillet_radius_m'], f'{what} fillet_radius_m', minimum=0.0)
                if i in (0, len(items) - 1):
                    raise self.err(extra['fillet_radius_m'],
                                   f'{what} is an end of the route: it has no corner to round')
            pts.append(p)
            labels.append(label)
            lines.append(item.start_mark.line + 1)
            radii.append(self.fillet if r is None else r)
        segments = [LineSpec(pts[i], pts[i + 1], f'the leg from {labels[i]} to {labels[i + 1]}')
                    for i in range(len(pts) - 1)]
        return segments, radii[1:-1], labels[1:-1], lines[1:-1], pts

    def legs(self, start_node, node):
        start, _ = self.point(start_node, 'start')
        items = self.sequence(node, 'legs')
        if not items:
            raise self.err(node, 'legs is empty: a route needs at least one leg')
        segments, radii, labels, lines, points = [], [], [], [], [start]
        here = start
        explicit_fillet = []
        for i, item in enumerate(items):
            what = f'leg {i + 1}'
            m = self.mapping(item, what, allowed=LEG_KEYS)
            kind = self.choice(m['type'], f'{what} type', ('line', 'arc')) if 'type' in m else 'line'
            label = self.label(what, m, item)
            if kind == 'line':
                seg, end = self.line_leg(m, item, what, label, here)
            else:
                seg, end = self.arc_leg(m, item, what, label, here)
            segments.append(seg)
            r = self.number(m['fillet_radius_m'], f'{what} fillet_radius_m', minimum=0.0) \
                if 'fillet_radius_m' in m else None
            explicit_fillet.append((r, m.get('fillet_radius_m')))
            radii.append(self.fillet if r is None else r)
            labels.append(f'the end of {label}')
            lines.append(item.start_mark.line + 1)
            points.append(end)
            here = end
        # A fillet asked for explicitly must have two straight legs to join.
        for i, (r, rnode) in enumerate(explicit_fillet):
            if r is not None and r > 0.0 and (i == len(segments) - 1 or not (
                    isinstance(segments[i], LineSpec) and isinstance(segments[i + 1], LineSpec))):
                raise self.err(rnode, f'leg {i + 1} fillet_radius_m: a fillet rounds the corner between two '
                                      'straight legs; this leg ' + ('is the last one' if i == len(segments) - 1
                                                                    else 'or the next one is an arc'))
        return segments, radii[:-1], labels[:-1], lines[:-1], points

    def line_leg(self, m, item, what, label, here):
        for bad in ('center', 'direction', 'sweep_deg'):
            if bad in m:
                raise self.err(m[bad], f'{what}: "{bad}" belongs to an arc leg (add "type: arc")')
        if 'to' in m:
            if 'course_deg' in m or 'length_m' in m:
                raise self.err(item, f'{what}: give either "to" or "course_deg" + "length_m", not both')
            end, _ = self.point(m['to'], f'{what} to')
        elif 'course_deg' in m and 'length_m' in m:
            chi = math.radians(self.number(m['course_deg'], f'{what} course_deg'))
            length = self.number(m['length_m'], f'{what} length_m', positive=True)
            end = (here[0] + length * math.cos(chi), here[1] + length * math.sin(chi))
            bad = check_point(end[0], end[1], f'{what} end')
            if bad:
                raise self.err(m['length_m'], bad)
        else:
            raise self.err(item, f'{what}: a straight leg needs "to" or both "course_deg" and "length_m"')
        if _same(end, here):
            raise self.err(item, f'{label} ends where it starts, {_fmt_point(self, here)}: zero-length leg')
        return LineSpec(here, end, label), end

    def arc_leg(self, m, item, what, label, here):
        for bad in ('course_deg', 'length_m'):
            if bad in m:
                raise self.err(m[bad], f'{what}: "{bad}" belongs to a straight leg')
        for req in ('center', 'direction'):
            if req not in m:
                raise self.err(item, f'{what}: an arc leg needs "{req}"')
        center, _ = self.point(m['center'], f'{what} center')
        cw = DIRECTIONS[self.choice(m['direction'], f'{what} direction', tuple(DIRECTIONS))]
        radius = math.hypot(here[0] - center[0], here[1] - center[1])
        if radius <= self.arc_tol:
            raise self.err(m['center'], f'{what}: the arc starts at its centre {_fmt_point(self, center)} (radius 0)')
        if ('to' in m) == ('sweep_deg' in m):
            raise self.err(item, f'{what}: an arc leg needs exactly one of "to" and "sweep_deg"')
        if 'to' in m:
            end, _ = self.point(m['to'], f'{what} to')
            r_end = math.hypot(end[0] - center[0], end[1] - center[1])
            if abs(r_end - radius) > self.arc_tol:
                raise self.err(m['to'], f'{what}: the arc is not on one circle: its start {_fmt_point(self, here)} is '
                                        f'{radius:.3f} m from the centre {_fmt_point(self, center)} but its end '
                                        f'{_fmt_point(self, end)} is {r_end:.3f} m from it (difference '
                                        f'{abs(r_end - radius):.3f} m > arc_tolerance_m {self.arc_tol:g})')
            if _same(end, here):
                raise self.err(m['to'], f'{what}: the arc ends where it starts; use "sweep_deg: 360" for a full circle')
            # Snap the end onto the circle (moves it by <= arc_tolerance_m) so the legs join exactly.
            bearing = math.atan2(end[1] - center[1], end[0] - center[0])
            end = (center[0] + radius * math.cos(bearing), center[1] + radius * math.sin(bearing))
            return ArcSpec(here, end, center, cw, label), end
        sweep = math.radians(self.number(m['sweep_deg'], f'{what} sweep_deg', positive=True))
        if sweep >= 2.0 * math.pi - 1e-9:
            raise self.err(m['sweep_deg'], f'{what}: sweep_deg must be < 360 in one leg (use two legs for more)')
        bearing = math.atan2(here[1] - center[1], here[0] - center[0]) + (sweep if cw else -sweep)
        end = (center[0] + radius * math.cos(bearing), center[1] + radius * math.sin(bearing))
        return ArcSpec(here, end, center, cw, label), end

    def curve(self, node):
        if not isinstance(node, yaml.MappingNode):
            raise self.err(node, f'curve must be a mapping with a "type", got {_kind(node)}')
        type_node = next((v for k, v in node.value if isinstance(k, yaml.ScalarNode) and k.value == 'type'), None)
        if type_node is None:
            raise self.err(node, f'curve: missing required key "type" ({", ".join(CURVE_KEYS)})')
        kind = self.choice(type_node, 'curve type', tuple(CURVE_KEYS))
        m = self.mapping(node, f'curve ({kind})', required=CURVE_REQUIRED[kind], allowed=CURVE_KEYS[kind])
        try:
            return getattr(self, f'curve_{kind}')(m, node)
        except RouteError:
            raise
        except ValueError as exc:                    # a curve's own check (e.g. a cusp)
            raise self.err(node, f'curve ({kind}): {exc}') from None

    def step(self, m):
        return self.number(m['step_m'], 'curve step_m', positive=True) if 'step_m' in m else DEFAULT_STEP_M

    def angle(self, m, key, default=0.0, positive=False):
        return math.radians(self.number(m[key], f'curve {key}', positive=positive)) if key in m else default

    def curve_sine(self, m, node):
        start = self.point(m['start'], 'curve start')[0] if 'start' in m else (0.0, 0.0)
        course = self.angle(m, 'course_deg')
        length = self.number(m['length_m'], 'curve length_m', positive=True)
        amplitude = self.number(m['amplitude_m'], 'curve amplitude_m')
        wavelength = self.number(m['wavelength_m'], 'curve wavelength_m', positive=True)
        samples = curves.sine_samples(length, amplitude, wavelength, self.step(m), start, course,
                                      self.angle(m, 'phase_deg'))
        end = (start[0] + length * math.cos(course), start[1] + length * math.sin(course))
        return curves.samples_to_route(*samples), [start, end]

    def curve_circle(self, m, node):
        center = self.point(m['center'], 'curve center')[0]
        clockwise = DIRECTIONS[self.choice(m['direction'], 'curve direction', tuple(DIRECTIONS))]
        radius = self.number(m['radius_m'], 'curve radius_m', positive=True)
        segs = curves.circle_segments(center, radius, self.angle(m, 'start_bearing_deg'),
                                      self.angle(m, 'sweep_deg', positive=True), clockwise)
        return self.build(segs, node), [segs[0].start, segs[-1].end]

    def curve_spline(self, m, node):
        items = self.sequence(m['points'], 'curve points')
        if len(items) < 2:
            raise self.err(m['points'], f'a spline needs at least 2 points, got {len(items)}')
        pts = []
        for i, item in enumerate(items):
            p = self.point(item, f'curve point {i + 1}')[0]
            if pts and _same(p, pts[-1]):
                raise self.err(item, f'curve point {i + 1} repeats point {i} {_fmt_point(self, p)}')
            pts.append(p)
        return curves.samples_to_route(*curves.spline_samples(pts, self.step(m))), pts

    def label(self, what, extra, node):
        name = self.text(extra['name'], f'{what} name') if 'name' in extra else None
        line = node.start_mark.line + 1
        return f'{what} "{name}" (line {line})' if name else f'{what} (line {line})'


def _fmt_point(reader, p):
    """A NED point written back in the file's frame for messages."""
    if reader.frame == 'enu':
        return f'[{p[1]:.3f}, {p[0]:.3f}]'
    return f'(north {p[0]:.3f} m, east {p[1]:.3f} m)'


def _same(p, q):
    return math.hypot(p[0] - q[0], p[1] - q[1]) < _SAME_POINT_M


def _kind(node):
    if isinstance(node, yaml.MappingNode):
        return 'a mapping'
    if isinstance(node, yaml.SequenceNode):
        return 'a list'
    if node is None:
        return 'nothing'
    return f'the value {node.value!r}'
