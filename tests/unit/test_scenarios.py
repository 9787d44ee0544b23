"""The shipped scenario files and what the seed batch relies on (cheap: no ROS graph is started).

- every scenario of scenarios/*.yaml loads (ship_mission.scenario.load_scenarios: a plain file's one,
  each of a matrix file's), its route loads, and the launcher can derive the node parameters
  from it;
- every seed scenario cites its source document by author and year (SEED_DOCUMENTS), asks
  for a look-ahead above the stability limit of its paired autopilot (Angelopoulos 2011 eq. 34
  / Simakis 1992 eq. 3.5, in metres) with the autopilot's real omega_n, and runs long enough to
  finish its route at the model's trim speed;
- the Lee 2004 course changes (_004, the matrix scenarios/course_changes_004.yaml) step the
  course by the angle their name says, from the route's course, and a PD run differs from its
  fuzzy PID twin only in the autopilot; the Simakis 1992 files (_003) give the NPS AUV II's
  0.4 rad limit to the autopilot;
- guidance_node's course law: the schedule parser and lookup (hand-computed values);
- run_seed_scenarios: scenario selection and the claim checks on hand-made rows.
"""
import copy
import math
import pathlib
import re

import pytest
import yaml

from ship_mission.launcher import node_parameters
from ship_mission.scenario import load_scenario, load_scenarios
from ship_guidance.los import critical_lookahead
from ship_planner.route_loader import load_route
from ship_sim.simulator import VesselSimulator

ROOT = pathlib.Path(__file__).resolve().parents[2]
# The project's four source documents, as identified from their title pages; a seed scenario
# (name ending in _000, _001, _003 or _004) must cite its document by author and year.
SEED_DOCUMENTS = {
    # Martinsen and Lekkas (NTNU), "Curved path following with deep reinforcement learning:
    # results from three vessel models", OCEANS 2018
    '000': 'Martinsen and Lekkas 2018',
    # Angelopoulos, "String stability of multiple surface marine vessels", NPS thesis, 2011
    '001': 'Angelopoulos 2011',
    # Simakis, "Vehicle guidance and control along circular trajectories", NPS thesis, 1992
    '003': 'Simakis 1992',
    # Lee (Korea Maritime University), "An optimal route decision and LOS guidance system for
    # automatic navigation of ships", thesis, 2004
    '004': 'Lee 2004',
}
FILES = sorted((ROOT / 'scenarios').glob('*.yaml'))
#: (file, scenario name) of every shipped scenario: a plain file's one, each of a matrix file's
SCENARIOS = [(f, s.name) for f in FILES for s in load_scenarios(f)]
SEEDS = [(f, name) for f, name in SCENARIOS if re.search(r'_00[0-4]$', name)]
GAINS = yaml.safe_load((ROOT / 'ros_ws/src/ship_autopilot/ship_autopilot/data/'
                        'autopilot_gains.yaml').read_text())['models']


def ids(entries):
    return [name for _, name in entries]


@pytest.mark.parametrize('path, name', SCENARIOS, ids=ids(SCENARIOS))
def test_scenario_and_its_route_load(path, name):
    scenario = load_scenario(path, name)
    assert scenario.vessels
    for i, spec in enumerate(scenario.vessels):
        plan = load_route(spec.route_file)
        assert plan.route.length > 0.0
        params, _ = node_parameters(scenario, spec, i, record=True)
        assert params['vessel_node']['model'] == spec.model
        assert params['vessel_node']['max_steps'] == round(scenario.duration_s / scenario.dt_s)


def test_the_seed_scenarios_are_there():
    names = {name for _, name in SEEDS}
    assert {'figure_eight_003', 'quarter_circle_arc_003', 'quarter_circle_03pts_003',
            'quarter_circle_13pts_003', 'route_following_mariner_pd_004',
            'route_following_tanker_fuzzy_004', 'curved_path_tanker_current09_ilos_000'} <= names
    for ang in (30, 45, 60, 90):
        assert {f'course_change_{ang}_pd_004', f'course_change_{ang}_fuzzy_004'} <= names
    for ship in ('mariner', 'container', 'tanker'):
        for cur in ('0', '09'):
            assert f'curved_path_{ship}_current{cur}_los_000' in names


