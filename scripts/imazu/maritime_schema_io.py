"""Imazu encounters <-> maritime-schema TrafficSituation (the ``maritime-schema`` package, DNV's
data classes for traffic-situation JSON, pinned in requirements/interop.txt).

A case here is what imazu.cases.load_cases gives: {'own': {north_m, east_m, course_deg,
speed_mps}, 'targets': [{name, north_m, east_m, course_deg, speed_mps, colregs}, ...]} in a
flat NED frame in metres. maritime-schema places ships by WGS-84 latitude / longitude and gives
speed over ground in knots and course over ground in degrees, so the frame is anchored at a
geographic origin (default nav_display's DEFAULT_ORIGIN_DEG, open water) with
ship_sim.geodetic (its tangent plane: good to well under a metre over an Imazu case's 15 km).

What the schema has no field for travels in the situation's extra fields (the schema allows
them): ``shipnav`` holds the Imazu case number and each target's COLREGs situation as the
case file states it (the own ship's view at t = 0), so a round trip gives back the case. Ship
ids are UUIDs derived from the case and ship names (uuid5), so writing a case twice gives the
same file.
"""
import math
import uuid

from ship_guidance.nav_display import DEFAULT_ORIGIN_DEG
from ship_sim.geodetic import geodetic_to_ned, ned_to_geodetic

#: metres per second in one knot (1852 m / 3600 s).
KNOT_MPS = 1852.0 / 3600.0
#: Own route length written as the own ship's second waypoint (m), as imazu.runner's route.
ROUTE_LENGTH_M = 40000.0
NAMESPACE = uuid.uuid5(uuid.NAMESPACE_URL, 'shipnav/imazu')


def _ship_id(title, name):
    return uuid.uuid5(NAMESPACE, f'{title}/{name}')


def _position(north, east, origin):
    lat, lon = ned_to_geodetic(north, east, *origin)
    return {'latitude': float(lat), 'longitude': float(lon)}


def _ship(title, name, ship, origin, route_m=None):
    """dict of a maritime-schema Ship: static (id, name), initial (position, sog kn, cog, heading
    = cog deg); with ``route_m``, two waypoints: the start and ``route_m`` ahead on the course."""
    cog = ship['course_deg'] % 360.0
    out = {'static': {'id': _ship_id(title, name), 'name': name},
           'initial': {'position': _position(ship['north_m'], ship['east_m'], origin),
                       'sog': ship['speed_mps'] / KNOT_MPS, 'cog': cog, 'heading': cog}}
    if route_m is not None:
        c = math.radians(cog)
        end = (ship['north_m'] + route_m * math.cos(c), ship['east_m'] + route_m * math.sin(c))
        out['waypoints'] = [{'position': _position(ship['north_m'], ship['east_m'], origin)},
                            {'position': _position(*end, origin)}]
    return out


def to_traffic_situation(number, case, origin=DEFAULT_ORIGIN_DEG):
    """maritime_schema TrafficSituation of Imazu case ``number`` (``case`` as load_cases gives
    it); targets keep their case names, the own ship is named 'own ship'."""
    from maritime_schema.types.caga import TrafficSituation
    title = f'imazu_{number:02d}'
    targets = case['targets']
    return TrafficSituation(
        title=title,
        description=f'Imazu case {number}: ' + ', '.join(f"{t['name']} {t['colregs']}"
                                                         for t in targets),
        own_ship=_ship(title, 'own ship', case['own'], origin, ROUTE_LENGTH_M),
        target_ships=[_ship(title, t['name'], t, origin) for t in targets],
        shipnav={'imazu_case': number, 'origin_deg': list(origin),
                 'colregs': {t['name']: t['colregs'] for t in targets}})


def _local(ship, origin):
    p = ship.initial.position
    north, east = geodetic_to_ned(p.latitude, p.longitude, *origin)
    return {'north_m': float(north), 'east_m': float(east), 'course_deg': float(ship.initial.cog),
            'speed_mps': float(ship.initial.sog) * KNOT_MPS}


def from_traffic_situation(situation, origin=None):
    """(case number or None, case dict) of a TrafficSituation: positions in the NED frame at
    ``origin`` (default: the one the file was written with, else the own ship's initial
    position); a target's situation from the file's ``shipnav`` extra field, else None."""
    extra = getattr(situation, 'shipnav', None) or {}
    if origin is None:
        p = situation.own_ship.initial.position
        origin = tuple(extra.get('origin_deg') or (p.latitude, p.longitude))
    colregs = extra.get('colregs', {})
    targets = [{'name': t.static.name, **_local(t, origin), 'colregs': colregs.get(t.static.name)}
               for t in situation.target_ships or []]
    return extra.get('imazu_case'), {'own': _local(situation.own_ship, origin), 'targets': targets}


def dumps(situation):
    """The JSON text of a TrafficSituation as the schema names its fields (camelCase)."""
    return situation.model_dump_json(by_alias=True, exclude_none=True, indent=1)


def loads(text):
    """TrafficSituation from JSON text (validated by the schema's classes)."""
    from maritime_schema.types.caga import TrafficSituation
    return TrafficSituation.model_validate_json(text)
