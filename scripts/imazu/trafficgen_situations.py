"""Reader of DNV ship-traffic-generator's situation files (trafficgen's output, the 55 baseline
situations of its repository's data/baseline_situations_generated/) into the encounter dict
imazu.cases uses, so the Imazu runner can run them.

Those files do not load in the pinned maritime-schema (requirements/interop.txt, 0.0.7): they
are written in the schema's later version 0.2.0 ("schemaVersion" in each file), which moved
positions to {lat, lon} (0.0.7: {latitude, longitude}), speed to each waypoint's "leg": {sog}
and dimensions into static.dimensions, gives no initial position, course or speed, and numbers
the ships with integers where 0.0.7 requires UUIDs; 0.2.0 is not on the package index, and
trafficgen 0.9.1 carries its own copy of the classes. So this module reads the JSON itself
(through ship_sim.safe_load), field by field, and refuses a file that lacks one.

Each ship: the first waypoint is its start, the bearing from the first to the second waypoint
its course (a trafficgen target sails one straight leg at one speed), the first leg's sog its
speed. The own ship's start is the frame's origin (own ship at (0, 0), as in an Imazu case).
The situation of each target comes from the file's title, one code per target in order (HO,
OT-GW, OT-SO, CR-GW, CR-SO).
"""
import math

from ship_sim.geodetic import geodetic_to_ned
from ship_sim.safe_load import load_json_file

KNOT_MPS = 1852.0 / 3600.0
#: trafficgen's title codes -> the situation names of ship_guidance.colregs (own ship's view).
SITUATIONS = {'HO': 'head-on', 'OT-GW': 'overtaking', 'OT-SO': 'being-overtaken',
              'CR-GW': 'crossing-give-way', 'CR-SO': 'crossing-stand-on'}


class TrafficgenFormatError(ValueError):
    """A trafficgen situation file lacks a field this reader needs."""


def _field(obj, *keys, where):
    for k in keys:
        if not isinstance(obj, dict) or k not in obj:
            raise TrafficgenFormatError(f'{where}: no {".".join(keys)}')
        obj = obj[k]
    return obj


def _ship(ship, origin, where):
    wps = _field(ship, 'waypoints', where=where)
    if len(wps) < 2:
        raise TrafficgenFormatError(f'{where}: fewer than two waypoints')
    (lat0, lon0), (lat1, lon1) = [(_field(w, 'position', 'lat', where=where),
                                   _field(w, 'position', 'lon', where=where)) for w in wps[:2]]
    n0, e0 = (float(v) for v in geodetic_to_ned(lat0, lon0, *origin))
    n1, e1 = (float(v) for v in geodetic_to_ned(lat1, lon1, *origin))
    sog = float(_field(wps[0], 'leg', 'sog', where=where))
    dims = (ship.get('static') or {}).get('dimensions') or {}
    return {'north_m': n0, 'east_m': e0,
            'course_deg': math.degrees(math.atan2(e1 - e0, n1 - n0)) % 360.0,
            'speed_mps': sog * KNOT_MPS,
            'length_m': dims.get('length'), 'beam_m': dims.get('width')}


def read_situation(path):
    """(title, case dict as imazu.cases.load_cases gives, plus each ship's 'length_m' and
    'beam_m' or None) of one trafficgen situation file."""
    data = load_json_file(path)
    where = str(path)
    own = _field(data, 'ownShip', where=where)
    wp0 = _field(own, 'waypoints', where=where)[0]
    origin = (_field(wp0, 'position', 'lat', where=where), _field(wp0, 'position', 'lon', where=where))
    title = str(_field(data, 'title', where=where))
    codes = [c.strip() for c in title.split(',')]
    ships = _field(data, 'targetShips', where=where)
    if len(codes) != len(ships):
        raise TrafficgenFormatError(f'{where}: title {title!r} names {len(codes)} situations '
                                    f'for {len(ships)} target ships')
    targets = []
    for i, (code, ship) in enumerate(zip(codes, ships), 1):
        if code not in SITUATIONS:
            raise TrafficgenFormatError(f'{where}: unknown situation code {code!r}')
        targets.append({'name': f'ts{i}', **_ship(ship, origin, f'{where} target {i}'),
                        'colregs': SITUATIONS[code]})
    return title, {'own': _ship(own, origin, f'{where} own ship'), 'targets': targets}
