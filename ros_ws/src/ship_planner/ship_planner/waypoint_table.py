"""Read the waypoint tables of Simakis 1992 (NPS thesis) into a RoutePlan.

Source: Simakis 1992 Chapter IV.C (the figure-eight data table and the paragraph after it) and the
program listings NOMO.FOR (path following, READ(11,*) X2,Y2,ITURN,DD,IPATH,ICCW,X0,Y0) and
REFERENCE PATH (draws the reference path from the same file).

File format (extension .wpt; whitespace-separated, one waypoint per row):

    # comment lines start with '#'; blank lines are ignored
    #@ name: figure_eight_003          directives: '#@ key: value' (keys below)
    #@ source: <citation>
    x y TURN D PATH ICCW x0 y0          optional header row naming the columns
    15.0 0.0 0 1.0 0 0 0.0 0.0

Directives: name (required), source (required), length_unit_m (metres per table unit, default
1; Simakis's tables are nondimensional, in vehicle lengths), start ("x y", the point the route
starts from, default "0 0": NOMO.FOR starts every run at X1 = Y1 = 0 with PSI = 0), and
arc_tolerance (table units, default 0.01). The reader's length_unit_m argument overrides the
file's (e.g. to scale a table to a ship: L = 160.93 m for the Mariner).

Columns (each row describes the leg that ENDS at its waypoint):
  x, y   the next waypoint (X2, Y2). Simakis 1992 eqs. (2.4)-(2.5), x_dot = u cos psi - v sin psi,
         y_dot = u sin psi + v cos psi, are Fossen's NED kinematics, so x is north, y is east
         and psi turns from x towards y: north = x * unit, east = y * unit.
  TURN   (ITURN) when to switch to the next row. The text says 1 = "enter a circle of radius D
         centred at the way point", 0 = "turn at a distance D from the heading point"; the code
         does the reverse: ITURN = 1 compares D with TURNL = sqrt(dist^2 - YPR^2), the
         along-track distance left to the waypoint (YPR is the cross-track offset from the line
         X1,Y1 -> X2,Y2), and ITURN = 0 compares D with TURNC, the straight distance (a circle
         of acceptance). We follow the code, which produced the figures: 0 -> 'radius',
         1 -> 'along_track' (extras['switching']).
  D      (DD) the switching distance for TURN, table units (metres after scaling).
  PATH   (IPATH) 0 = straight line to (x, y), 1 = circular arc about (x0, y0).
  ICCW   1 = counter-clockwise, 0 = clockwise, as Simakis 1992 draws it (x to the right, y up).
         With x = north and y = east that picture is mirrored: its CCW runs from +x towards +y,
         psi increasing, a starboard turn, i.e. CLOCKWISE seen from above in NED. So ICCW = 1
         -> Arc(clockwise=True), ICCW = 0 -> Arc(clockwise=False). The figure-eight table
         confirms it: only with this reading is every arc tangent to the legs it joins.
  x0,y0  the arc's centre; zeros on straight rows (ignored). NOMO.FOR takes the radius from
         the previous waypoint and never checks the end; we require both on one circle.

OCR notes: the figure-eight table in the OCR text is clean (header "x <sub>0</sub>" is x0);
every arc row has equal start and end radii (5.0) and all joins are tangent except the 90 deg
corner at (15, 0), so no number had to be guessed. The figure-eight ends at (6, 5), not at its
start (0, 0): the table does not close the lower loop (Simakis's Fig. 28 is not in the OCR).
Simakis's 2-point quarter-circle runs (Figs. 14-23, 26) give only the end points (0,0) and
(10,10); see ship_planner.quarter_circle_routes for the centre we chose.
"""
import math

import numpy as np

from ship_planner.fillets import ArcSpec, LineSpec, segments_to_route
from ship_planner.route_data import (MAX_ROUTE_SAMPLES, RouteError, RoutePlan, check_point,
                                     check_route_size)
from ship_sim.safe_load import TextFileError, read_text_file

COLUMNS = ('x', 'y', 'TURN', 'D', 'PATH', 'ICCW', 'x0', 'y0')
DIRECTIVES = ('name', 'source', 'length_unit_m', 'start', 'arc_tolerance')
SWITCH_MODES = {0: 'radius', 1: 'along_track'}
FRAME = 'simakis_xy'   # the x/y table frame of Simakis 1992 (x north, y east, vehicle lengths)


