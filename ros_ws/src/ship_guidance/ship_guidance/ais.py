"""AIS targets from NMEA 0183 AIVDM/AIVDO sentences: decode, track per MMSI, dead-reckon.

Decoding is pyais's (messages of ITU-R M.1371-5); this module adds what a tracker needs around
it: checks that never raise, multi-sentence assembly, one track per MMSI in the local NED plane
at a geodetic origin (ship_sim.geodetic), dead reckoning between reports and a staleness rule.

Messages used (everything else that is valid AIS is counted in ``ignored`` and skipped):
  1, 2, 3  class A position report (SOG, COG, true heading, position)
  18       class B position report;  19: class B extended (position + name, type, dimensions)
  5        class A static and voyage data (name, ship type, dimensions; two sentences)
  24       class B static data, part A (name) and part B (ship type, dimensions)

Reporting intervals relied on (ITU-R M.1371-5, Annex 1, Tables 1 and 2): class A moored or at
anchor and slower than 3 kn reports every 3 min; under way every 10 s (0-14 kn), 6 s
(14-23 kn), 2 s (> 23 kn), faster while changing course. Class B "CS" reports every 30 s above
2 kn and every 3 min at or below 2 kn. Static data (messages 5 and 24) comes every 6 min.
A target is therefore dropped only after ``stale_after_s`` without a position report (default
360 s: two missed reports of a class A ship at anchor, or of a slow class B ship; a ship under
way misses 36 or more reports first). Static data is kept per MMSI as long as the track.

Dead reckoning: between reports a target moves in a straight line in the local plane at its
last SOG along its last COG (constant-velocity model; within the tangent plane's range the
straight line differs from the rhumb line far less than a real ship departs from constant
course and speed over a few minutes). A report whose SOG or COG is "not available"
(102.3 kn, 360 deg) still places the target but holds it there (velocity unknown: zero).
Orientation is the true heading when reported (511 = not available), else the COG.

Bad input is counted per reason in ``AisTracker.bad`` and skipped, never raised:
  malformed                 not an AIVDM/AIVDO sentence (fields, talker, characters, pyais error)
  checksum                  the '*hh' checksum does not match
  truncated                 no payload, or fewer bits than the message type carries
  fragment                  a part of a multi-sentence message out of order or without its
                            first, or a message never completed (see below)
  unknown_type              message type 0 or above 27 (not defined by ITU-R M.1371)
  bad_mmsi                  MMSI 0
  position_not_available    latitude 91 / longitude 181 or out of range: the report is skipped
  velocity_not_available    SOG 102.3 kn or COG 360 deg: position used, target held (see above)
Time is the caller's (receive time, sim or wall clock, seconds); AIS's own UTC second is unused.

Multi-sentence messages (at most 9 parts, sequential message id 0-9 or empty, IEC 61162-1) are
sent in consecutive slots of one transmission, so their parts arrive together: a message begun
and not complete within FRAGMENT_TIMEOUT_S of its first part is dropped, and at most
MAX_PENDING_FRAGMENTS are kept (the oldest dropped first); both count as 'fragment'. One
receiver has at most 20 in flight (ids 0-9 on channels A and B), so the bound leaves room for
several sources on one UDP port, while a sender of endless first parts cannot grow the store.
A sequential message id outside 0-9 is 'malformed'.
"""
from collections import OrderedDict
import math
from dataclasses import dataclass, field

from pyais.exceptions import AISBaseException
from pyais.messages import NMEAMessage

from ship_sim.geodetic import geodetic_to_ned

KNOT = 1852.0 / 3600.0                 # m/s per knot
STALE_AFTER_S = 360.0                  # default staleness timeout (see the module docstring)
POSITION_TYPES = frozenset((1, 2, 3, 18, 19))
STATIC_TYPES = frozenset((5, 19, 24))
SUPPORTED_TYPES = POSITION_TYPES | STATIC_TYPES
#: Payload bits each used message carries (ITU-R M.1371-5); message 5 is accepted from 420 bits
#: (some transponders drop the final spare and DTE bits) and 24 part A from 160.
MIN_BITS = {1: 168, 2: 168, 3: 168, 5: 420, 18: 168, 19: 312, 24: 160}
BAD_REASONS = ('malformed', 'checksum', 'truncated', 'fragment', 'unknown_type', 'bad_mmsi',
               'position_not_available', 'velocity_not_available')
