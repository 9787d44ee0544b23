"""An AIS target in a scenario, real processes through the launcher
(scenarios/head_on_ais_mariner.yaml, its first DURATION_S): a Mariner with colav_node (SB-MPC) eastbound meets a
target that exists only as AIS position reports (scenarios/ais/head_on_target.nmea, encoded by
pyais from a constant course and speed by scripts/make_ais_replay.py), replayed by the launcher's
ais_node on sim time, in lockstep.

- The replay file is what the tool makes from the track its first line names (so the file's
  origin is known and reproducible).
- ais_node publishes the target on /targets at every step, stamped exactly at the own steps, at
  the reported track: within AIS's quantisation (0.19 m position, 0.1 kn SOG over the 6 s
  between reports) of the closed-form constant-velocity track.
- COLREGs Rule 14: the own ship alters to starboard, apparently (Rule 8(b): at least 30 deg),
  and passes port to port beyond colav d_safe_m of the TRUE track; left alone they would meet.
- A light target on timed waypoints (target_wp, far to the north) is at its closed-form
  position (piecewise linear in time, on from its last leg after the last waypoint) and
  heading at every step, stamped at the own steps; colav_node sees both targets.
- metrics.json has both as `traffic` (source ais / light, as the launcher recorded them in
  the bag; closest approach to the own ship), not as vessels.
- The record is complete (/targets_sync is acknowledged every step) and a second run gives
  identical metrics, colav messages and target odometry (colav_node waits for each step's AIS
  targets).
"""
import json
import shlex

import numpy as np
import pytest
import yaml

import make_ais_replay
from ship_mission.bag import read_bag, read_custom_data
from ship_mission.encounter import alteration, decision_rows, min_distance, target_tracks
from ship_mission.scenario import TARGETS_KEY
from ship_guidance.ais import KNOT
from ship_guidance.colav_params import ColavParams

from harness import REPO_ROOT, run_twice_complete

SCENARIO = REPO_ROOT / 'scenarios' / 'head_on_ais_mariner.yaml'
OWN = 'vessel_0'
WAYPOINT_TARGET = 'target_wp'
REPORT_PERIOD_S = 6.0
# The run must hold the closest approach and the opening after it. Head-on from R0 = 4000 m at
# U = 7.7175 m/s each, the own course altered by theta: the relative velocity's part along the
# line of sight is U (1 + cos theta) of |v_rel|^2 = 4 U^2 cos^2(theta / 2), so the closest point
# comes at R0 / (2 U) = 259 s whatever theta, plus the time the turn takes (doc/results/encounters.md's run:
# 267 s). 320 s leaves about a minute of opening range; the waypoint target's second leg starts
# at 200 s, so both legs are checked (after its last waypoint, at 400 s: tests/unit/
# test_light_traffic.py).
DURATION_S = 320.0


def _replay_command(replay):
    """The make_ais_replay.py arguments named in the replay file's first line."""
    first = replay.read_text().splitlines()[0]
    assert first.startswith('# made by: scripts/make_ais_replay.py '), first
    return shlex.split(first.removeprefix('# made by: scripts/make_ais_replay.py '))


def test_replay_file_is_what_the_tool_makes(tmp_path, monkeypatch):
    scenario = yaml.safe_load(SCENARIO.read_text())
    replay = SCENARIO.parent / scenario['ais']['file']
    args = _replay_command(replay)
    out = tmp_path / 'again.nmea'
    monkeypatch.chdir(REPO_ROOT)
    assert make_ais_replay.main([str(out)] + args[1:]) == 0
    assert out.read_text().splitlines()[1:] == replay.read_text().splitlines()[1:]
    origin = args[args.index('--origin') + 1:args.index('--origin') + 3]
    assert [float(v) for v in origin] == [scenario['ais']['origin_lat_deg'],
                                          scenario['ais']['origin_lon_deg']]