@pytest.mark.parametrize('path, name', SEEDS, ids=ids(SEEDS))
def test_seed_scenario_cites_its_source_by_author_and_year(path, name):
    scenario = load_scenario(path, name)
    seed = name[-3:]
    cited = [k for k, citation in SEED_DOCUMENTS.items() if citation in scenario.source]
    assert cited, f'{name}: source cites none of {sorted(SEED_DOCUMENTS.values())}'
    assert seed in cited, f'{name} does not cite {SEED_DOCUMENTS[seed]}'
    assert scenario.description


def _pd_design(spec):
    """{zeta, omega_n} of the heading loop the autopilot block builds: the gain table's, or for
    a PD with its own k1, k2 the design they place on the model (the node's function)."""
    a = spec.autopilot_params
    if a.get('controller', 'pd') == 'pd' and a.get('k1'):
        from ship_autopilot.gains import heading_loop_design
        d = heading_loop_design(spec.model, 'pd', a['k1'], a['k2'])
        return {'zeta': d.zeta, 'omega_n': d.omega_n}
    return GAINS[spec.model]


@pytest.mark.parametrize('path, name', SEEDS, ids=ids(SEEDS))
def test_lookahead_is_above_the_stability_limit_of_the_paired_autopilot(path, name):
    spec = load_scenario(path, name).vessels[0]
    g = spec.guidance_params
    # The check must be switched on (the node refuses an unstable look-ahead only then) ...
    assert all(g.get(k) for k in ('autopilot_zeta', 'autopilot_omega_n', 'speed'))
    # ... with the autopilot that really runs: the gain table's design for this model, or the
    # design a PD's own k1, k2 place (Lee 2004's gains in the *_thesisgains_004 files).
    design = _pd_design(spec)
    assert g['autopilot_omega_n'] == pytest.approx(design['omega_n'], rel=1e-4)
    assert g['autopilot_zeta'] == pytest.approx(design['zeta'], rel=1e-4)
    assert g['speed'] == pytest.approx(VesselSimulator(spec.model).speed_water(), rel=2e-3)
    d = g.get('lookahead_m') or g['lookahead_ship_lengths'] * g['ship_length_m']
    sigma = g.get('integral_gain', 0.5) if g.get('law', 'ilos') == 'ilos' else 0.0
    assert d > critical_lookahead(g['autopilot_zeta'], g['autopilot_omega_n'], g['speed'], sigma)


# Not the fixed-length experiments: 300 s course changes (Lee 2004), 1000 s episodes (Martinsen and Lekkas 2018).
ROUTE_RUNS = [(f, n) for f, n in SEEDS if not n.startswith(('course_change_', 'curved_path_'))]


@pytest.mark.parametrize('path, name', ROUTE_RUNS, ids=ids(ROUTE_RUNS))
def test_route_runs_are_long_enough_to_finish(path, name):
    scenario = load_scenario(path, name)
    spec = scenario.vessels[0]
    route = load_route(spec.route_file).route
    trim_speed = VesselSimulator(spec.model).speed_water()
    assert route.length / trim_speed < scenario.duration_s


COURSE_RUNS = [(f, n) for f, n in SEEDS if n.startswith('course_')]


@pytest.mark.parametrize('path, name', COURSE_RUNS, ids=ids(COURSE_RUNS))
def test_course_change_steps_by_the_angle_in_its_name(path, name):
    scenario = load_scenario(path, name)
    spec = scenario.vessels[0]
    angle = float(re.match(r'course_(?:change|mariner|tanker)_(\d+)_', name).group(1))
    _, _, path_angle = load_route(spec.route_file).route.point_at(0.0)
    sched = spec.guidance_params['course_schedule_deg']
    assert sched[0] == 0.0 and len(sched) == 2            # the step comes at t = 0 (004 Figs.)
    assert spec.start.get('heading_deg', 0.0) == 0.0       # starting on the route's course
    assert sched[1] - math.degrees(path_angle) == pytest.approx(angle)
    assert scenario.duration_s >= 300.0                    # 004 Figs. 5.8-5.11 span 300 s
    assert scenario.settle_s < scenario.duration_s


