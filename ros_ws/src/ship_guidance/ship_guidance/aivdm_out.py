"""AIVDM/AIVDO out: a simulation's vessels as NMEA 0183 AIS sentences for chart plotters.

The sensor model (ship_guidance.ais_sensor) decides when each vessel reports and what the
receiver gets; this module turns that into sentences, encoded by pyais (ITU-R M.1371-5 payloads,
NMEA 0183 / IEC 61162-1 framing): talker ``AI``, ``VDM`` for other vessels (what a receiver
hears), ``VDO`` for the own ship (what its own transponder tells its plotter).

  class A (``A``)            position: message 1 (message 3 for the extra reports of a vessel
                             changing course, sent in slots the transponder reserves with
                             ITDMA); static and voyage data: message 5 (two sentences)
  class B (``B`` CS, ``SO``) position: message 18; static data: message 24 part A (name) and
                             part B (ship type, call sign, dimensions)

Static data goes out with a vessel's first received position report and then with the first
received one 6 min (ais_sensor.STATIC_INTERVAL_S) or more after the last, with its delay.
Dimensions (to bow, stern, port, starboard; whole metres, AIS's limits 511/511/63/63) place
the GNSS antenna on the hull: the vessel's reference point is taken midships on the centre
line, so to_bow = length / 2 - antenna_x. A dimension that is unknown (length or beam 0) is
sent as 0 ("not available"). Navigational status: 5 (moored) or 0 (under way using engine).
The UTC second field is the second of the report's time, modulo 60. Radio channels alternate
A, B per vessel and message (the two parts of a message 24 share one: gpsd pairs them only
then); multi-sentence messages carry a sequential message id 0-9.
"""
import math
from dataclasses import dataclass

import pyais

from ship_guidance.ais import HEADING_NOT_AVAILABLE
from ship_guidance.ais_sensor import STATIC_INTERVAL_S, AisSensor, SensorConfig

ROT_MAX_DEG_MIN = 708.0          # the largest rate of turn the 8-bit ROT field carries
STATUS_UNDER_WAY, STATUS_MOORED = 0, 5


@dataclass(frozen=True)
class VesselInfo:
    """What a vessel's transponder is configured with (static data) and how it reports."""
    mmsi: int
    klass: str = 'A'              # 'A', 'B' (CS) or 'SO'
    own: bool = False             # AIVDO (own ship) rather than AIVDM
    name: str = ''
    callsign: str = ''
    ship_type: int = 0            # M.1371 Table 53 (e.g. 70 cargo, 80 tanker, 37 pleasure)
    length_m: float = 0.0         # overall; 0: unknown
    beam_m: float = 0.0           # 0: unknown
    antenna_x_m: float = 0.0      # GNSS antenna forward of the reference point (midships)
    antenna_y_m: float = 0.0      # to starboard

    def dimensions(self):
        """(to_bow, to_stern, to_port, to_starboard) in whole metres within AIS's fields."""
        def clip(v, hi):
            return int(min(hi, max(0, round(v))))
        bow = stern = port = stbd = 0
        if self.length_m > 0.0:
            bow = clip(self.length_m / 2.0 - self.antenna_x_m, 511)
            stern = clip(self.length_m / 2.0 + self.antenna_x_m, 511)
        if self.beam_m > 0.0:
            port = clip(self.beam_m / 2.0 + self.antenna_y_m, 63)
            stbd = clip(self.beam_m / 2.0 - self.antenna_y_m, 63)
        return bow, stern, port, stbd


def _encode(fields, own, channel, seq_id=None):
    return pyais.encode_dict(fields, talker_id='AI', sentence_type='VDO' if own else 'VDM',
                             radio_channel=channel, seq_id=seq_id)


def position_fields(report, msg_type=None):
    """pyais fields of the position report (message 1/3 for class A, 18 for class B)."""
    if msg_type is None:
        msg_type = 18 if report.klass != 'A' else 3 if report.turning else 1
    heading = report.heading_deg
    fields = dict(msg_type=msg_type, mmsi=int(report.mmsi), lat=float(report.lat),
                  lon=float(report.lon), speed=min(102.2, round(report.sog_kn, 1)),
                  course=round(report.cog_deg, 1) % 360.0,
                  heading=HEADING_NOT_AVAILABLE if heading is None else round(heading) % 360,
                  second=int(math.floor(report.t_sent)) % 60, accuracy=True)
    if msg_type == 18:
        fields.update(cs=report.klass == 'B')
    else:
        fields.update(status=STATUS_MOORED if report.moored else STATUS_UNDER_WAY,
                      turn=max(-ROT_MAX_DEG_MIN, min(ROT_MAX_DEG_MIN, report.rot_deg_min)))
    return fields


def static_fields(info):
    """pyais fields of the static data: [message 5] (class A) or [24 A, 24 B] (class B)."""
    bow, stern, port, stbd = info.dimensions()
    dims = dict(to_bow=bow, to_stern=stern, to_port=port, to_starboard=stbd)
    name, callsign = info.name.upper()[:20], info.callsign.upper()[:7]
    if info.klass == 'A':
        # ais_version 2: "compliant with ITU-R M.1371-5 (or later)"; epfd 1: GPS.
        return [dict(msg_type=5, mmsi=info.mmsi, ais_version=2, callsign=callsign,
                     shipname=name, ship_type=info.ship_type, epfd=1, **dims)]
    return [dict(msg_type=24, mmsi=info.mmsi, partno=0, shipname=name),
            dict(msg_type=24, mmsi=info.mmsi, partno=1, ship_type=info.ship_type,
                 callsign=callsign, **dims)]


class AivdmOut:
    """Vessels' true states in, AIVDM/AIVDO sentences out (as received, in time order).

    ``add(info)`` each vessel, then ``step(mmsi, truth)`` with ais_sensor.Truth at every
    state of that vessel: returns [(t_received, [sentence, ...]), ...], one entry per AIS
    message (a message 5 is two sentences)."""

    def __init__(self, lat0_deg, lon0_deg, config=SensorConfig()):
        self.sensor = AisSensor(lat0_deg, lon0_deg, config)
        self.infos = {}
        self._static_due = {}
        self._channel = {}
        self._seq = 0

    def add(self, info):
        self.sensor.add(info.mmsi, info.klass, info.own, (info.antenna_x_m, info.antenna_y_m))
        static_fields(info)               # refuses bad static data now, not at the first report
        self.infos[info.mmsi] = info
        self._static_due[info.mmsi] = -math.inf
        self._channel[info.mmsi] = 0

    def _next_channel(self, mmsi):
        self._channel[mmsi] ^= 1
        return 'B' if self._channel[mmsi] else 'A'

    def _next_seq(self):
        self._seq = (self._seq + 1) % 10
        return self._seq

    def step(self, mmsi, truth):
        info = self.infos[mmsi]
        out = []
        for r in self.sensor.step(mmsi, truth):
            out.append((r.t_received, _encode(position_fields(r), info.own,
                                              self._next_channel(mmsi))))
            if r.t_sent >= self._static_due[mmsi]:
                self._static_due[mmsi] = r.t_sent + STATIC_INTERVAL_S
                channel = self._next_channel(mmsi)   # both parts of a 24 on one: gpsd pairs so
                for fields in static_fields(info):
                    seq = self._next_seq() if fields['msg_type'] == 5 else None
                    out.append((r.t_received, _encode(fields, info.own, channel, seq)))
        return out
