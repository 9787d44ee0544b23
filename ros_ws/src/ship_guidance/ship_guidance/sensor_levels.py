"""The named sensor degradation levels of the colav studies: the one table of their numbers (pure).

Each level says what colav sees of the other ships (ship_guidance.sensed_targets runs it):

``perfect``
    The true states, exactly (no sensor, no tracker, position sigma 0): today's light-target
    path, bit for bit.
``typical_ais``
    Class A AIS at the ITU-R M.1371-5 intervals (10 s at the Imazu 12 kn, 3 1/3 s turning;
    ship_guidance.ais_sensor.report_interval), the sensor model's own defaults for loss
    (5 %, bursts of 2 reports) and noise (3 m per axis, 0.1 kn, 1 deg: SensorConfig, our
    choice, not measured), 1-2 s from transmission to the tracker (receiver, relay, a node's
    poll), the GNSS antenna 40 m aft of the reference point on the centre line (a bridge aft
    on a 160 m ship: AIS reports the antenna; the tracker tracks that point).
``poor_ais``
    The same transponders heard badly (our choice of a bad day, not measured): 30 % of the
    reports lost in bursts of 6 on average (a minute of silence at 10 s), position noise
    10 m (an uncorrected GNSS), SOG 0.5 kn, COG 5 deg, 5-10 s from transmission to tracker.
``radar_only``
    No AIS at all: the own ship's radar (ship_guidance.radar_sensor, IMO MSC.192(79)
    accuracies taken as 2 sigma: 15 m in range, 0.5 deg in bearing; 80 % detection per 2.5 s
    scan within 11 NM), plots without identity, associated by the tracker's gated nearest
    neighbour; a plot in no track's gate opens a track. A radar track goes to colav once it
    has ``radar_confirm_plots`` plots (20: about a minute of scans at 80 %; MSC.192(79) gives
    a tracked target's motion trend within one minute), so colav never acts on a track
    without a velocity; a track without a plot for ``radar_coast_s`` (20 s, 8 scans: all
    missed at 80 % about once in 400 000 scans) is deleted, so a track opened by a plot
    outside the true track's gate (1 % of plots with the 99 % gate) dies before it confirms:
    the confirmed track keeps the target's plots (the tracker associates to confirmed tracks
    first).

For every AIS level the tracker's measurement model is the level's own noise (the filter knows
its sensor); reports are stamped with their time of reception, as tracker_node stamps them,
so the latency is a lag the filter does not know of. Seeds: the sensor model's generators
take the run's seed (AIS per MMSI, radar its own stream): a level and a seed give one run.
"""
import math
from dataclasses import dataclass, replace

from ship_guidance.ais import KNOT
from ship_guidance.ais_sensor import SensorConfig
from ship_guidance.radar_sensor import RadarConfig
from ship_guidance.tracker import TrackerConfig


@dataclass(frozen=True)
class SensorLevel:
    """One degradation level: AIS sensor model (None: no AIS), its class and antenna offset
    (m forward, m to starboard of the reference point), radar (None: no radar), the plots a
    radar track needs before colav sees it, the silence (s) after which it is deleted."""
    name: str
    summary: str
    ais: SensorConfig | None = None
    ais_class: str = 'A'
    antenna: tuple = (0.0, 0.0)
    radar: RadarConfig | None = None
    radar_confirm_plots: int = 20
    radar_coast_s: float = 20.0

    @property
    def perfect(self):
        return self.ais is None and self.radar is None

    def seeded(self, seed):
        """The level with its sensors' seeds set to ``seed``."""
        return replace(self, ais=None if self.ais is None else replace(self.ais, seed=int(seed)),
                       radar=None if self.radar is None else replace(self.radar, seed=int(seed)))

    def tracker_config(self):
        """TrackerConfig whose measurement noise is this level's AIS noise (defaults without
        AIS: radar plots carry their own sigma)."""
        if self.ais is None:
            return TrackerConfig()
        return TrackerConfig(position_sigma_m=self.ais.position_sigma_m,
                             sog_sigma_mps=self.ais.sog_sigma_kn * KNOT,
                             cog_sigma_rad=math.radians(self.ais.cog_sigma_deg))


#: GNSS antenna of every AIS target: 40 m aft of the reference point, on the centre line.
ANTENNA = (-40.0, 0.0)

LEVELS = {level.name: level for level in (
    SensorLevel('perfect', 'true states, exactly'),
    SensorLevel('typical_ais', 'class A AIS, 5 % lost, 3 m noise, 1-2 s late',
                ais=SensorConfig(latency_s=1.0, latency_jitter_s=1.0), antenna=ANTENNA),
    SensorLevel('poor_ais', 'class A AIS, 30 % lost in bursts of 6, 10 m noise, 5-10 s late',
                ais=SensorConfig(loss_probability=0.3, mean_burst_length=6.0,
                                 position_sigma_m=10.0, sog_sigma_kn=0.5, cog_sigma_deg=5.0,
                                 heading_sigma_deg=2.0, latency_s=5.0, latency_jitter_s=5.0),
                antenna=ANTENNA),
    SensorLevel('radar_only', 'own radar, no AIS: 15 m / 0.5 deg, 80 % per 2.5 s scan',
                radar=RadarConfig()),
)}


def level(name):
    """The level called ``name`` (KeyError naming the known ones)."""
    try:
        return LEVELS[name]
    except KeyError:
        raise KeyError(f'no sensor level {name!r} (known: {", ".join(LEVELS)})') from None