SOG_NOT_AVAILABLE = 102.3              # kn
COG_NOT_AVAILABLE = 360.0              # deg
HEADING_NOT_AVAILABLE = 511
FRAGMENT_TIMEOUT_S = 5.0               # a multi-sentence message not complete by then is dropped
MAX_PENDING_FRAGMENTS = 100            # multi-sentence messages in assembly at once
SEQUENCE_IDS = range(10)               # IEC 61162-1 sequential message identifier


@dataclass
class Track:
    """One target: the last position report (NED at the origin) and the static data."""
    mmsi: int
    t: float = None                    # receive time of the last position report (s)
    lat: float = None                  # deg
    lon: float = None
    north: float = None                # m, at the origin
    east: float = None
    sog: float = 0.0                   # m/s over ground (0 when not available)
    cog: float = 0.0                   # rad, NED, clockwise from north
    heading: float = None              # rad, true heading, None when not reported
    klass: str = None                  # 'A' (1/2/3/5) or 'B' (18/19/24)
    moored: bool = False               # navigational status at anchor (1) or moored (5)
    name: str = None
    ship_type: int = None
    to_bow: int = None                 # m from the reference point (dimension fields)
    to_stern: int = None
    to_port: int = None
    to_starboard: int = None
    t_static: float = None             # receive time of the last static data
    reports: int = 0

    @property
    def length(self):
        """Overall length (m) from the dimension fields, None when not given (0 = unknown)."""
        if self.to_bow is None or self.to_bow + self.to_stern == 0:
            return None
        return float(self.to_bow + self.to_stern)

    @property
    def beam(self):
        if self.to_port is None or self.to_port + self.to_starboard == 0:
            return None
        return float(self.to_port + self.to_starboard)


@dataclass(frozen=True)
class TargetState:
    """A target dead-reckoned to time t: NED position (m), course over ground and orientation."""
    mmsi: int
    t: float
    north: float
    east: float
    sog: float                          # m/s
    cog: float                          # rad, NED
    psi: float                          # rad, NED: true heading if reported, else COG
    age: float                          # s since the last position report
    track: Track = field(compare=False, repr=False)


def dead_reckon(north, east, sog, cog, dt):
    """Constant-velocity prediction dt seconds on: (north, east) + sog * dt * (cos, sin)(cog)."""
    return north + sog * dt * math.cos(cog), east + sog * dt * math.sin(cog)


def parse_replay(lines, rate_hz, offset_s=0.0):
    """Lines of an AIS replay file -> [(t, sentence)], in time order (stable).

    Format, one sentence a line: ``<t_s> <sentence>`` (t_s: seconds, a number) or the sentence
    alone, timed at ``offset_s + i / rate_hz`` for the i-th such line (0, 1, ...), except that
    a later part of a multi-sentence message (part number > 1) takes the time of the line
    before it: the parts are one transmission, and a slow rate must not let them expire
    (FRAGMENT_TIMEOUT_S). ``offset_s`` is added to the given times too. Blank lines and lines
    starting with ``#`` are skipped.
    """
    if not rate_hz > 0.0:
        raise ValueError(f'rate_hz must be > 0, got {rate_hz}')
    out = []
    plain = 0
    for line in lines:
        line = line.strip()
        if not line or line.startswith('#'):
            continue
        head, _, rest = line.partition(' ')
        try:
            t = float(head)
        except ValueError:
            t = None
        if t is not None and rest.strip() and math.isfinite(t):
            out.append((offset_s + t, rest.strip()))
        elif plain and later_part(line):
            out.append((offset_s + (plain - 1) / rate_hz, line))
        else:
            out.append((offset_s + plain / rate_hz, line))
            plain += 1
    out.sort(key=lambda item: item[0])
    return out


def later_part(line):
    """Whether an NMEA line is part 2 or later of a multi-sentence message (by its fields)."""
    fields = line.split(',', 3)
    return len(fields) == 4 and fields[2].isdigit() and int(fields[2]) > 1


def _payload_type(payload):
    """Message type from the first 6-bit character of an armoured payload, None if invalid."""
    c = ord(payload[0]) - 48
    if c > 40:
        c -= 8
    return c if 0 <= c < 64 else None


