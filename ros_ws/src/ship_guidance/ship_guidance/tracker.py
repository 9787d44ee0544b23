"""Multi-target tracker for AIS reports: one Kalman filter per MMSI, with covariance (pure).

Feed position reports (``AisReport``: MMSI, time, local NED position, SOG, COG, heading, AIS
class) to ``Tracker.update``; read the tracks predicted to any time with ``Tracker.tracks(t)``
or ``Tracker.estimate(mmsi, t)`` (``TrackEstimate``: state and its covariance).

Model: nearly constant velocity (white-noise acceleration), state x = [north, east, v_north,
v_east] (m, m/s) in the local plane. Over dt the state goes x <- F x with F = [[I, dt I],
[0, I]] and the covariance gains Q = q [[dt^3/3 I, dt^2/2 I], [dt^2/2 I, dt I]], q the
acceleration's power spectral density (``process_noise``, m^2/s^3; Bar-Shalom, Li and
Kirubarajan 2001, 6.2.2). The default q = 5e-3 m^2/s^3 lets the velocity wander by sqrt(q dt):
0.2 m/s over a 10 s class A interval, 1 m/s over 3 min. It is sized for turns: a ship turning
at 30 deg/min at 10 kn accelerates at 0.045 m/s^2, and with it the filter's errors stay within
its covariance (tests/unit/test_tracker.py) while a straight course is tracked with little
more noise than with a smaller q (a filter with a smaller q is overconfident in such a turn).

Measurement: the reported position and the velocity from SOG and COG, z = [north, east,
sog cos(cog), sog sin(cog)], with R = diag(sigma_p^2, sigma_p^2) for the position and, for the
velocity, J diag(sigma_sog^2, sigma_cog^2) J^T (J the Jacobian of the polar-to-NED map at the
reported SOG and COG). The sigmas default to the AIS sensor model's (ship_guidance.ais_sensor
.SensorConfig: the one place for those numbers); AIVDM's quantisation (0.1 kn, 0.1 deg,
1/10000 arc minute, ship_guidance.aivdm_out) is small beside them and not added. A report
without SOG or COG (AIS "not available") updates the position only. The update is the Joseph
form, which keeps P symmetric and positive definite. The tracked point is the GNSS antenna's
(AIS reports its position; the offset to the reference point is not applied).

Initiation: the first report of an MMSI opens its track with x from the report and P = R
(without a velocity: a velocity variance of INITIAL_SPEED_SIGMA_MPS^2 per axis).

Association: by MMSI (AIS carries its identity); no gating, every report is used.

Late (out-of-sequence) reports: a report whose time is before its track's newest report is
retrodicted by reprocessing: each track keeps its reports of the last ``reprocess_window_s``
with the estimate after each; the late report is filtered in after the newest kept estimate
older than it and the later reports are filtered again, which is the estimate the reports
would have given in time order. A report older than every kept estimate (or than the track's
first report) is dropped and counted in ``late_dropped``; a second report with the same time
as one kept is a duplicate (two receivers hearing one transmission) and is counted in
``duplicates``.

Deletion: a track is deleted once its newest report is more than ``expiry_s`` old: the longer
of ais.STALE_AFTER_S (360 s, ais_node's rule) and EXPIRY_INTERVALS report intervals of its
last report (ais_sensor.report_interval from its class, SOG and whether it was moored), so a
3-min reporter (class A at anchor, class B at 2 kn or less) keeps its track through two lost
reports in a row: 540 s. Prediction goes on with a growing covariance until then.

Radar plots (no identity; ``Tracker.associate_radar``): gated nearest neighbour on the
Mahalanobis distance. The plot (NED position, its sigma per axis) is compared with every live
track predicted to its time; d^2 = y^T S^-1 y with y the innovation and S = H P H^T + R, and
the plot goes to the track of the smallest d^2 if that is within the gate (``radar_gate``,
default the chi-square 99 % point of 2 degrees of freedom, 9.21), as a position-only update.
Confirmed tracks first (``confirmed_reports``): a plot in the gate of a track with that many
reports goes to the nearest such track, and to a tentative one only if it is in no confirmed
gate. Without that rule, a tentative track that a stray plot opened beside a confirmed one
(about 1 plot in 100 falls outside the true track's 99 % gate) wins the target's plots by
nearest neighbour whenever its larger covariance makes its d^2 the smaller, and the
confirmed track can starve and be deleted: the target's identity is lost.
Not done: a plot outside every gate is returned unused (no radar-only track initiation),
tracks older than the plot only are candidates (a plot older than a track's newest report
would need that track's reprocessing), and two plots never compete for one track (no global
nearest neighbour or JPDA): the plots are taken one at a time.

Library: plain numpy, not filterpy or Stone Soup (both on PyPI). The filter is 4 states and
a few lines; filterpy's predict/update cost about what this one does per call, but importing
filterpy.kalman loads matplotlib at every node start, and its filter object holds state that
the late-report reprocessing would have to copy in and out; Stone Soup is a framework of its
own (types, deleters, initiators) far larger than this need.
"""
import math
from bisect import bisect_right
from dataclasses import dataclass, field

