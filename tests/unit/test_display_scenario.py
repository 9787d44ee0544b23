"""The scenario's `display:` key and the nav_display_node parameters the launcher derives."""
from pathlib import Path

import pytest
import yaml

from ship_mission.launcher import display_every, display_parameters
from ship_mission.scenario import ScenarioError, load_scenario

from ship_planner.route_loader import load_route

REPO = Path(__file__).resolve().parents[2]
FLAGSHIP = REPO / 'scenarios' / 'flagship_mariner.yaml'
BUSAN = REPO / 'scenarios' / 'busan_passage_mariner.yaml'


def _variant(tmp_path, source, display):
    data = yaml.safe_load(source.read_text())
    for v in data['vessels'].values():
        v['route'] = str((source.parent / v['route']).resolve())
    if display is not None:
        data['display'] = display
    path = tmp_path / 'variant.yaml'
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return load_scenario(path)


def test_display_is_on_by_default_and_reads_one_odom_per_frame(tmp_path):
    sc = _variant(tmp_path, FLAGSHIP, None)
    # 2 frames per sim second (the node's default) at dt = 0.1 s: every 5th step.
    assert sc.display == {} and display_every(sc) == round(1.0 / (sc.dt_s * 2.0))
    spec = sc.vessels[0]
    assert display_parameters(sc, spec) == {'use_sim_time': False, 'model': spec.model}
    assert display_every(_variant(tmp_path, FLAGSHIP, {'display_rate_hz': 100.0})) == 1


def test_display_false_starts_nothing(tmp_path):
    sc = _variant(tmp_path, FLAGSHIP, False)
    assert sc.display is None and display_every(sc) == 0


def test_the_fix_origin_is_the_route_origin_unless_the_scenario_gives_one(tmp_path):
    sc = _variant(tmp_path, BUSAN, None)
    plan = load_route(sc.vessels[0].route_file)
    assert plan.origin_lat_deg is not None
    p = display_parameters(sc, sc.vessels[0])
    assert (p['origin_lat_deg'], p['origin_lon_deg']) == (plan.origin_lat_deg, plan.origin_lon_deg)
    sc = _variant(tmp_path, BUSAN, {'origin': {'lat_deg': 10.0, 'lon_deg': 20.0},
                                    'display_rate_hz': 5.0})
    p = display_parameters(sc, sc.vessels[0])
    assert (p['origin_lat_deg'], p['origin_lon_deg'], p['display_rate_hz']) == (10.0, 20.0, 5.0)


@pytest.mark.parametrize('display, key', [
    ({'rate': 1.0}, 'display.rate'),
    ({'display_rate_hz': 0.0}, 'display.display_rate_hz'),
    ({'origin': {'lat_deg': 95.0, 'lon_deg': 0.0}}, 'display.origin.lat_deg'),
    ('yes', 'display'),
])
def test_a_bad_display_key_is_refused_naming_it(tmp_path, display, key):
    with pytest.raises(ScenarioError, match=f': {key}: '):
        _variant(tmp_path, FLAGSHIP, display)


def test_without_any_origin_the_display_uses_the_default_sea_area_not_0_0(tmp_path):
    """The flagship gives no origin (display, routes, ais): the launcher passes none and the
    node's default (its config file says the same) is the documented sea area; a scenario whose
    only origin is its `ais:` block's gets that one."""
    from ship_guidance.nav_display import DEFAULT_ORIGIN_DEG
    from ship_mission.scenario import scenario_origin as display_origin
    sc = _variant(tmp_path, FLAGSHIP, None)
    assert display_origin(sc) is None and 'origin_lat_deg' not in display_parameters(sc, sc.vessels[0])
    config = yaml.safe_load((REPO / 'ros_ws' / 'src' / 'ship_guidance' / 'config' /
                             'nav_display.yaml').read_text())['/**']['ros__parameters']
    assert (config['origin_lat_deg'], config['origin_lon_deg']) == DEFAULT_ORIGIN_DEG
    assert abs(DEFAULT_ORIGIN_DEG[0]) > 1.0 and abs(DEFAULT_ORIGIN_DEG[1]) > 1.0
    ais = load_scenario(REPO / 'scenarios' / 'head_on_ais_mariner.yaml')
    assert all(load_route(s.route_file).origin_lat_deg is None for s in ais.vessels)
    assert display_origin(ais) == (ais.ais['origin_lat_deg'], ais.ais['origin_lon_deg'])