def load_waypoint_table(path, length_unit_m=None):
    """Read a waypoint table in the format of Simakis 1992 file. Returns a RoutePlan; raises RouteError."""
    path = str(path)
    try:
        text = read_text_file(path)
    except TextFileError as exc:
        raise RouteError(f'cannot read the waypoint table: {exc.detail}', file=path,
                         line=exc.line) from None
    plan = parse_waypoint_table(text, path, length_unit_m)
    plan.file = path
    return plan


def parse_waypoint_table(text, filename='<string>', length_unit_m=None):
    """Validate waypoint-table text (see the module docstring); filename is used in messages."""
    meta, rows = _split(text, filename)
    for key in ('name', 'source'):
        if key not in meta:
            raise RouteError(f'missing directive "#@ {key}: ..."', file=filename)
    unit = _directive_number(meta, 'length_unit_m', 1.0, filename) if length_unit_m is None else float(length_unit_m)
    if not math.isfinite(unit) or unit <= 0.0:
        raise RouteError(f'length_unit_m must be a positive number of metres, got {unit}', file=filename)
    tol = _directive_number(meta, 'arc_tolerance', 0.01, filename)
    start = (0.0, 0.0)
    if 'start' in meta:
        value, line = meta['start']
        try:
            start = tuple(float(v) for v in value.split())
        except ValueError:
            start = ()
        if len(start) != 2 or not all(math.isfinite(v) for v in start):
            raise RouteError(f'start must be two finite numbers "x y", got {value!r}', file=filename, line=line)
    if len(rows) < 1:
        raise RouteError('the table has no waypoint rows: a route needs at least 2 points (start + 1 row)',
                         file=filename)
    if len(rows) > MAX_ROUTE_SAMPLES:
        raise RouteError(f'the table has {len(rows)} rows; at most {MAX_ROUTE_SAMPLES} are accepted',
                         file=filename)
    bad = check_point(*_ned(start, unit), 'start')
    if bad:
        raise RouteError(bad, file=filename, line=meta['start'][1] if 'start' in meta else None)

    segments, switching, points = [], [], [start]
    here = start
    for n, (line, v) in enumerate(rows, start=1):
        x, y, turn, d, path, iccw, x0, y0 = v

        def fail(detail, n=n, line=line):
            return RouteError(detail, file=filename, row=n, line=line)
        for col, val in (('TURN', turn), ('PATH', path), ('ICCW', iccw)):
            if val not in (0.0, 1.0):
                raise fail(f'{col} must be 0 or 1, got {val:g}')
        if d < 0.0:
            raise fail(f'D (switching distance) must be >= 0, got {d:g}')
        end = (x, y)
        for what, p in (('waypoint', end), ('arc centre', (x0, y0))):
            bad = check_point(*_ned(p, unit), f'{what} ({p[0]:g}, {p[1]:g})')
            if bad:
                raise fail(bad)
        if math.hypot(x - here[0], y - here[1]) < 1e-9:
            raise fail(f'waypoint ({x:g}, {y:g}) repeats the previous point: zero-length leg')
        if path == 1.0:
            r0 = math.hypot(here[0] - x0, here[1] - y0)
            r1 = math.hypot(x - x0, y - y0)
            if r0 < 1e-9:
                raise fail(f'arc centre ({x0:g}, {y0:g}) is the arc start itself (radius 0)')
            if abs(r1 - r0) > tol:
                raise fail(f'arc is not on one circle: its start ({here[0]:g}, {here[1]:g}) is {r0:.4f} from the '
                           f'centre ({x0:g}, {y0:g}) but its end ({x:g}, {y:g}) is {r1:.4f} from it '
                           f'(difference {abs(r1 - r0):.4f} > arc_tolerance {tol:g})')
            seg = ArcSpec(_ned(here, unit), _ned(_on_circle(end, (x0, y0), r0), unit), _ned((x0, y0), unit),
                          iccw == 1.0, f'row {n}')
        else:
            seg = LineSpec(_ned(here, unit), _ned(end, unit), f'row {n}')
        segments.append(seg)
        switching.append({'mode': SWITCH_MODES[int(turn)], 'distance_m': d * unit, 'row': n, 'line': line})
        points.append(end)
        here = end

    try:
        route = segments_to_route(segments)
    except ValueError as exc:
        raise RouteError(f'the route could not be built: {exc}', file=filename) from None
    bad = check_route_size(route)
    if bad:
        raise RouteError(bad, file=filename)
    return RoutePlan(route=route, name=meta['name'][0], source=meta['source'][0], frame=FRAME,
                     waypoints_ned=np.array([_ned(p, unit) for p in points]),
                     file=None if filename == '<string>' else filename,
                     extras={'switching': switching, 'length_unit_m': unit,
                             'rows': [list(v) for _, v in rows]})