import numpy as np

from ship_guidance.ais import KNOT, STALE_AFTER_S
from ship_guidance.ais_sensor import SensorConfig, report_interval

_SENSOR = SensorConfig()
#: Report intervals a track survives in silence beyond STALE_AFTER_S (the module docstring).
EXPIRY_INTERVALS = 3.0
#: Velocity sigma (m/s per axis) of a track opened by a report without SOG/COG: about the
#: speed of a fast merchant ship.
INITIAL_SPEED_SIGMA_MPS = 15.0
_I4 = np.eye(4)
_H_POS = np.eye(4)[:2]


@dataclass(frozen=True)
class TrackerConfig:
    """Noise model and bookkeeping of ``Tracker`` (module docstring); validated by ``check``."""
    process_noise: float = 5e-3                          # q, m^2/s^3
    position_sigma_m: float = _SENSOR.position_sigma_m
    sog_sigma_mps: float = _SENSOR.sog_sigma_kn * KNOT
    cog_sigma_rad: float = math.radians(_SENSOR.cog_sigma_deg)
    reprocess_window_s: float = 60.0
    radar_gate: float = 9.21                             # chi-square(2) 99 %: d^2 of a plot

    def check(self):
        """ValueError naming the first bad field; returns self."""
        for name in ('process_noise', 'sog_sigma_mps', 'cog_sigma_rad', 'reprocess_window_s',
                     'radar_gate'):
            v = getattr(self, name)
            if not (math.isfinite(v) and v >= 0.0):
                raise ValueError(f'{name} must be a finite number >= 0, got {v!r}')
        if not (math.isfinite(self.position_sigma_m) and self.position_sigma_m > 0.0):
            raise ValueError(f'position_sigma_m must be a finite number > 0, got '
                             f'{self.position_sigma_m!r}')
        return self


@dataclass(frozen=True)
class AisReport:
    """One AIS position report: ``t`` the time the position is valid (s; a receiver that only
    knows the time of reception gives that, the latency then becomes a lag), NED position (m),
    SOG (m/s) and COG (rad, clockwise from north), None when not available, true heading (rad)
    or None, AIS class ('A', 'B' or 'SO', ais_sensor.CLASSES) and whether the vessel reports
    itself moored or at anchor."""
    mmsi: int
    t: float
    north: float
    east: float
    sog: float | None = None
    cog: float | None = None
    heading: float | None = None
    klass: str = 'A'
    moored: bool = False
    position_sigma_m: float | None = None   # this report's own sigma (a radar plot), else config's

    @classmethod
    def from_sensor(cls, r, t=None):
        """From an ``ais_sensor.Report`` at its t_sent (or ``t``)."""
        return cls(r.mmsi, r.t_sent if t is None else t, r.north, r.east, r.sog_kn * KNOT,
                   math.radians(r.cog_deg), math.radians(r.heading_deg), r.klass, r.moored)


@dataclass(frozen=True)
class TrackEstimate:
    """A track at time ``t``: state x = [north, east, v_north, v_east] and its 4x4 covariance
    P, the newest report's time and heading (None if never reported), reports used."""
    mmsi: int
    t: float
    x: np.ndarray
    P: np.ndarray
    t_report: float
    heading: float | None
    klass: str
    n_reports: int

    @property
    def north(self):
        return float(self.x[0])

    @property
    def east(self):
        return float(self.x[1])

    @property
    def sog(self):
        return math.hypot(self.x[2], self.x[3])

    @property
    def cog(self):
        return math.atan2(self.x[3], self.x[2])

    @property
    def position_sigma_m(self):
        """Square root of the largest eigenvalue of the position covariance (m)."""
        return math.sqrt(max(float(np.linalg.eigvalsh(self.P[:2, :2])[-1]), 0.0))


