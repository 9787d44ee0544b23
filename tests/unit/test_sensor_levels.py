"""The sensor levels' table (ship_guidance.sensor_levels), the radar model and the pipeline from
true states to the targets colav sees (ship_guidance.sensed_targets)."""
import math
from dataclasses import fields

import numpy as np
import pytest
from scipy import stats

from imazu.cases import load_cases
from ship_guidance.ais_sensor import CLASSES
from ship_guidance.colav import Target
from ship_guidance.radar_sensor import Radar, RadarConfig
from ship_guidance.sensed_targets import SensedTargets
from ship_guidance.sensor_levels import LEVELS, SensorLevel, level
from ship_guidance.tracker import AisReport, Tracker


def test_the_table_names_the_four_levels_and_each_is_well_formed():
    assert list(LEVELS) == ['perfect', 'typical_ais', 'poor_ais', 'radar_only']
    for name, lv in LEVELS.items():
        assert lv.name == name and lv.summary
        lv.tracker_config().check()
        if lv.ais is not None:
            lv.ais.check()
            assert lv.ais_class in CLASSES and len(lv.antenna) == 2
        if lv.radar is not None:
            lv.radar.check()
    assert LEVELS['perfect'].perfect and LEVELS['perfect'].seeded(5).perfect
    assert not any(lv.perfect for n, lv in LEVELS.items() if n != 'perfect')
    assert LEVELS['radar_only'].ais is None and LEVELS['radar_only'].radar is not None
    with pytest.raises(KeyError, match='typical_ais'):
        level('nope')


def test_poor_ais_is_no_better_than_typical_in_any_number():
    typical, poor = LEVELS['typical_ais'].ais, LEVELS['poor_ais'].ais
    for f in ('loss_probability', 'mean_burst_length', 'position_sigma_m', 'sog_sigma_kn',
              'cog_sigma_deg', 'heading_sigma_deg', 'latency_s', 'latency_jitter_s'):
        assert getattr(poor, f) >= getattr(typical, f), f
    assert poor.loss_probability > typical.loss_probability


def test_seeds_and_the_trackers_noise_follow_the_level():
    for lv in LEVELS.values():
        s = lv.seeded(7)
        for cfg in (s.ais, s.radar):
            assert cfg is None or cfg.seed == 7
        if lv.ais is not None:
            tc = lv.tracker_config()
            assert tc.position_sigma_m == lv.ais.position_sigma_m
            assert tc.cog_sigma_rad == pytest.approx(math.radians(lv.ais.cog_sigma_deg))
    # every field of a level is documented in its dataclass (no hidden numbers elsewhere)
    assert {f.name for f in fields(SensorLevel)} >= {'ais', 'radar', 'radar_confirm_plots',
                                                     'radar_coast_s'}


def test_radar_only_sees_every_imazu_target_and_keeps_a_true_track_through_missed_scans():
    lv = LEVELS['radar_only']
    r = lv.radar
    for case in load_cases().values():
        own = case['own']
        for t in case['targets']:
            assert math.hypot(t['north_m'] - own['north_m'],
                              t['east_m'] - own['east_m']) < r.detection_range_m
    # a true track dies only if every scan of its coast time misses: (1 - Pd)^n small
    n_scans = int(lv.radar_coast_s / r.scan_period_s)
    assert (1.0 - r.detection_probability) ** n_scans < 1e-4
    assert lv.radar_confirm_plots > 1      # one stray plot never reaches colav