class AisTracker:
    """Feed sentences with their receive time; read the live targets at any time.

    ``feed(line, t)`` returns the MMSI a complete message updated (None otherwise); counters:
    ``bad`` (reason -> count, BAD_REASONS), ``ignored`` (valid AIS type not used -> count),
    ``decoded`` (type -> count). ``targets(t)`` drops stale tracks and dead-reckons the rest.
    """

    def __init__(self, lat0_deg, lon0_deg, stale_after_s=STALE_AFTER_S):
        if not stale_after_s > 0.0:
            raise ValueError(f'stale_after_s must be > 0, got {stale_after_s}')
        geodetic_to_ned(lat0_deg, lon0_deg, lat0_deg, lon0_deg)   # validates the origin
        self.lat0, self.lon0 = float(lat0_deg), float(lon0_deg)
        self.stale_after_s = float(stale_after_s)
        self.tracks = {}
        self.bad = dict.fromkeys(BAD_REASONS, 0)
        self.ignored = {}
        self.decoded = {}
        self.last_bad = None            # (reason, line) of the latest bad input, for warnings
        # (talker, channel, seq id) -> (receive time of the first part, [sentences so far]),
        # oldest first
        self._parts = OrderedDict()

    # -- input -------------------------------------------------------------------------------

    def feed(self, line, t):
        """One NMEA line (str or bytes, tag block allowed) received at time t (s)."""
        if isinstance(line, str):
            line = line.encode('ascii', 'replace')
        line = line.strip()
        if line.startswith(b'\\'):                     # NMEA 4.0 tag block: \...*hh\!AIVDM...
            end = line.find(b'\\', 1)
            line = line[end + 1:] if end > 0 else b''
        try:
            sentence = NMEAMessage(line)
        except (AISBaseException, ValueError, IndexError, TypeError):
            return self._reject('malformed', line)
        if sentence.type not in ('VDM', 'VDO'):
            return self._reject('malformed', line)
        if not sentence.is_valid:
            return self._reject('checksum', line)
        if not sentence.payload:
            return self._reject('truncated', line)
        if sentence.frag_cnt > 1:
            parts = self._collect(sentence, line, float(t))
            if parts is None:
                return None
            try:
                sentence = NMEAMessage.assemble_from_iterable(parts)
            except (AISBaseException, ValueError, IndexError, TypeError):
                return self._reject('malformed', line)
        return self._decode(sentence, line, float(t))

    def _collect(self, sentence, line, t):
        """Buffer the parts of a multi-sentence message; the full list once the last arrives."""
        if sentence.seq_id is not None and sentence.seq_id not in SEQUENCE_IDS:
            return self._reject('malformed', line)
        self.expire_fragments(t)
        key = (sentence.talker, sentence.channel, sentence.seq_id)
        n, k = sentence.frag_cnt, sentence.frag_num
        if k == 1:
            if self._parts.pop(key, None) is not None:   # the previous message never finished
                self._reject('fragment', line)
            while len(self._parts) >= MAX_PENDING_FRAGMENTS:
                self._parts.popitem(last=False)
                self.bad['fragment'] += 1
            self._parts[key] = (t, [sentence])
        else:
            got = self._parts.get(key)
            if got is None or len(got[1]) != k - 1 or got[1][0].frag_cnt != n:
                self._parts.pop(key, None)
                return self._reject('fragment', line)
            got[1].append(sentence)
        if k == n:
            return self._parts.pop(key)[1]
        return None

    def expire_fragments(self, t):
        """Drop the multi-sentence messages begun more than FRAGMENT_TIMEOUT_S before ``t``
        (each counted as 'fragment'); return how many."""
        parts = self._parts
        n = 0
        while parts:
            t0 = next(iter(parts.values()))[0]
            if not t - t0 > FRAGMENT_TIMEOUT_S:
                break
            parts.popitem(last=False)
            n += 1
        self.bad['fragment'] += n
        return n

    def _decode(self, sentence, line, t):
        payload = sentence.payload.decode('ascii', 'replace') if isinstance(
            sentence.payload, bytes) else str(sentence.payload)
        kind = _payload_type(payload)
        if kind is None or kind == 0 or kind > 27:
            return self._reject('unknown_type', line)
        if kind not in SUPPORTED_TYPES:
            self.ignored[kind] = self.ignored.get(kind, 0) + 1
            return None
        if 6 * len(payload) - int(sentence.fill_bits or 0) < MIN_BITS[kind]:
            return self._reject('truncated', line)
        try:
            msg = sentence.decode()
        except (AISBaseException, ValueError, IndexError, TypeError, KeyError):
            return self._reject('malformed', line)
        if not msg.mmsi:
            return self._reject('bad_mmsi', line)
        track = self.tracks.get(msg.mmsi)
        if track is None:
            track = Track(int(msg.mmsi))
        self.decoded[kind] = self.decoded.get(kind, 0) + 1
        track.klass = 'A' if kind in (1, 2, 3, 5) else 'B'
        if kind in STATIC_TYPES:
            self._static(track, msg, kind, t)
        if kind in POSITION_TYPES and not self._position(track, msg, line, t):
            if track.t is None and track.t_static is None:
                return None                           # nothing known: do not open a track
        self.tracks[track.mmsi] = track
        return track.mmsi

    def _static(self, track, msg, kind, t):
        name = getattr(msg, 'shipname', None)
        if name:
            track.name = name.strip('@ ') or track.name
        ship_type = getattr(msg, 'ship_type', None)
        if ship_type is not None:
            track.ship_type = int(ship_type)
        if getattr(msg, 'to_bow', None) is not None:
            track.to_bow, track.to_stern = int(msg.to_bow), int(msg.to_stern)
            track.to_port, track.to_starboard = int(msg.to_port), int(msg.to_starboard)
        track.t_static = t

    def _position(self, track, msg, line, t):
        lat, lon = msg.lat, msg.lon
        if lat is None or lon is None or not (abs(lat) <= 90.0 and abs(lon) <= 180.0):
            self._reject('position_not_available', line)
            return False
        sog, cog = msg.speed, msg.course
        if sog is None or cog is None or sog >= SOG_NOT_AVAILABLE or cog >= COG_NOT_AVAILABLE:
            self._reject('velocity_not_available', line)
            sog, cog = 0.0, 0.0
        north, east = geodetic_to_ned(lat, lon, self.lat0, self.lon0)
        track.t, track.lat, track.lon = t, float(lat), float(lon)
        track.north, track.east = float(north), float(east)
        track.sog, track.cog = float(sog) * KNOT, math.radians(float(cog))
        heading = msg.heading
        track.heading = (math.radians(float(heading)) if heading is not None
                         and heading != HEADING_NOT_AVAILABLE and 0 <= heading < 360 else None)
        status = getattr(msg, 'status', None)         # class A only (messages 1-3)
        track.moored = status is not None and int(status) in (1, 5)
        track.reports += 1
        return True

    def _reject(self, reason, line):
        self.bad[reason] += 1
        self.last_bad = (reason, line.decode('ascii', 'replace') if isinstance(line, bytes)
                         else line)
        return None

    @property
    def pending_fragments(self):
        """Multi-sentence messages begun and not yet complete."""
        return len(self._parts)

    # -- output ------------------------------------------------------------------------------

    def prune(self, t):
        """Drop tracks without any report for more than stale_after_s (and expired fragments);
        return the MMSIs dropped."""
        self.expire_fragments(t)
        limit = self.stale_after_s
        gone = []
        for mmsi, tr in self.tracks.items():
            last = max(x for x in (tr.t, tr.t_static, -math.inf) if x is not None)
            if t - last > limit:
                gone.append(mmsi)
        for mmsi in gone:
            del self.tracks[mmsi]
        return gone

    def state(self, mmsi, t):
        """The target dead-reckoned to time t, None if unknown, without position or stale."""
        tr = self.tracks.get(mmsi)
        if tr is None or tr.t is None:
            return None
        age = t - tr.t
        if age > self.stale_after_s:
            return None
        dt = max(age, 0.0)
        north, east = dead_reckon(tr.north, tr.east, tr.sog, tr.cog, dt)
        psi = tr.heading if tr.heading is not None else tr.cog
        return TargetState(tr.mmsi, t, north, east, tr.sog, tr.cog, psi, age, tr)

    def targets(self, t):
        """Live targets at time t (stale tracks pruned first), sorted by MMSI."""
        self.prune(t)
        out = (self.state(m, t) for m in sorted(self.tracks))
        return [s for s in out if s is not None]