def test_course_change_pairs_differ_only_in_the_controller():
    # the gain table's runs (Lee 2004's own gains place another loop for each controller)
    pairs = [(f, n) for f, n in COURSE_RUNS if n.startswith('course_change_') and '_pd_' in n]
    assert len(pairs) == 4
    for path, pd in pairs:
        a, b = (copy.deepcopy(load_scenario(path, n).expanded)
                for n in (pd, pd.replace('_pd_', '_fuzzy_')))
        assert a['vessels']['vessel_0']['autopilot'] == {'controller': 'pd'}
        assert b['vessels']['vessel_0']['autopilot'] == {'controller': 'fuzzy_pid'}
        for d in (a, b):
            for key in ('name', 'source', 'description'):
                d.pop(key)
            d['vessels']['vessel_0'].pop('autopilot')
        assert a == b


AUV_RUNS = [(f, n) for f, n in SEEDS if n.endswith('_003')]


@pytest.mark.parametrize('path, name', AUV_RUNS, ids=ids(AUV_RUNS))
def test_auv_scenarios_pass_the_vehicle_rudder_limits_to_the_autopilot(path, name):
    spec = load_scenario(path, name).vessels[0]
    assert spec.model == 'nps_auv2'
    ap = spec.autopilot_params
    assert math.radians(ap['rudder_max_deg']) == pytest.approx(0.4)   # 003: |DR| <= 0.4 rad
    assert math.radians(ap['rudder_rate_max_deg']) == pytest.approx(1.0)
    from ship_sim.models import make_model
    model = make_model('nps_auv2')
    assert model.rudder_max == pytest.approx(0.4) and model.rudder_rate_max == pytest.approx(1.0)
    # 003's arc law leads the tangent by d / (2R); the turn-rate lead is our equivalent
    # (2 zeta U / omega_n within 10 % of d / 2 for this vehicle and look-ahead).
    g = spec.guidance_params
    assert g['curvature_lead'] is True
    d = g['lookahead_ship_lengths'] * g['ship_length_m']
    lead = 2 * g['autopilot_zeta'] * g['speed'] / g['autopilot_omega_n']
    assert lead == pytest.approx(d / 2, rel=0.1)


# -- guidance_node: the course law's schedule -----------------------------------------------------

def test_course_schedule_parse_and_lookup():
    from ship_guidance.guidance import course_at, parse_course_schedule
    times, courses = parse_course_schedule([0.0, 90.0, 50, 120, 100.0, -45.0])
    assert times == [0.0, 50.0, 100.0]
    assert courses == pytest.approx([math.pi / 2, 2 * math.pi / 3, -math.pi / 4])
    assert course_at(times, courses, -5.0) == pytest.approx(math.pi / 2)   # before t0: course0
    assert course_at(times, courses, 49.99) == pytest.approx(math.pi / 2)
    assert course_at(times, courses, 50.0) == pytest.approx(2 * math.pi / 3)  # from t1 on
    assert course_at(times, courses, 1e6) == pytest.approx(-math.pi / 4)


@pytest.mark.parametrize('bad', [[], [0.0], [0.0, 10.0, 5.0], [0.0, 10.0, 0.0, 20.0],
                                 [10.0, 0.0, 5.0, 1.0], [0.0, float('nan')], [0.0, True],
                                 ['0', '10']])
def test_course_schedule_refuses_bad_values(bad):
    from ship_guidance.guidance import parse_course_schedule
    with pytest.raises(ValueError):
        parse_course_schedule(bad)


# -- run_seed_scenarios ---------------------------------------------------------------------------

