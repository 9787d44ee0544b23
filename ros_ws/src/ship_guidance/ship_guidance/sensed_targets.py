"""The targets colav sees at a sensor level: true states -> AIS / radar -> tracker -> colav (pure).

``SensedTargets(level, names, seed)``: call ``observe`` with the true target states at every
simulation step (the sensors decide when they report), ``targets(t)`` at a decision: the live,
confirmed tracks predicted to ``t`` as colav ``Target``s, each with its position sigma (the
square root of the largest eigenvalue of its position covariance), which widens its safe
distance in the decision (ColavParams.uncertainty_k). The levels and their numbers are
ship_guidance.sensor_levels'.

AIS: every target is a class ``level.ais_class`` transponder with an MMSI of its own
(``MMSI_BASE`` + its index in ``names``), its rate of turn the change of its true heading since
the previous step; each report received goes to the tracker stamped with its time of
reception (as tracker_node stamps it). The track keeps the target's name (AIS carries the
identity). Radar: each scan's plots go to the tracker's gated nearest neighbour
(Tracker.associate_radar); a plot in no gate opens a track ``radar<k>`` (k counting from 1),
position only, which colav sees once it has ``level.radar_confirm_plots`` plots; a radar
track without a plot for ``level.radar_coast_s`` is deleted.

``stats()``: what the sensors did and what colav saw (reports sent, lost, received; scans,
detections; the position sigma and the error of the tracks seen at the decisions, the error
against the nearest true target).
"""
import math

import numpy as np

from ship_guidance import colav_io
from ship_guidance.ais_sensor import AisSensor, Truth
from ship_guidance.radar_sensor import Radar
from ship_guidance.tracker import AisReport, Tracker
from ship_sim.frames import wrap_angle

#: MMSI of the first target (a valid 9-digit ship MMSI; the others follow it).
MMSI_BASE = 211000001
#: Geodetic origin the AIS model encodes positions at (only the local plane is used here).
ORIGIN = (0.0, 0.0)


class SensedTargets:
    def __init__(self, level, names, seed=0):
        self.level = level.seeded(seed)
        self.names = list(names)
        self.tracker = Tracker(self.level.tracker_config())
        self.ais = None
        self.mmsi = {}
        if self.level.ais is not None:
            self.ais = AisSensor(*ORIGIN, self.level.ais)
            for i, name in enumerate(self.names):
                self.mmsi[name] = MMSI_BASE + i
                self.ais.add(MMSI_BASE + i, self.level.ais_class, antenna=self.level.antenna)
        self.radar = None if self.level.radar is None else Radar(self.level.radar)
        self.name_of = {m: n for n, m in self.mmsi.items()}
        self.radar_ids = set()         # the live radar tracks' ids
        self.n_radar_tracks = 0
        self._prev = {}                # name -> (t, heading) of the previous step
        self.received = 0
        self._sigma, self._error, self.decisions, self.unseen = [], [], 0, 0

    def observe(self, t, own_north, own_east, truths):
        """Feed the true states (colav Targets, named as ``names``) at sim time ``t``."""
        if self.ais is not None:
            for tg in truths:
                psi = tg.heading if tg.heading is not None else tg.course
                prev = self._prev.get(tg.name)
                rot = 0.0 if prev is None or t <= prev[0] else \
                    float(wrap_angle(psi - prev[1])) / (t - prev[0])
                self._prev[tg.name] = (t, psi)
                for r in self.ais.step(self.mmsi[tg.name],
                                       Truth(t, tg.north, tg.east, psi, tg.speed, tg.course, rot)):
                    self.received += 1
                    self.tracker.update(AisReport.from_sensor(r, t=r.t_received))
        if self.radar is not None:
            for p in self.radar.scan(t, own_north, own_east, [(tg.north, tg.east)
                                                              for tg in truths]):
                if self.tracker.associate_radar(p.t, p.north, p.east, p.sigma_m,
                                               self.level.radar_confirm_plots) is None:
                    self.n_radar_tracks += 1
                    self.radar_ids.add(self.n_radar_tracks)
                    self.tracker.update(AisReport(self.n_radar_tracks, p.t, p.north, p.east,
                                                  position_sigma_m=p.sigma_m))

    def _name(self, mmsi):
        return self.name_of.get(mmsi) or f'radar{mmsi}'

    def targets(self, t, truths=()):
        """colav Targets of the confirmed live tracks at ``t`` (module docstring); with the
        true states ``truths`` the seen tracks' errors are kept for ``stats``."""
        for mmsi in [m for m in self.radar_ids if m not in self.tracker
                     or t - self.tracker.estimate(m, t).t_report > self.level.radar_coast_s]:
            self.tracker.drop(mmsi)
            self.radar_ids.discard(mmsi)
        out = []
        for est in self.tracker.tracks(t):
            if est.mmsi in self.radar_ids and est.n_reports < self.level.radar_confirm_plots:
                continue
            psi = est.heading if est.heading is not None else est.cog
            d = est.cog - psi
            out.append(colav_io.target_state(self._name(est.mmsi), est.north, est.east, psi,
                                             est.sog * math.cos(d), est.sog * math.sin(d),
                                             est.position_sigma_m))
        self.decisions += 1
        if truths:
            self.unseen += max(len(truths) - len(out), 0)
            true_ne = np.array([[tg.north, tg.east] for tg in truths])
            for tg in out:
                self._sigma.append(tg.position_sigma_m)
                self._error.append(float(np.min(np.hypot(*(true_ne - [tg.north, tg.east]).T))))
        return out

    def stats(self):
        """Counts and the seen tracks' sigma and error at the decisions (module docstring)."""
        sig, err = np.array(self._sigma), np.array(self._error)
        out = {'decisions': self.decisions, 'targets_unseen': self.unseen,
               'position_sigma_m_mean': float(sig.mean()) if sig.size else None,
               'position_sigma_m_max': float(sig.max()) if sig.size else None,
               'position_error_m_rms': float(np.sqrt(np.mean(err ** 2))) if err.size else None,
               'position_error_m_max': float(err.max()) if err.size else None}
        if self.ais is not None:
            vs = self.ais.vessels.values()
            out.update(ais_sent=sum(v.sent for v in vs), ais_lost=sum(v.lost for v in vs),
                       ais_received=self.received)
        if self.radar is not None:
            out.update(radar_scans=self.radar.scans, radar_detections=self.radar.detections,
                       radar_missed=self.radar.missed, radar_tracks=self.n_radar_tracks)
        return out