def odometry_covariances(est, psi):
    """(pose, twist) covariances of a track as nav_msgs/Odometry carries them: 36 numbers
    each, row-major over (x, y, z, roll, pitch, yaw) and (vx, vy, vz, wx, wy, wz). Pose: the
    position block in ENU (x east, y north); yaw: the variance of the heading reported (the
    sensor's heading sigma) when ``est`` has one, else of the estimated COG (cross-track
    velocity variance / speed^2, at most pi^2). Twist: the velocity block rotated into the
    body frame FLU at heading ``psi`` (NED, rad). What the state does not hold (z, roll,
    pitch, their rates, the yaw rate) is 0, as in the simulators' odometry."""
    P = est.P
    pose, twist = [0.0] * 36, [0.0] * 36
    P = 0.5 * (P + P.T)                     # exactly symmetric, as a covariance is
    pose[0], pose[1], pose[6], pose[7] = P[1, 1], P[1, 0], P[0, 1], P[0, 0]
    if est.heading is not None:
        pose[35] = math.radians(_SENSOR.heading_sigma_deg) ** 2
    else:
        speed2 = est.sog ** 2
        c, s = math.cos(est.cog), math.sin(est.cog)
        cross = np.array([-s, c]) @ P[2:, 2:] @ np.array([-s, c])
        pose[35] = min(cross / speed2, math.pi ** 2) if speed2 > 0.0 else math.pi ** 2
    c, s = math.cos(psi), math.sin(psi)
    J = np.array([[c, s], [s, -c]])        # (vn, ve) -> (forward, left)
    V = J @ P[2:, 2:] @ J.T
    V = 0.5 * (V + V.T)
    twist[0], twist[1], twist[6], twist[7] = V[0, 0], V[0, 1], V[1, 0], V[1, 1]
    return [float(v) for v in pose], [float(v) for v in twist]


def transition(dt, q):
    """(F, Q) of the nearly-constant-velocity model over ``dt`` s (module docstring)."""
    F = np.eye(4)
    F[0, 2] = F[1, 3] = dt
    a, b, c = q * dt ** 3 / 3.0, q * dt ** 2 / 2.0, q * dt
    Q = np.array([[a, 0, b, 0], [0, a, 0, b], [b, 0, c, 0], [0, b, 0, c]])
    return F, Q


def predict(x, P, dt, q):
    F, Q = transition(dt, q)
    return F @ x, F @ P @ F.T + Q


def measurement(report, config):
    """(z, H, R) of a report (module docstring)."""
    sigma = config.position_sigma_m if report.position_sigma_m is None else report.position_sigma_m
    sp = sigma ** 2
    if report.sog is None or report.cog is None:
        return np.array([report.north, report.east]), _H_POS, np.diag([sp, sp])
    s, c = report.sog, report.cog
    cc, sc = math.cos(c), math.sin(c)
    J = np.array([[cc, -s * sc], [sc, s * cc]])
    R = np.zeros((4, 4))
    R[0, 0] = R[1, 1] = sp
    R[2:, 2:] = J @ np.diag([config.sog_sigma_mps ** 2, config.cog_sigma_rad ** 2]) @ J.T
    return np.array([report.north, report.east, s * cc, s * sc]), _I4, R


def update(x, P, z, H, R):
    """Kalman update in Joseph form; (x, P)."""
    S = H @ P @ H.T + R
    K = np.linalg.solve(S, H @ P).T          # P H^T S^-1 (S, P symmetric)
    x = x + K @ (z - H @ x)
    A = _I4 - K @ H
    P = A @ P @ A.T + K @ R @ K.T
    return x, 0.5 * (P + P.T)


def initial_state(report, config):
    z, H, R = measurement(report, config)
    if H is _H_POS:
        v = INITIAL_SPEED_SIGMA_MPS ** 2
        return np.array([z[0], z[1], 0.0, 0.0]), np.diag([R[0, 0], R[1, 1], v, v])
    return z.copy(), R.copy()


def expiry_s(report):
    """Silence after which a track whose newest report is ``report`` is deleted (module doc)."""
    sog_kn = 0.0 if report.sog is None else report.sog / KNOT
    interval = report_interval(report.klass, sog_kn, moored=report.moored)
    return max(STALE_AFTER_S, EXPIRY_INTERVALS * interval)


@dataclass
class _Track:
    mmsi: int
    history: list = field(default_factory=list)    # [(report, x, P)] in time order
    n_reports: int = 1

    @property
    def newest(self):
        return self.history[-1]