def test_radar_detects_at_its_probability_with_its_noise_and_repeats_for_a_seed():
    cfg = RadarConfig(seed=3)
    target = (3000.0, 4000.0)        # 5 km, bearing atan2(4, 3)
    radar = Radar(cfg)
    plots = [p for k in range(4000) for p in radar.scan(k * cfg.scan_period_s, 0.0, 0.0, [target])]
    n = radar.scans
    assert n == 4000 and radar.detections == len(plots)
    # detections binomial(n, Pd): within its 99.9 % interval
    lo, hi = stats.binom.interval(0.999, n, cfg.detection_probability)
    assert lo <= len(plots) <= hi
    rng = np.array([p.range_m for p in plots])
    brg = np.array([p.bearing for p in plots])
    chi_lo, chi_hi = stats.chi2.interval(0.999, len(plots) - 1)
    for values, sigma in ((rng - 5000.0, cfg.range_sigma_m),
                          (brg - math.atan2(4.0, 3.0), math.radians(cfg.bearing_sigma_deg))):
        s2 = np.var(values, ddof=1)
        assert chi_lo / (len(plots) - 1) <= s2 / sigma ** 2 <= chi_hi / (len(plots) - 1)
        assert abs(values.mean()) < 4.0 * sigma / math.sqrt(len(plots))
    assert all(p.sigma_m == max(cfg.range_sigma_m, p.range_m * math.radians(
        cfg.bearing_sigma_deg)) for p in plots)
    again = Radar(cfg)
    assert plots == [p for k in range(4000)
                     for p in again.scan(k * cfg.scan_period_s, 0.0, 0.0, [target])]
    # out of range: nothing
    assert Radar(cfg).scan(0.0, 0.0, 0.0, [(cfg.detection_range_m + 1.0, 0.0)]) == []


def test_tracker_drop_deletes_one_track():
    tr = Tracker()
    tr.update(AisReport(5, 0.0, 10.0, 20.0))
    assert tr.drop(5) and 5 not in tr and tr.deleted == 1 and not tr.drop(5)


def _straight_run(name, seed, t_end=900.0, dt=0.5):
    """A target crossing at 6 m/s, the own ship still at the origin: the targets seen each second."""
    sensed = SensedTargets(level(name), ['ts1'], seed)
    seen = []
    for k in range(int(t_end / dt) + 1):
        t = k * dt
        truth = [Target(4000.0, 6000.0 - 6.0 * t, -math.pi / 2, 6.0, -math.pi / 2, name='ts1')]
        sensed.observe(t, 0.0, 0.0, truth)
        if k % int(1.0 / dt) == 0:
            seen.append((t, truth[0], sensed.targets(t, truth)))
    return sensed, seen


@pytest.mark.parametrize('name', ['typical_ais', 'poor_ais', 'radar_only'])
def test_the_targets_seen_follow_the_truth_within_their_uncertainty(name):
    lv = level(name)
    sensed, seen = _straight_run(name, seed=2)
    named = [(t, truth, s) for t, truth, out in seen for s in out]
    assert named, 'the target was never seen'
    # one target, one track at a time once confirmed (no stray track reaches colav)
    assert all(len(out) <= 1 for _, _, out in seen)
    # the error: the antenna offset (a bias the filter does not know of) plus the lag of the
    # latency at the target's speed, plus 4 position sigmas of the track
    bias = math.hypot(*lv.antenna) + 6.0 * (0.0 if lv.ais is None else
                                            lv.ais.latency_s + lv.ais.latency_jitter_s)
    for t, truth, s in named:
        err = math.hypot(s.north - truth.north, s.east - truth.east)
        assert err <= bias + 4.0 * s.position_sigma_m, (t, err, s.position_sigma_m)
    if lv.ais is not None:
        assert {s.name for _, _, s in named} == {'ts1'}       # AIS: the identity kept
    else:
        assert all(s.name.startswith('radar') for _, _, s in named)
        # confirmed after radar_confirm_plots plots: not before that many scans
        first = min(t for t, _, _ in named)
        assert first >= (lv.radar_confirm_plots - 1) * lv.radar.scan_period_s
    st = sensed.stats()
    assert st['decisions'] == len(seen)
    again, seen2 = _straight_run(name, seed=2)
    assert seen2 == seen and again.stats() == st
