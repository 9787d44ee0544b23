"""Targets in a run's analysis: track metrics (ship_mission.metrics.track_metrics), the closest
approach between tracks sampled at different times (ship_mission.encounter.min_distance) and the
traffic plots (ship_mission.plots)."""
import math
from types import SimpleNamespace

import numpy as np
import pytest

from ship_mission import plots
from ship_mission.encounter import min_distance
from ship_mission.metrics import track_metrics


def _straight(t, x0, y0, course_deg, speed):
    c = math.radians(course_deg)      # clockwise from north; ENU x east, y north
    t = np.asarray(t, dtype=float)
    return SimpleNamespace(t=t, x=x0 + speed * math.sin(c) * t, y=y0 + speed * math.cos(c) * t,
                           yaw=np.full(t.size, math.pi / 2 - c))


def test_track_metrics_of_a_constant_velocity_track():
    tr = _straight(np.arange(0.0, 100.01, 0.5), 10.0, -20.0, 37.0, 6.0)
    m = track_metrics(tr.t, tr.x, tr.y)
    assert m['duration_s'] == 100.0 and m['odom_samples'] == 201
    assert m['distance_travelled_m'] == pytest.approx(600.0, rel=1e-12)
    assert m['speed_mean_mps'] == pytest.approx(6.0, rel=1e-12)
    assert track_metrics([5.0], [0.0], [0.0])['speed_mean_mps'] is None


def test_closest_approach_between_tracks_on_different_stamps_is_the_cpa():
    """Own ship east at 5 m/s from the origin, target north at 5 m/s from (1000, -1200): the
    relative motion closes on the line x - y = const; the CPA has the closed form
    d = |r0 x v_rel| / |v_rel| at t = -r0 . v_rel / |v_rel|^2. The target is sampled at other
    times (every 0.7 s from 0.3 s): it is interpolated, exact for a straight track."""
    own = _straight(np.arange(0.0, 400.01, 0.1), 0.0, 0.0, 90.0, 5.0)
    tgt = _straight(np.arange(0.3, 400.0, 0.7), 1000.0, -1200.0, 0.0, 5.0)
    r0 = np.array([1000.0, -1200.0])
    v_rel = np.array([-5.0, 5.0])
    t_cpa = -r0 @ v_rel / (v_rel @ v_rel)
    d_cpa = abs(r0[0] * v_rel[1] - r0[1] * v_rel[0]) / np.linalg.norm(v_rel)
    m = min_distance(own, tgt)
    assert m['t_min_s'] == pytest.approx(t_cpa, abs=0.05)
    assert m['min_distance_m'] == pytest.approx(d_cpa, abs=1e-6)
    # At the CPA the relative position (x, y) = r0 + v_rel t = (-100, -100): south-west of the
    # own ship heading east, 135 deg clockwise from its bow, on its starboard quarter.
    assert m['side'] == 'starboard' and m['bearing_at_min_deg'] == pytest.approx(135.0, abs=0.1)


def test_closest_approach_needs_overlapping_times():
    own = _straight(np.arange(0.0, 10.0, 1.0), 0.0, 0.0, 0.0, 1.0)
    assert min_distance(own, _straight(np.arange(20.0, 30.0, 1.0), 0.0, 0.0, 0.0, 1.0)) is None


def test_traffic_plots_are_written(tmp_path):
    from ship_mission.bag import Series
    empty = Series(np.zeros(0), np.zeros(0))
    own = _straight(np.arange(0.0, 300.0, 0.1), 0.0, 0.0, 90.0, 5.0)
    vessel = SimpleNamespace(**vars(own), route=None, rudder=empty, rudder_cmd=empty,
                             heading_cmd=empty, cross_track_error=empty)
    traffic = {'ais_1': _straight(np.arange(0.0, 300.0, 1.0), 1000.0, -1200.0, 0.0, 5.0)}
    paths = plots.make_plots({'/vessel_0': vessel}, tmp_path, traffic=traffic)
    assert [p.name for p in paths] == ['track.png', 'cross_track_error.png', 'heading.png',
                                       'rudder.png', 'over_ground.png', 'range.png']
    assert all(p.stat().st_size > 1000 for p in paths)