def format_waypoint_table(rows, name, source, length_unit_m=None, start=None, comments=()):
    """Table text for rows of (x, y, TURN, D, PATH, ICCW, x0, y0); the inverse of the reader."""
    out = [f'# {c}' if c else '#' for c in comments]
    out.append(f'#@ name: {name}')
    out.append(f'#@ source: {source}')
    if length_unit_m is not None:
        out.append(f'#@ length_unit_m: {length_unit_m:.6g}')
    if start is not None:
        out.append(f'#@ start: {start[0]:.6g} {start[1]:.6g}')
    out.append('\t'.join(COLUMNS))
    for r in rows:
        x, y, turn, d, path, iccw, x0, y0 = r
        out.append('\t'.join([_num(x), _num(y), str(int(turn)), _num(d), str(int(path)), str(int(iccw)),
                              _num(x0), _num(y0)]))
    return '\n'.join(out) + '\n'


def _num(v):
    """Fixed notation, enough digits to round-trip points generated on a circle."""
    s = f'{float(v):.6f}'.rstrip('0')
    return s + '0' if s.endswith('.') else s


def _ned(p, unit):
    return (p[0] * unit, p[1] * unit)          # x -> north, y -> east (Simakis 1992 eqs. 2.4-2.5)


def _on_circle(p, c, r):
    """p moved radially onto the circle (c, r): closes the tolerance gap so the legs join exactly."""
    b = math.atan2(p[1] - c[1], p[0] - c[0])
    return (c[0] + r * math.cos(b), c[1] + r * math.sin(b))


def _directive_number(meta, key, default, filename):
    if key not in meta:
        return default
    value, line = meta[key]
    try:
        v = float(value)
    except ValueError:
        raise RouteError(f'{key} must be a number, got {value!r}', file=filename, line=line) from None
    if not math.isfinite(v) or v <= 0.0:
        raise RouteError(f'{key} must be a positive finite number, got {value!r}', file=filename, line=line)
    return v


def _split(text, filename):
    """Directives {key: (value, line)} and data rows [(line, 8 floats)]."""
    meta, rows = {}, []
    header_seen = False
    for i, raw in enumerate(text.splitlines(), start=1):
        s = raw.strip()
        if not s:
            continue
        if s.startswith('#@'):
            key, sep, value = s[2:].partition(':')
            key = key.strip()
            if not sep or key not in DIRECTIVES:
                raise RouteError(f'unknown directive {s!r}; use "#@ key: value" with key one of '
                                 f'{", ".join(DIRECTIVES)}', file=filename, line=i)
            if key in meta:
                raise RouteError(f'directive "{key}" is given twice', file=filename, line=i)
            if not value.strip():
                raise RouteError(f'directive "{key}" has no value', file=filename, line=i)
            meta[key] = (value.strip(), i)
            continue
        if s.startswith('#'):
            continue
        cols = s.split()
        if [c.lower() for c in cols] == [c.lower() for c in COLUMNS]:
            if header_seen or rows:
                raise RouteError('the header row must come once, before the data', file=filename, line=i)
            header_seen = True
            continue
        n = len(rows) + 1
        if len(cols) != len(COLUMNS):
            raise RouteError(f'expected {len(COLUMNS)} columns ({" ".join(COLUMNS)}), got {len(cols)}: {s!r}',
                             file=filename, row=n, line=i)
        vals = []
        for name, c in zip(COLUMNS, cols):
            try:
                v = float(c)
            except ValueError:
                raise RouteError(f'column {name} must be a number, got {c!r}', file=filename, row=n, line=i) from None
            if not math.isfinite(v):
                raise RouteError(f'column {name} must be finite, got {c!r}', file=filename, row=n, line=i)
            vals.append(v)
        rows.append((i, vals))
    return meta, rows