class Tracker:
    """Tracks by MMSI (module docstring); counters ``late_dropped``, ``duplicates``,
    ``reprocessed`` (late reports filtered in), ``deleted``."""

    def __init__(self, config=TrackerConfig()):
        self.config = config.check()
        self._tracks = {}
        self.late_dropped = 0
        self.duplicates = 0
        self.reprocessed = 0
        self.deleted = 0

    def __len__(self):
        return len(self._tracks)

    def __contains__(self, mmsi):
        return mmsi in self._tracks

    def update(self, report):
        """Use one report; returns 'new', 'updated', 'late' (retrodicted), 'late_dropped' or
        'duplicate'."""
        for v in (report.t, report.north, report.east):
            if not math.isfinite(v):
                raise ValueError(f'report of {report.mmsi}: non-finite time or position')
        c = self.config
        track = self._tracks.get(report.mmsi)
        if track is None:
            x, P = initial_state(report, c)
            self._tracks[report.mmsi] = _Track(report.mmsi, [(report, x, P)])
            return 'new'
        hist = track.history
        times = [r.t for r, _, _ in hist]
        i = bisect_right(times, report.t)          # entries at or before report.t: hist[:i]
        if i > 0 and times[i - 1] == report.t:
            self.duplicates += 1
            return 'duplicate'
        if i == 0:
            self.late_dropped += 1
            return 'late_dropped'
        late = i < len(hist)
        track.n_reports += 1
        redo = [report] + [r for r, _, _ in hist[i:]]
        del hist[i:]
        for r in redo:
            prev, x, P = hist[-1]
            x, P = predict(x, P, r.t - prev.t, c.process_noise)
            x, P = update(x, P, *measurement(r, c))
            hist.append((r, x, P))
        newest = hist[-1][0].t
        keep = bisect_right([r.t for r, _, _ in hist], newest - c.reprocess_window_s)
        if keep > 0:                      # keep at least the newest estimate before the window
            del hist[:min(keep - 1, len(hist) - 1)]
        if late:
            self.reprocessed += 1
            return 'late'
        return 'updated'

    def associate_radar(self, t, north, east, sigma_m, confirmed_reports=None):
        """A radar plot at ``t`` (NED position, sigma per axis, m) to its gated nearest track
        (module docstring): the MMSI it updated, or None if it falls in no track's gate. With
        ``confirmed_reports``, the tracks with at least that many reports come first: the plot
        goes to a track with fewer only if it falls in no such track's gate."""
        best = None     # (not confirmed, d2, mmsi, newest report): the smallest wins
        R = np.diag([sigma_m ** 2, sigma_m ** 2])
        z = np.array([north, east])
        for mmsi, track in self._tracks.items():
            r, x, P = track.newest
            if r.t > t:
                continue
            x, P = predict(x, P, t - r.t, self.config.process_noise)
            y = z - x[:2]
            d2 = float(y @ np.linalg.solve(P[:2, :2] + R, y))
            if d2 > self.config.radar_gate:
                continue
            rank = (confirmed_reports is not None and track.n_reports < confirmed_reports, d2)
            if best is None or rank < best[:2]:
                best = (*rank, mmsi, r)
        if best is None:
            return None
        *_, mmsi, last = best
        plot = AisReport(mmsi, t, north, east, klass=last.klass, moored=last.moored,
                         position_sigma_m=sigma_m)
        self.update(plot)
        return mmsi

    def prune(self, t):
        """Delete the tracks silent for longer than their expiry at ``t``; the MMSIs deleted."""
        gone = [m for m, tr in self._tracks.items()
                if t - tr.newest[0].t > expiry_s(tr.newest[0])]
        for m in gone:
            del self._tracks[m]
        self.deleted += len(gone)
        return gone

    def drop(self, mmsi):
        """Delete the track of ``mmsi`` now (a tentative radar track its owner gives up on);
        counted in ``deleted``. True if there was one."""
        if self._tracks.pop(mmsi, None) is None:
            return False
        self.deleted += 1
        return True

    def estimate(self, mmsi, t):
        """The track of ``mmsi`` predicted to ``t`` (a ``TrackEstimate``), None if there is
        none; at a time before its newest report, the newest estimate (a track never goes
        back in time). Does not delete."""
        track = self._tracks.get(mmsi)
        if track is None:
            return None
        r, x, P = track.newest
        if t > r.t:
            x, P = predict(x, P, t - r.t, self.config.process_noise)
        heading = next((h.heading for h, _, _ in reversed(track.history)
                        if h.heading is not None), None)
        return TrackEstimate(mmsi, max(t, r.t), x, P, r.t, heading, r.klass, track.n_reports)

    def tracks(self, t):
        """The live tracks at ``t`` (expired ones deleted first), sorted by MMSI."""
        self.prune(t)
        return [self.estimate(m, t) for m in sorted(self._tracks)]
