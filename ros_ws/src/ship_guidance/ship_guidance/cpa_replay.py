"""Replay a recorded AIS log through the decoder and the tracker: CPA/TCPA per target over time.

Input: an ``ais_log.AisLog`` (timed sentences). The sentences go in time order to
ais.AisTracker (decoding, multi-sentence assembly, static data) and every new position report
to tracker.Tracker (a Kalman filter per MMSI), stamped with the log time, exactly as
tracker_node feeds them from UDP. Every ``period_s`` of log time (a grid from the first
sentence; periods without any track are skipped) each live track is predicted to that time
and compared with the own ship:

    range, true bearing            cpa.range_and_bearing of the two estimated positions
    CPA distance, TCPA             cpa.cpa of the estimated positions and velocities
    their sigmas                   cpa.cpa_sigma of the two tracks' covariances (summed:
                                   independent filters fed by independent reports)
    situation                      colregs.classify of the same states (headings: the reported
                                   true heading, else the estimated COG)

The situation is the COLREGs geometry only, not what colav would decide: that needs the own
ship's route, its colav parameters and its manoeuvring model, which a recorded log does not
hold.

The own ship, one of:
  - an MMSI (``own_mmsi``): that ship's position reports, tracked like any other;
  - the ship of the log's AIVDO position reports (the default): a transponder's own reports;
    AIVDO position reports from two MMSIs are refused (give the MMSI);
  - a fixed ship (``FixedOwnShip``): a position at the first sentence's time, a course and a
    speed, exact (zero covariance); with speed 0 a shore observer such as the receiver.
The local plane (ship_sim.geodetic) has its origin at the own ship's first position; targets
farther than ``max_range_m`` from the own ship give no rows (counted): the plane is accurate to
a fraction of a metre within tens of kilometres of its origin, and CPA beyond that horizon is
not a collision question.

Bounds of the numbers (tests/unit/test_ais_cpa.py): for ships on straight tracks the only
errors are AIS's quantisation (position 1/10000 arc minute, SOG 0.1 kn, COG 0.1 deg), which
the Kalman estimates average; the CPA from the tracks then agrees with the analytic CPA of the
true tracks within a bound derived there from that quantisation and the filter's covariance.
"""
import math
from collections import Counter
from dataclasses import asdict, dataclass, field

import numpy as np

from ship_guidance.ais import KNOT, AisTracker
from ship_guidance.colregs import SITUATIONS, classify
from ship_guidance.cpa import cpa, cpa_sigma, range_and_bearing
from ship_guidance.tracker import AisReport, Tracker, TrackerConfig

#: Default horizon (m): 20 nautical miles, beyond a collision-avoidance decision's range and
#: within the local plane's sub-metre radius (ship_sim.geodetic).
MAX_RANGE_M = 20.0 * 1852.0
#: Sentences between two progress calls.
PROGRESS_EVERY = 10_000


class ReplayError(ValueError):
    """The replay cannot run as asked (one-line message): no own ship, two AIVDO ships."""


@dataclass(frozen=True)
class FixedOwnShip:
    """An own ship not in the log: position (deg) at the log's first time, COG (deg), SOG (kn)."""
    lat: float
    lon: float
    cog_deg: float = 0.0
    sog_kn: float = 0.0


@dataclass(frozen=True)
class ReplayConfig:
    period_s: float = 10.0
    max_range_m: float = MAX_RANGE_M
    tracker: TrackerConfig = TrackerConfig()

    def check(self):
        for name in ('period_s', 'max_range_m'):
            v = getattr(self, name)
            if not (math.isfinite(v) and v > 0.0):
                raise ValueError(f'{name} must be a finite number > 0, got {v!r}')
        self.tracker.check()
        return self


@dataclass(frozen=True)
class Row:
    """One target at one output time (the CSV's columns, in this order)."""
    t_s: float                 # log time
    mmsi: int
    name: str                  # from static data, '' until known
    range_m: float
    bearing_deg: float         # true, from the own ship
    cpa_m: float
    tcpa_s: float              # < 0: the closest point is past, the range is opening
    cpa_sigma_m: float
    tcpa_sigma_s: float
    position_sigma_m: float    # the target track's (largest axis of its position covariance)
    report_age_s: float        # since the target's newest report
    reports: int               # position reports in the target's track
    situation: str             # colregs.SITUATIONS


FIELDS = tuple(Row.__dataclass_fields__)


@dataclass
class _Own:
    source: str                # 'aivdo', 'mmsi' or 'fixed'
    mmsi: int = None
    lat: float = None
    lon: float = None
    fixed: FixedOwnShip = None


@dataclass
class Replay:
    """The result: ``rows`` (Row, time order) and ``summary`` (JSON-ready dict)."""
    rows: list = field(default_factory=list)
    summary: dict = field(default_factory=dict)


def _is_vdo(sentence):
    return sentence.split(',', 1)[0][3:] == 'VDO'


