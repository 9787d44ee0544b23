"""AIS as a sensor: what a receiver hears of a vessel's true track, and when.

Per vessel (one ``AisSensor.step`` per true state, any step size) the model decides when the
transponder transmits, whether the report is received, what it carries and when it arrives:

Reporting intervals, ITU-R M.1371-5 (2014), Annex 1, Table 1 (class A) and Table 2 (class B):

  class A  at anchor or moored, not faster than 3 kn          3 min
           at anchor or moored, faster than 3 kn              10 s
           0-14 kn                                             10 s
           0-14 kn and changing course                         3 1/3 s
           14-23 kn                                            6 s
           14-23 kn and changing course                        2 s
           > 23 kn (changing course or not)                    2 s
  class B "SO" (SOTDMA)  not faster than 2 kn 3 min, 2-14 kn 30 s, 14-23 kn 15 s, > 23 kn 5 s
  class B "CS" (CSTDMA)  not faster than 2 kn 3 min, faster than 2 kn 30 s
  static and voyage data (messages 5, 24)                     6 min

A speed on a band's boundary belongs to the slower band (14 kn: 10 s). M.1371 leaves the test
for "changing course" to the equipment standards; here a vessel changes course while its rate
of turn is at least ``turn_threshold_deg_min`` (our choice, default 10 deg/min). A change of
interval takes effect at once (the next report is due one new interval after the last one).
A SOTDMA station picks each slot at random within a selection interval of +-10 % of the
nominal increment (Annex 2, 4.4.1), so an interval is the nominal one times 1 + U(-0.1, 0.1);
the first report of a vessel comes at a uniformly random phase within its first interval.
Reports are made at the step times the caller gives: a report due between two steps goes out
at the later one (use steps much shorter than the intervals).

Reception: a two-state Gilbert-Elliott chain per vessel, advanced once per transmission: in
the good state every report is received, in the bad state every report is lost (Gilbert 1960,
Elliott 1963). It is given in a mariner's terms: ``loss_probability`` L (the stationary share
of lost reports) and ``mean_burst_length`` b (reports lost in a row, on average): the chain
leaves the bad state with r = 1/b per report and enters it with p = r L / (1 - L), so that
P(bad) = p / (p + r) = L and bursts are geometric with mean 1/r = b (p <= 1 needs
b >= L / (1 - L)). b = 1 / (1 - L) makes losses independent (p + r = 1). Defaults (our
choice, not measured): L = 0.05, b = 2.

What a received report carries: the position of the GNSS antenna, which sits
(``antenna_x_m`` forward, ``antenna_y_m`` to starboard) from the vessel's reference point,
plus Gaussian noise of ``position_sigma_m`` per axis (north, east); SOG, COG and true heading
each plus Gaussian noise (``sog_sigma_kn``, ``cog_sigma_deg``, ``heading_sigma_deg``;
SOG kept >= 0); the rate of turn. Reception delay: ``latency_s`` + U(0, ``latency_jitter_s``);
a report is handed out only once the caller's time reaches its time of reception.
Encoding (ship_guidance.aivdm_out) quantises on top: position 1/10000 arc minute, SOG 0.1 kn,
COG 0.1 deg, heading 1 deg.

Randomness: every vessel has its own numpy Generator seeded with (seed, MMSI), so its reports
depend only on its own inputs: the same inputs give the same reports bit for bit, whatever
order the vessels' steps interleave in (one ROS callback per odometry topic).
An own ship (``own``, AIVDO: the transponder's output to its own plotter) loses nothing and
has no reception delay; its GNSS noise is the same.
"""
import math
from dataclasses import dataclass

import numpy as np

from ship_guidance.ais import KNOT
from ship_sim.geodetic import ned_to_geodetic

CLASSES = ('A', 'B', 'SO')            # class A, class B "CS", class B "SO"
STATIC_INTERVAL_S = 360.0             # messages 5 and 24 (M.1371-5 Annex 1, Tables 1 and 2)
SLOT_SELECTION = 0.1                  # +-10 % selection interval (M.1371-5 Annex 2, 4.4.1)


