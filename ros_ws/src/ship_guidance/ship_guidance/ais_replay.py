"""AIS replay files from known tracks: position reports encoded by pyais (the inverse of
ship_guidance.ais), for tests and scenarios whose AIS targets must follow a known track.

Each report is one message 1 (class A) or 18 (class B) sentence at the target's local NED
position converted to WGS-84 at the origin (ship_sim.geodetic), its SOG and COG, true heading
"not available" (the receiver then takes the COG); a line of the replay format is
``<t_s> <sentence>`` (ship_guidance.ais.parse_replay). AIS quantises what it carries: position
to 1/10000 arc minute (about 0.19 m), SOG to 0.1 kn, COG to 0.1 deg.
"""
import math

import pyais

from ship_guidance.ais import KNOT
from ship_sim.geodetic import ned_to_geodetic

HEADING_NOT_AVAILABLE = 511


def position_sentence(mmsi, north, east, sog_mps, cog_rad, lat0_deg, lon0_deg, msg_type=1):
    """One AIVDM sentence: a position report of ``mmsi`` at (north, east) m from the origin."""
    if msg_type not in (1, 18):
        raise ValueError(f'msg_type must be 1 (class A) or 18 (class B), got {msg_type}')
    lat, lon = ned_to_geodetic(north, east, lat0_deg, lon0_deg)
    course = math.degrees(cog_rad) % 360.0
    fields = dict(type=msg_type, msg_type=msg_type, mmsi=int(mmsi), lat=float(lat),
                  lon=float(lon), speed=round(sog_mps / KNOT, 1), course=round(course, 1) % 360.0,
                  heading=HEADING_NOT_AVAILABLE)
    return pyais.encode_dict(fields, talker_id='AI', sentence_type='VDM')[0]


def replay_lines(mmsi, times, north, east, sog_mps, cog_rad, lat0_deg, lon0_deg, msg_type=1):
    """Replay-file lines ``<t_s> <sentence>``, one report per time (sequences of equal length)."""
    return [f'{t:g} {position_sentence(mmsi, n, e, v, c, lat0_deg, lon0_deg, msg_type)}'
            for t, n, e, v, c in zip(times, north, east, sog_mps, cog_rad)]