def test_runner_selects_the_seed_scenarios_and_filters():
    import run_seed_scenarios as rs
    chosen = rs.find_scenarios([], [])
    assert sorted(s.name for s in chosen) == sorted(ids(SEEDS))
    only = rs.find_scenarios([], ['course_change_3', 'quarter_circle_*pts_003'])
    assert {s.name for s in only} == {'course_change_30_pd_004', 'course_change_30_fuzzy_004',
                                     'quarter_circle_03pts_003', 'quarter_circle_05pts_003',
                                     'quarter_circle_07pts_003', 'quarter_circle_13pts_003'}
    for ref in rs.REFERENCE_ROUTES.values():
        assert (ROOT / 'scenarios' / ref).exists()


def _row(**metrics):
    return {'metrics': metrics}


def test_runner_claim_checks_on_hand_made_rows():
    import run_seed_scenarios as rs
    rows = {
        'course_change_30_pd_004': _row(heading_error_mean_rad=math.radians(-1.0)),
        'course_change_30_fuzzy_004': _row(heading_error_mean_rad=math.radians(0.2)),
        'course_change_45_pd_004': _row(heading_error_mean_rad=math.radians(-1.0)),
        'course_change_45_fuzzy_004': _row(heading_error_mean_rad=math.radians(-0.8)),
        'course_change_60_pd_004': _row(heading_error_mean_rad=math.radians(-1.0)),
        'course_change_90_pd_004': _row(heading_error_mean_rad=math.radians(-1.0)),
        'course_change_90_fuzzy_004': _row(heading_error_mean_rad=math.radians(1.5)),
        # Table I at 0.9 m/s ranks container (829) > mariner (499) > tanker (62)
        'curved_path_mariner_current09_los_000': _row(reward_gaussian_sum=900.0),
        'curved_path_container_current09_los_000': _row(reward_gaussian_sum=1000.0),
        'curved_path_tanker_current09_los_000': _row(reward_gaussian_sum=10.0),
        # ... and at 0 m/s the same: here mariner and container swapped
        'curved_path_mariner_current0_los_000': _row(reward_gaussian_sum=900.0),
        'curved_path_container_current0_los_000': _row(reward_gaussian_sum=800.0),
        'curved_path_tanker_current0_los_000': _row(reward_gaussian_sum=10.0),
    }
    verdicts = {c.split(':')[0]: v for c, v, _ in rs.claim_checks(rows)}
    assert verdicts['Lee 2004 Fig. 5.7-5.11, 30 deg'] is True      # |0.2| < |-1.0|
    assert verdicts['Lee 2004 Fig. 5.7-5.11, 45 deg'] is True      # |-0.8| < |-1.0|
    assert verdicts['Lee 2004 Fig. 5.7-5.11, 60 deg'] is None      # the fuzzy run is missing
    assert verdicts['Lee 2004 Fig. 5.7-5.11, 90 deg'] is False     # |1.5| > |-1.0|
    assert verdicts['Martinsen and Lekkas 2018 Table I, LOS at 0.9 m/s'] is True
    assert verdicts['Martinsen and Lekkas 2018 Table I, LOS at 0.0 m/s'] is False
    assert not any(c.startswith('003') for c in verdicts)     # no 003 run, no 003 claim


@pytest.mark.parametrize('value, expected', [(None, 'zstd'), ('lz4', 'lz4'), ('none', 'none'),
                                             ('gzip', None)])
def test_bag_compression_key(tmp_path, value, expected):
    from ship_mission.scenario import ScenarioError
    src = ROOT / 'scenarios' / 'flagship_mariner.yaml'
    data = yaml.safe_load(src.read_text())
    for v in data['vessels'].values():
        v['route'] = str((src.parent / v['route']).resolve())
    if value is not None:
        data['bag_compression'] = value
    path = tmp_path / 'variant.yaml'
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    if expected is None:
        with pytest.raises(ScenarioError, match=r"bag_compression.*one of none, lz4, zstd, got 'gzip'"):
            load_scenario(path)
    else:
        assert load_scenario(path).bag_compression == expected
