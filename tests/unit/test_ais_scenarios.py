"""AIS targets in a scenario's `ais:` section (ship_mission.scenario, ship_mission.launcher), the replay
encoding behind its file (ship_guidance.ais_replay) and colav_node's per-step completeness of a
many-target topic (ship_guidance.colav_io.SyncedSource)."""
import math
from pathlib import Path

import numpy as np
import pytest

import make_ais_replay
from ship_mission.launcher import (AIS_SYNC, AIS_TARGETS, ais_parameters, check_scenario,
                              node_parameters, record_ack_args, traffic_parameters)
from ship_mission.scenario import ScenarioError, load_scenario
from ship_guidance.ais import KNOT, AisTracker, parse_replay
from ship_guidance.ais_replay import replay_lines
from ship_guidance.colav_io import SyncedSource

ROOT = Path(__file__).resolve().parents[2]
HEAD_ON_AIS = ROOT / 'scenarios' / 'head_on_ais_mariner.yaml'
PLATOON = ROOT / 'scenarios' / 'platoon_mariner_5.yaml'


def test_ais_section_starts_ais_node_on_the_clock_and_wires_colav_and_the_record_ack():
    sc = load_scenario(HEAD_ON_AIS)
    check_scenario(sc)
    assert Path(sc.ais['file']).is_absolute() and Path(sc.ais['file']).is_file()
    p = ais_parameters(sc)
    assert p['use_sim_time'] is True and p['publish_on_clock'] is True
    # step 0 reaches everyone: ais_node waits for the recorder and the one colav_node
    assert p['wait_readers'] == ['/vessel_0/colav_node', '/mission_recorder']
    assert ais_parameters(sc, record=False)['wait_readers'] == ['/vessel_0/colav_node']
    assert traffic_parameters(sc)['wait_readers'] == ['/vessel_0/colav_node', '/mission_recorder']
    assert (p['origin_lat_deg'], p['origin_lon_deg']) == (63.44, 10.40)
    params, _ = node_parameters(sc, sc.vessels[0], 0, record=True)
    colav = params['colav_node']
    assert (colav['targets_topic'], colav['targets_sync_topic']) == (AIS_TARGETS, AIS_SYNC)
    assert colav['target_topics'] == ['/target_wp/odom']   # the light target, no other vessel
    ack = record_ack_args(sc)
    assert ack[0] == '--ack' and ack[1].endswith(',/target_wp/odom,' + AIS_SYNC)


def test_realtime_ais_is_timer_driven_and_not_waited_for(scenario_variant):
    sc = load_scenario(scenario_variant(HEAD_ON_AIS, lambda d: d.update(stepping='realtime')))
    assert ais_parameters(sc)['publish_on_clock'] is False
    assert 'wait_readers' not in ais_parameters(sc)
    assert traffic_parameters(sc)['wait_readers'] == ['']     # nobody waits in realtime
    colav = node_parameters(sc, sc.vessels[0], 0, record=True)[0]['colav_node']
    assert (colav['targets_topic'], colav['targets_sync_topic']) == (AIS_TARGETS, '')


@pytest.mark.parametrize('change, key', [
    (lambda a: a.pop('file'), r'ais\.file: an AIS replay file'),
    (lambda a: a.update(file='nowhere.nmea'), r'ais\.file: .* is not a file'),
    (lambda a: a.pop('origin_lat_deg'), r'ais\.origin_lat_deg: must be a number'),
    (lambda a: a.update(origin_lon_deg=200.0), r'ais\.origin_lon_deg: must be <= 180'),
    (lambda a: a.update(publish_on_clock=False), r'ais\.publish_on_clock: set by the launcher'),
])
def test_bad_ais_sections_are_refused_naming_the_key(scenario_variant, change, key):
    with pytest.raises(ScenarioError, match=key):
        load_scenario(scenario_variant(HEAD_ON_AIS, lambda d: change(d['ais'])))


def test_unknown_ais_node_parameter_is_refused_with_the_closest_name(scenario_variant):
    sc = load_scenario(scenario_variant(HEAD_ON_AIS, lambda d: d['ais'].update(stale_after=60)))
    with pytest.raises(ScenarioError, match=r'ais\.stale_after: .*"stale_after_s"'):
        check_scenario(sc)


def test_ais_beside_a_platoon_is_refused(scenario_variant):
    def change(d):
        d['ais'] = {'file': str(HEAD_ON_AIS.parent / 'ais' / 'head_on_target.nmea'),
                    'origin_lat_deg': 0.0, 'origin_lon_deg': 0.0}
    with pytest.raises(ScenarioError, match=r': ais: AIS targets are not supported beside a'):
        load_scenario(scenario_variant(PLATOON, change))


# -- the replay encoding ------------------------------------------------------------------------

def test_replay_lines_decode_back_to_the_track_within_ais_resolution():
    """pyais encodes, ship_guidance.ais decodes: positions within 1/10000 arc minute (0.19 m at
    the equator's scale, less east-west at 63 deg), SOG to 0.1 kn, COG to 0.1 deg."""
    origin = (63.44, 10.40)
    t = np.arange(0.0, 60.0, 6.0)
    cog, sog = math.radians(123.4), 7.7175
    north = 500.0 + sog * math.cos(cog) * t
    east = -300.0 + sog * math.sin(cog) * t
    lines = replay_lines(257000100, t, north, east, [sog] * len(t), [cog] * len(t), *origin)
    tracker = AisTracker(*origin)
    for (t_s, sentence), t_expected in zip(parse_replay(lines, 1.0), t):
        assert t_s == t_expected
        assert tracker.feed(sentence, t_s) == 257000100
        s = tracker.state(257000100, t_s)
        i = int(round(t_s / 6.0))
        assert math.hypot(s.north - north[i], s.east - east[i]) < 0.2
        assert abs(s.sog - sog) <= 0.05 * KNOT + 1e-9
        assert abs(math.degrees(s.cog) % 360.0 - 123.4) < 0.05 + 1e-9
    assert sum(tracker.bad.values()) == 0


def test_make_ais_replay_refuses_a_bad_target_in_one_line(tmp_path, capsys):
    code = make_ais_replay.main([str(tmp_path / 'x.nmea'), '--mmsi', '1', '--origin', '0', '0',
                                 '--light', '{"course_deg": 0}', '--duration', '10'])
    assert code == 2 and 'give either' in capsys.readouterr().err


# -- colav_node's completeness of a many-target topic ----------------------------------------

def test_synced_source_is_complete_only_when_every_announced_message_has_come():
    s = SyncedSource()
    assert not s.ready(0)
    s.received(0)                       # a target of step 0 before its announcement
    assert not s.ready(0)
    s.announced(0, 2)                   # two targets at step 0: one still missing
    assert not s.ready(0)
    s.received(0)
    assert s.ready(0) and not s.ready(100)
    s.announced(100, 0)                 # a step without targets is complete at once
    assert s.ready(100)
    s.announced(200, 1)
    s.announced(300, 1)
    s.received(300)                     # step 300's target, step 200's still in flight
    assert s.ready(100) and not s.ready(200) and not s.ready(300)
    s.received(200)
    assert s.ready(300)
    assert s.complete_ns == 300 and not s._received and not s._announced   # nothing kept