def _first_position(sentences, want):
    """(mmsi, lat, lon) of the first position report for which want(mmsi, is_vdo) holds."""
    dec = AisTracker(0.0, 0.0)
    seen = {}
    for t, s in sentences:
        mmsi = dec.feed(s, t)
        track = dec.tracks.get(mmsi) if mmsi is not None else None
        if track is None or track.reports == seen.get(mmsi, 0):
            continue
        seen[mmsi] = track.reports
        if want(mmsi, _is_vdo(s)):
            return mmsi, track.lat, track.lon
    return None


def _own_ship(sentences, own_mmsi, fixed):
    if fixed is not None:
        return _Own('fixed', None, fixed.lat, fixed.lon, fixed)
    if own_mmsi is not None:
        got = _first_position(sentences, lambda m, vdo: m == own_mmsi)
        if got is None:
            raise ReplayError(f'MMSI {own_mmsi} has no position report in the log')
        return _Own('mmsi', *got)
    got = _first_position(sentences, lambda m, vdo: vdo)
    if got is None:
        raise ReplayError('the log has no AIVDO (own-ship) position report: name the own '
                          'ship by its MMSI or give a fixed own ship')
    return _Own('aivdo', *got)


class _Run:
    def __init__(self, log, own, config, progress):
        self.log, self.own, self.config, self.progress = log, own, config, progress
        self.dec = AisTracker(own.lat, own.lon)
        self.trk = Tracker(config.tracker)
        self.used = {}                       # MMSI -> decoder report count already tracked
        self.reports = Counter()             # MMSI -> position reports given to the tracker
        self.names, self.types = {}, {}
        self.intervals = {}                  # MMSI -> [[t opened, t deleted or None], ...]
        self.rows = []
        self.beyond_range = Counter()
        self.periods_without_own = 0
        self.t0 = log.sentences[0][0]
        if own.fixed is not None:
            f = own.fixed
            self.own_v = f.sog_kn * KNOT * np.array([math.cos(math.radians(f.cog_deg)),
                                                     math.sin(math.radians(f.cog_deg))])

    # -- input ----------------------------------------------------------------------------

    def feed(self, t, sentence):
        dec = self.dec
        no_velocity = dec.bad['velocity_not_available']
        mmsi = dec.feed(sentence, t)
        track = dec.tracks.get(mmsi) if mmsi is not None else None
        if track is None:
            return
        if track.name:
            self.names[mmsi] = track.name
        if track.ship_type is not None:
            self.types[mmsi] = track.ship_type
        if track.reports == self.used.get(mmsi, 0):
            return                                   # static data only
        self.used[mmsi] = track.reports
        own = self.own
        if own.source == 'aivdo' and _is_vdo(sentence) and mmsi != own.mmsi:
            raise ReplayError(f'AIVDO position reports from two MMSIs ({own.mmsi}, {mmsi}): '
                              f'name the own ship by its MMSI')
        velocity = dec.bad['velocity_not_available'] == no_velocity
        status = self.trk.update(AisReport(
            mmsi, t, track.north, track.east, track.sog if velocity else None,
            track.cog if velocity else None, track.heading,
            'A' if track.klass == 'A' else 'B', track.moored))
        self.reports[mmsi] += 1
        if status == 'new':
            self.intervals.setdefault(mmsi, []).append([t, None])

    # -- output ---------------------------------------------------------------------------

    def own_state(self, t):
        """(position, velocity, covariance 4x4, heading) of the own ship at t, or None."""
        own = self.own
        if own.fixed is not None:
            v = self.own_v
            return v * (t - self.t0), v, np.zeros((4, 4)), math.radians(own.fixed.cog_deg)
        est = self.trk.estimate(own.mmsi, t)
        if est is None:
            return None
        return est.x[:2], est.x[2:], est.P, est.heading if est.heading is not None else est.cog

    def emit(self, t):
        for mmsi in self.dec.prune(t):
            self.used.pop(mmsi, None)
        for mmsi in self.trk.prune(t):
            self.intervals[mmsi][-1][1] = t
        state = self.own_state(t)
        if state is None:
            self.periods_without_own += 1
            return
        ests = [e for e in self.trk.tracks(t) if e.mmsi != self.own.mmsi]
        if not ests:
            return
        p_o, v_o, P_o, psi_o = state
        x = np.array([e.x for e in ests])
        P = np.array([e.P for e in ests]) + P_o
        psi = np.array([e.heading if e.heading is not None else e.cog for e in ests])
        tcpa, dcpa = cpa(p_o, v_o, x[:, :2], x[:, 2:])
        s_tcpa, s_dcpa = cpa_sigma(p_o, v_o, x[:, :2], x[:, 2:], P)
        rng, brg = range_and_bearing(p_o, x[:, :2])
        code = classify(p_o, psi_o, v_o, x[:, :2], psi, x[:, 2:])
        for i, e in enumerate(ests):
            if rng[i] > self.config.max_range_m:
                self.beyond_range[e.mmsi] += 1
                continue
            self.rows.append(Row(
                float(t), e.mmsi, self.names.get(e.mmsi, ''), float(rng[i]),
                math.degrees(float(brg[i])), float(dcpa[i]), float(tcpa[i]), float(s_dcpa[i]),
                float(s_tcpa[i]), e.position_sigma_m, float(t - e.t_report), e.n_reports,
                SITUATIONS[int(code[i])]))

    # -- the loop -------------------------------------------------------------------------

    def run(self):
        sentences = self.log.sentences
        period, t0 = self.config.period_s, self.t0
        k = 0                                        # next output at t0 + k period
        n = len(sentences)
        for i, (t, sentence) in enumerate(sentences):
            while t0 + k * period < t:
                if not len(self.trk):                # nothing to report: skip to t
                    k = max(k, math.ceil((t - t0) / period))
                    if t0 + k * period < t:
                        k += 1
                    break
                self.emit(t0 + k * period)
                k += 1
            self.feed(t, sentence)
            if self.progress is not None and (i + 1) % PROGRESS_EVERY == 0:
                self.progress(i + 1, n)
        t_last = sentences[-1][0]
        while t0 + k * period <= t_last:
            self.emit(t0 + k * period)
            k += 1
        if self.progress is not None:
            self.progress(n, n)
        return Replay(self.rows, self.summary())

    def summary(self):
        by_target = {}
        for r in self.rows:
            by_target.setdefault(r.mmsi, []).append(r)
        targets = []
        for mmsi in sorted(set(self.reports) - {self.own.mmsi}):
            rows = by_target.get(mmsi, [])
            ahead = [r for r in rows if r.tcpa_s >= 0.0]
            best = min(ahead, key=lambda r: r.cpa_m) if ahead else None
            near = min(rows, key=lambda r: r.range_m) if rows else None
            targets.append({
                'mmsi': mmsi, 'name': self.names.get(mmsi, ''),
                'ship_type': self.types.get(mmsi), 'position_reports': self.reports[mmsi],
                'tracks': self.intervals.get(mmsi, []), 'rows': len(rows),
                'periods_beyond_range': self.beyond_range[mmsi],
                'min_cpa': None if best is None else {
                    't_s': best.t_s, 'cpa_m': best.cpa_m, 'tcpa_s': best.tcpa_s,
                    't_cpa_s': best.t_s + best.tcpa_s, 'cpa_sigma_m': best.cpa_sigma_m,
                    'range_m': best.range_m, 'situation': best.situation},
                'min_range': None if near is None else {'t_s': near.t_s,
                                                        'range_m': near.range_m}})
        targets.sort(key=lambda d: (d['min_cpa'] is None,
                                    d['min_cpa']['cpa_m'] if d['min_cpa'] else 0.0, d['mmsi']))
        log, dec, trk, own = self.log, self.dec, self.trk, self.own
        opened = sum(len(v) for m, v in self.intervals.items())
        deleted = sum(1 for v in self.intervals.values() for a in v if a[1] is not None)
        return {
            'log': {'form': log.form, 'unix_time': log.unix_time, 'lines': log.lines,
                    'sentences': len(log.sentences), 'rejected': dict(sorted(
                        log.rejected.items())), 'times_inherited': log.inherited,
                    't_first_s': log.sentences[0][0], 't_last_s': log.sentences[-1][0]},
            'decoder': {'rejected': {k: v for k, v in dec.bad.items()
                                     if v and k != 'velocity_not_available'},
                        'reports_without_velocity': dec.bad['velocity_not_available'],
                        'decoded_types': {str(k): v for k, v in sorted(dec.decoded.items())},
                        'ignored_types': {str(k): v for k, v in sorted(dec.ignored.items())}},
            'tracker': {'position_reports': sum(self.reports.values()),
                        'duplicates': trk.duplicates, 'late_dropped': trk.late_dropped,
                        'late_reprocessed': trk.reprocessed, 'tracks_opened': opened,
                        'tracks_deleted': deleted},
            'own_ship': {'source': own.source, 'mmsi': own.mmsi,
                         'name': self.names.get(own.mmsi, ''), 'origin_deg': [own.lat, own.lon],
                         'fixed': None if own.fixed is None else asdict(own.fixed),
                         'periods_without_own_ship': self.periods_without_own},
            'settings': {'period_s': self.config.period_s,
                         'max_range_m': self.config.max_range_m,
                         'tracker': asdict(self.config.tracker)},
            'rows': len(self.rows),
            'targets': targets}


def replay(log, own_mmsi=None, own_fixed=None, config=ReplayConfig(), progress=None):
    """Replay ``log`` (module docstring); ``progress(done, total)`` is called every
    PROGRESS_EVERY sentences and at the end. Returns a ``Replay``."""
    config.check()
    if own_mmsi is not None and own_fixed is not None:
        raise ReplayError('give the own ship by MMSI or as a fixed ship, not both')
    if not log.sentences:
        raise ReplayError('the log has no sentence')
    own = _own_ship(log.sentences, own_mmsi, own_fixed)
    return _Run(log, own, config, progress).run()
