"""The scenario `wind:` block (ship_mission.wind_block): checked, inherited, passed to vessel_node."""
import json
import pathlib

import pytest

from ship_mission.fields import ScenarioError
from ship_mission.launcher import node_parameters
from ship_mission.scenario import load_scenario
from ship_mission.wind_block import wind_meta

SCENARIOS = pathlib.Path(__file__).resolve().parents[2] / 'scenarios'
FLAGSHIP = SCENARIOS / 'flagship_mariner.yaml'
PLATOON = SCENARIOS / 'platoon_mariner_5.yaml'
WIND = {'speed_mps': 12.0, 'direction_deg': 270.0, 'gust_sd_mps': 1.5,
        'time_constant_s': 30.0, 'seed': 4, 'coefficients': 'isherwood72'}


def _vessel_params(scenario, spec):
    return node_parameters(scenario, spec, 0, record=True)[0]['vessel_node']


def test_scenario_wind_reaches_every_vessel_node_and_the_bag_metadata(scenario_variant):
    sc = load_scenario(scenario_variant(FLAGSHIP, lambda d: d.update(wind=WIND)))
    spec = sc.vessels[0]
    p = _vessel_params(sc, spec)
    assert (p['wind_speed'], p['wind_direction_deg'], p['wind_gust_sd'],
            p['wind_time_constant'], p['wind_seed'], p['wind_coefficients']) == (
        12.0, 270.0, 1.5, 30.0, 4, 'isherwood72')
    meta = wind_meta(sc.vessels)
    assert meta[0] == '--meta'
    key, value = meta[1].split('=', 1)
    assert key == f'mission.wind/{spec.namespace}' and json.loads(value) == WIND


def test_a_vessels_own_block_replaces_the_scenarios(scenario_variant):
    def change(d):
        d['wind'] = WIND
        next(iter(d['vessels'].values()))['wind'] = {'speed_mps': 0.0}
    sc = load_scenario(scenario_variant(FLAGSHIP, change))
    p = _vessel_params(sc, sc.vessels[0])
    assert p['wind_speed'] == 0.0 and 'wind_direction_deg' not in p


def test_platoon_vessels_get_the_scenario_wind(scenario_variant):
    def change(d):
        d['wind'] = {'speed_mps': 10.0, 'direction_deg': 45.0}
        d['platoon']['route'] = str((SCENARIOS / d['platoon']['route']).resolve())
    sc = load_scenario(scenario_variant(PLATOON, change))
    assert all(s.wind == {'speed_mps': 10.0, 'direction_deg': 45.0} for s in sc.vessels)


def test_no_wind_block_leaves_the_parameters_alone():
    sc = load_scenario(FLAGSHIP)
    assert not any(k.startswith('wind_') for k in _vessel_params(sc, sc.vessels[0]))
    assert wind_meta(sc.vessels) == []


@pytest.mark.parametrize('block, key', [
    ({'speed_mps': -1.0}, 'wind.speed_mps'),
    ({'speed_mps': 70.0}, 'wind.speed_mps'),
    ({'direction': 10.0}, 'wind.direction'),
    ({'seed': 1.5}, 'wind.seed'),
    ({'coefficients': 'mss'}, 'wind.coefficients'),
    ([1, 2], 'wind'),
])
def test_bad_wind_block_is_refused_naming_the_key(scenario_variant, block, key):
    with pytest.raises(ScenarioError, match=key.replace('.', r'\.')):
        load_scenario(scenario_variant(FLAGSHIP, lambda d: d.update(wind=block)))


def test_wind_on_a_model_without_wind_loads_is_refused_before_the_run(scenario_variant):
    def change(d):
        d['wind'] = {'speed_mps': 10.0}
        next(iter(d['vessels'].values()))['model'] = 'nomoto1'
    with pytest.raises(ScenarioError, match=r"vessel_0\.wind: model 'nomoto1' has no wind"):
        load_scenario(scenario_variant(FLAGSHIP, change))

    def calm(d):
        change(d)
        next(iter(d['vessels'].values()))['wind'] = {'speed_mps': 0.0}
    assert load_scenario(scenario_variant(FLAGSHIP, calm)).vessels[0].model == 'nomoto1'
