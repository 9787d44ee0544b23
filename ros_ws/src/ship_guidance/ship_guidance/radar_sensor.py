"""A simple marine radar on the own ship: plots of the targets it detects, without identity (pure).

The antenna turns once per ``scan_period_s``; at each scan every target within
``detection_range_m`` of the own ship is detected with ``detection_probability`` (independent
per scan and target, no false alarms, no shadowing, no clutter) and gives one plot: its range
with Gaussian noise of ``range_sigma_m`` and its bearing with Gaussian noise of
``bearing_sigma_deg``, turned back into a NED position around the own ship's position (the
antenna at the own ship's reference point). All plots of a scan carry the scan's time and come
in bearing order (the order a turning antenna meets them), so nothing in them tells the
targets apart: the tracker associates them (ship_guidance.tracker.Tracker.associate_radar).

A plot's position sigma per axis, as the tracker takes it (isotropic), is the larger of the
range sigma and the cross-range sigma (range x bearing sigma in radians): the worse axis, so the
tracker's covariance is never smaller than the plot's error.

Default numbers: IMO MSC.192(79) (radar performance standard) asks for a range accuracy within
30 m (or 1 % of the range scale) and a bearing accuracy within 1 deg, and for detection with 80 %
probability per scan at the ranges of its Table 1 (11 NM for a ship above 5000 GT on X-band);
the accuracies are taken here as 2 sigma (15 m, 0.5 deg), the 80 % as the probability at every
range within the detection range (pessimistic nearer in). The scan period, 2.5 s (24 rpm), is a
common X-band rotation (our choice; the standard fixes none).

Randomness: one numpy Generator seeded with (seed, RNG_STREAM); every target in every scan
draws the same three numbers (detection, range and bearing noise) whether detected or not, in
the order the targets are given, so a run repeats bit for bit for a seed.
"""
import math
from dataclasses import dataclass

import numpy as np

NM = 1852.0
#: Second seed word of the radar's generator (AIS vessels use their MMSI, all below 1e9).
RNG_STREAM = 1_000_000_001


@dataclass(frozen=True)
class RadarConfig:
    """Parameters of the radar (module docstring); validated by ``check``."""
    scan_period_s: float = 2.5
    range_sigma_m: float = 15.0
    bearing_sigma_deg: float = 0.5
    detection_range_m: float = 11.0 * NM
    detection_probability: float = 0.8
    seed: int = 0

    def check(self):
        """ValueError naming the first bad field; returns self."""
        for name in ('scan_period_s', 'detection_range_m'):
            v = getattr(self, name)
            if not (math.isfinite(v) and v > 0.0):
                raise ValueError(f'{name} must be a finite number > 0, got {v!r}')
        for name in ('range_sigma_m', 'bearing_sigma_deg'):
            v = getattr(self, name)
            if not (math.isfinite(v) and v >= 0.0):
                raise ValueError(f'{name} must be a finite number >= 0, got {v!r}')
        if not 0.0 < self.detection_probability <= 1.0:
            raise ValueError(f'detection_probability must be in (0, 1], got '
                             f'{self.detection_probability!r}')
        return self


@dataclass(frozen=True)
class Plot:
    """One detection: scan time (s), NED position (m), its sigma per axis (m), range (m) and
    bearing (rad, clockwise from north) as measured."""
    t: float
    north: float
    east: float
    sigma_m: float
    range_m: float
    bearing: float


class Radar:
    """The radar of the module docstring; ``scan(t, ...)`` at every step, plots when one is due."""

    def __init__(self, config=RadarConfig()):
        self.config = config.check()
        self.rng = np.random.default_rng([int(config.seed), RNG_STREAM])
        self.t0 = None
        self.scans = 0
        self.detections = 0
        self.missed = 0

    def due(self, t):
        """True if a scan is due at ``t`` (the first call starts the antenna's clock)."""
        if self.t0 is None:
            self.t0 = t
        return t >= self.t0 + self.scans * self.config.scan_period_s

    def scan(self, t, own_north, own_east, targets):
        """Plots of one scan at ``t`` if one is due, else []: ``targets`` the true (north, east)
        of each target, in a fixed order."""
        if not self.due(t):
            return []
        self.scans += 1
        c = self.config
        bearing_sigma = math.radians(c.bearing_sigma_deg)
        plots = []
        for north, east in targets:
            u, dr, db = self.rng.random(), *self.rng.standard_normal(2)
            dn, de = north - own_north, east - own_east
            rng_m = math.hypot(dn, de)
            if rng_m > c.detection_range_m:
                continue
            if u >= c.detection_probability:
                self.missed += 1
                continue
            self.detections += 1
            r = max(rng_m + c.range_sigma_m * dr, 0.0)
            b = math.atan2(de, dn) + bearing_sigma * db
            plots.append(Plot(t, own_north + r * math.cos(b), own_east + r * math.sin(b),
                              max(c.range_sigma_m, r * bearing_sigma), r, b % (2.0 * math.pi)))
        plots.sort(key=lambda p: p.bearing)
        return plots