def report_interval(klass, sog_kn, turning=False, moored=False):
    """Nominal interval (s) between position reports (ITU-R M.1371-5, Annex 1, Tables 1, 2)."""
    if klass == 'A':
        if moored:
            return 180.0 if sog_kn <= 3.0 else 10.0
        if sog_kn <= 14.0:
            return 10.0 / 3.0 if turning else 10.0
        if sog_kn <= 23.0:
            return 2.0 if turning else 6.0
        return 2.0
    if klass == 'B':
        return 180.0 if sog_kn <= 2.0 else 30.0
    if klass == 'SO':
        if sog_kn <= 2.0:
            return 180.0
        return 30.0 if sog_kn <= 14.0 else 15.0 if sog_kn <= 23.0 else 5.0
    raise ValueError(f'AIS class must be one of {", ".join(CLASSES)}, got {klass!r}')


@dataclass(frozen=True)
class SensorConfig:
    """Parameters of the sensor model (module docstring); validated by ``check``."""
    loss_probability: float = 0.05
    mean_burst_length: float = 2.0     # reports
    position_sigma_m: float = 3.0
    sog_sigma_kn: float = 0.1
    cog_sigma_deg: float = 1.0
    heading_sigma_deg: float = 0.5
    latency_s: float = 0.0
    latency_jitter_s: float = 0.0
    turn_threshold_deg_min: float = 10.0
    seed: int = 0

    def check(self):
        """ValueError naming the first bad field; returns self."""
        L, b = self.loss_probability, self.mean_burst_length
        for name in ('position_sigma_m', 'sog_sigma_kn', 'cog_sigma_deg', 'heading_sigma_deg',
                     'latency_s', 'latency_jitter_s', 'turn_threshold_deg_min'):
            v = getattr(self, name)
            if not (math.isfinite(v) and v >= 0.0):
                raise ValueError(f'{name} must be a finite number >= 0, got {v!r}')
        if not 0.0 <= L < 1.0:
            raise ValueError(f'loss_probability must be in [0, 1), got {L!r}')
        if not (math.isfinite(b) and b >= 1.0):
            raise ValueError(f'mean_burst_length must be >= 1 report, got {b!r}')
        if L > 0.0 and (1.0 / b) * L / (1.0 - L) > 1.0:
            raise ValueError(f'mean_burst_length {b:g} is too short for loss_probability '
                             f'{L:g}: give at least {L / (1.0 - L):.3g} reports')
        return self


class GilbertElliott:
    """Two-state loss chain: good (nothing lost) <-> bad (everything lost), one step per report.

    ``p`` = P(good -> bad), ``r`` = P(bad -> good); stationary loss share p / (p + r), mean
    burst length 1 / r. Starts in its stationary distribution."""

    def __init__(self, p, r, rng):
        self.p, self.r, self.rng = p, r, rng
        self.bad = bool(p > 0.0 and rng.random() < p / (p + r))

    @classmethod
    def from_loss(cls, loss_probability, mean_burst_length, rng):
        r = 1.0 / mean_burst_length
        return cls(r * loss_probability / (1.0 - loss_probability), r, rng)

    def lost(self):
        """Advance one report; True if this report is lost."""
        u = self.rng.random()
        self.bad = u >= self.r if self.bad else u < self.p
        return self.bad


@dataclass(frozen=True)
class Truth:
    """True state of a vessel's reference point: NED (m), SOG (m/s), COG and heading (rad,
    clockwise from north), rate of turn (rad/s, clockwise)."""
    t: float
    north: float
    east: float
    psi: float
    sog: float
    cog: float
    rot: float = 0.0
    moored: bool = False


@dataclass(frozen=True)
class Report:
    """One AIS position report as received, ready to encode (ship_guidance.aivdm_out)."""
    t_sent: float            # s, the position's time
    t_received: float        # s
    mmsi: int
    klass: str               # 'A', 'B' (CS) or 'SO'
    lat: float               # deg, the antenna's, with noise
    lon: float
    north: float             # m, the same position in the local plane
    east: float
    sog_kn: float
    cog_deg: float           # [0, 360)
    heading_deg: float       # [0, 360)
    rot_deg_min: float
    turning: bool            # sent at the "changing course" rate
    moored: bool


def antenna_position(north, east, psi, x_fwd, y_stbd):
    """NED position of a point (x forward, y to starboard) of a vessel at (north, east, psi)."""
    c, s = math.cos(psi), math.sin(psi)
    return north + x_fwd * c - y_stbd * s, east + x_fwd * s + y_stbd * c