@pytest.mark.timeout(420)
def test_own_ship_avoids_an_ais_target_head_on_identically_twice(launch):
    scenario = yaml.safe_load(SCENARIO.read_text())
    d_safe = scenario['vessels'][OWN]['colav'].get('d_safe_m', ColavParams().d_safe_m)
    args = _replay_command(SCENARIO.parent / scenario['ais']['file'])
    light = json.loads(args[args.index('--light') + 1])
    mmsi = args[args.index('--mmsi') + 1]
    assert float(args[args.index('--period') + 1]) == REPORT_PERIOD_S
    dt = scenario['dt_s']
    n = int(round(DURATION_S / dt)) + 1

    # Both records complete (/targets_sync acknowledged every step), identical vessels and
    # traffic metrics and colav messages.
    runs, metrics, _ = run_twice_complete(launch, SCENARIO, DURATION_S, colav_ns=OWN)
    first = runs[0]
    data = read_bag(first / 'bag', namespaces=[f'/{OWN}', f'/{WAYPOINT_TARGET}'])
    own, wp = data.vessels[f'/{OWN}'], data.vessels[f'/{WAYPOINT_TARGET}']
    tracks = target_tracks(first / 'bag')
    assert list(tracks) == [f'ais_{mmsi}']
    ais = tracks[f'ais_{mmsi}']
    assert len(own.t) == len(ais.t) == n, 'the target at every step'
    np.testing.assert_array_equal(ais.t, own.t)

    # The true track: constant course and speed from (x_m, y_m).
    c = np.radians(light['course_deg'])
    v = light['speed_mps']
    true_x = light['x_m'] + v * np.sin(c) * own.t
    true_y = light['y_m'] + v * np.cos(c) * own.t
    # AIS quantisation: position 1/10000 arc minute (0.19 m), SOG 0.1 kn over at most one
    # report period of dead reckoning, COG 0.1 deg (exact here: 270.0).
    tol = 0.19 + 0.05 * KNOT * REPORT_PERIOD_S + 0.01
    err = np.hypot(ais.x - true_x, ais.y - true_y)
    assert err.max() < tol, f'AIS track {err.max():.3f} m off the true track'
    np.testing.assert_allclose(ais.u, v, atol=0.05 * KNOT + 1e-9)

    truth = type(ais)(t=own.t, x=true_x, y=true_y, yaw=np.full(n, np.pi / 2 - c))
    enc = min_distance(own, truth)
    alt = alteration(decision_rows(first / 'bag', OWN))
    before = own.t <= enc['t_min_s']
    turn = np.degrees(np.unwrap(own.yaw[before]) - own.yaw[0])
    print(f'AIS head-on: {enc}, {alt}, largest starboard turn {-turn.min():.1f} deg')
    # Left alone they meet: both on y = 0, heading for each other.
    assert abs(own.y[0]) < 1.0 and light['y_m'] == 0.0 and light['course_deg'] == 270.0
    assert enc['t_min_s'] < own.t[-1], 'still closing at the end of the run'
    assert enc['min_distance_m'] > d_safe, enc
    assert enc['side'] == 'port', enc
    assert alt['first_avoid_s'] is not None and alt['first_offset_deg'] > 0.0, alt
    assert not alt['last_resort']
    assert turn.min() <= -30.0, f'largest starboard turn {-turn.min():.1f} deg'

    # The waypoint target: closed form at every step (legs straight between the waypoints,
    # the last leg's velocity after the last one).
    way = np.array(scenario['traffic'][WAYPOINT_TARGET]['light']['waypoints'])
    assert len(wp.t) == n
    np.testing.assert_array_equal(wp.t, own.t)
    k = np.clip(np.searchsorted(way[:, 0], wp.t, side='right') - 1, 0, len(way) - 2)
    frac = (wp.t - way[k, 0]) / (way[k + 1, 0] - way[k, 0])
    np.testing.assert_allclose(wp.x, way[k, 1] + frac * (way[k + 1, 1] - way[k, 1]), atol=1e-6)
    np.testing.assert_allclose(wp.y, way[k, 2] + frac * (way[k + 1, 2] - way[k, 2]), atol=1e-6)
    leg_yaw = np.arctan2(np.diff(way[:, 2]), np.diff(way[:, 1]))
    np.testing.assert_allclose(wp.yaw, leg_yaw[k], atol=1e-12)
    n_targets = decision_rows(first / 'bag', OWN)[:, 5]
    assert (n_targets == 2).all(), 'colav_node saw both targets at every decision'

    # the launcher recorded the scenario's targets in the bag; the analysis read them from there
    assert json.loads(read_custom_data(first / 'bag')[TARGETS_KEY]) == \
        {'light': [f'/{WAYPOINT_TARGET}'], 'full': [], 'ais': True}
    traffic = metrics['traffic']
    assert set(traffic) == {f'ais_{mmsi}', f'/{WAYPOINT_TARGET}'}
    assert f'/{WAYPOINT_TARGET}' not in metrics['vessels']
    assert (traffic[f'ais_{mmsi}']['source'], traffic[f'/{WAYPOINT_TARGET}']['source']) == \
        ('ais', 'light')
    close = traffic[f'ais_{mmsi}']['closest_approach'][f'/{OWN}']
    assert abs(close['min_distance_m'] - enc['min_distance_m']) < tol
    assert traffic[f'/{WAYPOINT_TARGET}']['closest_approach'][f'/{OWN}']['min_distance_m'] > \
        2000.0

    second = runs[1]
    data2 = read_bag(second / 'bag', namespaces=[f'/{WAYPOINT_TARGET}'])
    wp2 = data2.vessels[f'/{WAYPOINT_TARGET}']
    for a, b in ((wp.t, wp2.t), (wp.x, wp2.x), (wp.y, wp2.y), (wp.yaw, wp2.yaw)):
        np.testing.assert_array_equal(a, b)
    ais2 = target_tracks(second / 'bag')[f'ais_{mmsi}']
    np.testing.assert_array_equal(ais.x, ais2.x)
    np.testing.assert_array_equal(ais.y, ais2.y)
