"""The scenario's `aivdm_out:` block -> aivdm_out_node parameters (ship_mission.aivdm_block)."""
import json
from pathlib import Path

import pytest
import yaml

from ship_mission.aivdm_block import MMSI_BASE, aivdm_parameters
from ship_mission.fields import ScenarioError
from ship_mission.scenario import load_scenario
from ship_sim.environment.wind import WIND_PROFILES

REPO = Path(__file__).resolve().parents[2]


def scenario(tmp_path, block):
    data = {'name': 'aivdm', 'duration_s': 10.0,
            'vessels': {'vessel_0': {'model': 'mariner',
                                     'route': str(REPO / 'scenarios/routes/head_on_east.yaml')}},
            'traffic': {'target_1': {'light': {'x_m': 100.0, 'course_deg': 90.0,
                                               'speed_mps': 5.0}}},
            'aivdm_out': block}
    path = tmp_path / 's.yaml'
    path.write_text(yaml.safe_dump(data))
    return load_scenario(path)


def test_defaults_own_ship_dimensions_and_run_folder_file(tmp_path):
    s = scenario(tmp_path, {'file': 'out.nmea', 'mmsi': {'target_1': 257000200},
                            'static': {'target_1': {'class': 'B', 'name': 'Yacht'}},
                            'loss_probability': 0})
    p = aivdm_parameters(s, tmp_path / 'run')
    own, tgt = json.loads(p['vessels'])
    assert own['own'] and not tgt['own']
    assert own['mmsi'] == MMSI_BASE and tgt['mmsi'] == 257000200
    assert (own['length_m'], own['beam_m']) == (WIND_PROFILES['mariner'].Loa,
                                                WIND_PROFILES['mariner'].B)
    assert tgt['class'] == 'B' and tgt['name'] == 'Yacht' and 'length_m' not in tgt
    assert tgt['topic'] == '/target_1/odom'
    assert p['file'] == str(tmp_path / 'run' / 'out.nmea')
    assert p['udp'] == '127.0.0.1:10110'
    assert p['loss_probability'] == 0.0 and isinstance(p['loss_probability'], float)


@pytest.mark.parametrize('block,key', [({'mmsi': {'nobody': 1}}, 'aivdm_out.mmsi.nobody'),
                                       ({'loss_probabilty': 0.1}, 'aivdm_out.loss_probabilty'),
                                       ({'mmsi': {'vessel_0': 5, 'target_1': 5}}, 'aivdm_out.mmsi'),
                                       ({'static': {'target_1': {'colour': 'red'}}},
                                        'aivdm_out.static.target_1')])
def test_bad_block_refused_naming_the_key(tmp_path, block, key):
    with pytest.raises(ScenarioError, match=key.replace('.', r'\.') + ':'):
        aivdm_parameters(scenario(tmp_path, block), tmp_path)


@pytest.mark.parametrize('stepping', ['lockstep', 'realtime'])
def test_lockstep_simulator_and_traffic_count_the_node_among_their_subscribers(tmp_path, stepping):
    # Publisher counts carry no names: were aivdm_out_node's subscriptions not counted, they
    # could meet a simulator's count before its autopilot had matched, and step 0 would go out
    # without it (the run then stalls waiting for a rudder_cmd that never comes).
    from ship_mission.launcher import node_parameters, traffic_parameters
    with_block = scenario(tmp_path, {'file': 'out.nmea'})
    without = scenario(tmp_path, None)
    for s in (with_block, without):
        s.stepping = stepping
    extra = int(stepping == 'lockstep')

    def subs(s):
        return [n for n in node_parameters(s, s.vessels[0], 0, record=True)[0]['vessel_node'][
            'lockstep_odom_readers'] if n]
    assert len(subs(with_block)) == len(subs(without)) + extra
    assert (len([n for n in traffic_parameters(with_block)['wait_readers'] if n])
            == len([n for n in traffic_parameters(without)['wait_readers'] if n]) + extra)