class _Vessel:
    __slots__ = ('mmsi', 'klass', 'own', 'antenna', 'rng', 'chain', 'next_due', 'last_sent',
                 'nominal', 'factor', 'pending', 'sent', 'lost')

    def __init__(self, mmsi, klass, own, antenna, config):
        if klass not in CLASSES:
            raise ValueError(f'AIS class of {mmsi} must be one of {", ".join(CLASSES)}, '
                             f'got {klass!r}')
        self.mmsi, self.klass, self.own, self.antenna = int(mmsi), klass, own, antenna
        self.rng = np.random.default_rng([int(config.seed), int(mmsi)])
        L = 0.0 if own else config.loss_probability
        self.chain = GilbertElliott.from_loss(L, config.mean_burst_length, self.rng)
        self.next_due = None
        self.last_sent = None
        self.nominal = None        # interval and slot factor the next report was planned with
        self.factor = 1.0
        self.pending = []
        self.sent = 0
        self.lost = 0


class AisSensor:
    """The sensor model of the module docstring for any number of vessels (by MMSI)."""

    def __init__(self, lat0_deg, lon0_deg, config=SensorConfig()):
        self.config = config.check()
        self.lat0, self.lon0 = lat0_deg, lon0_deg
        ned_to_geodetic(0.0, 0.0, lat0_deg, lon0_deg)       # refuses a bad origin now
        self.vessels = {}

    def add(self, mmsi, klass='A', own=False, antenna=(0.0, 0.0)):
        """Register a vessel: AIS class, own ship (AIVDO) or not, antenna (x fwd, y stbd) m."""
        if mmsi in self.vessels:
            raise ValueError(f'MMSI {mmsi} given twice')
        if not 0 < int(mmsi) < 10**9:
            raise ValueError(f'MMSI must have at most 9 digits and not be 0, got {mmsi!r}')
        self.vessels[mmsi] = _Vessel(mmsi, klass, own, tuple(map(float, antenna)), self.config)

    def interval(self, mmsi, truth):
        """Nominal report interval (s) of ``mmsi`` in the state ``truth``, and whether it is
        the "changing course" one."""
        v = self.vessels[mmsi]
        turning = abs(math.degrees(truth.rot)) * 60.0 >= self.config.turn_threshold_deg_min
        sog_kn = truth.sog / KNOT
        return report_interval(v.klass, sog_kn, turning, truth.moored), turning

    def step(self, mmsi, truth):
        """Feed the true state of ``mmsi`` at truth.t (non-decreasing per vessel); returns the
        reports of ``mmsi`` received by truth.t (time of reception order)."""
        v = self.vessels[mmsi]
        t = truth.t
        nominal, turning = self.interval(mmsi, truth)
        if v.next_due is None:
            v.next_due = t + v.rng.uniform(0.0, nominal)
        elif v.last_sent is not None and nominal != v.nominal:
            v.next_due = v.last_sent + nominal * v.factor
        v.nominal = nominal
        if t >= v.next_due:
            v.last_sent = t
            v.factor = 1.0 + v.rng.uniform(-SLOT_SELECTION, SLOT_SELECTION)
            v.next_due = t + nominal * v.factor
            v.sent += 1
            if v.chain.lost():
                v.lost += 1
            else:
                v.pending.append(self._report(v, truth, turning))
        if not v.pending or v.pending[0].t_received > t:
            return []
        out = sorted((r for r in v.pending if r.t_received <= t), key=lambda r: r.t_received)
        v.pending = [r for r in v.pending if r.t_received > t]
        return out

    def _report(self, v, truth, turning):
        c, rng = self.config, v.rng
        north, east = antenna_position(truth.north, truth.east, truth.psi, *v.antenna)
        dn, de, dsog, dcog, dhdg = rng.standard_normal(5)
        north += c.position_sigma_m * dn
        east += c.position_sigma_m * de
        lat, lon = ned_to_geodetic(north, east, self.lat0, self.lon0)
        delay = 0.0 if v.own else c.latency_s + c.latency_jitter_s * rng.random()
        return Report(
            t_sent=truth.t, t_received=truth.t + delay, mmsi=v.mmsi, klass=v.klass,
            lat=lat, lon=lon, north=north, east=east,
            sog_kn=max(0.0, truth.sog / KNOT + c.sog_sigma_kn * dsog),
            cog_deg=(math.degrees(truth.cog) + c.cog_sigma_deg * dcog) % 360.0,
            heading_deg=(math.degrees(truth.psi) + c.heading_sigma_deg * dhdg) % 360.0,
            rot_deg_min=math.degrees(truth.rot) * 60.0, turning=turning, moored=truth.moored)
