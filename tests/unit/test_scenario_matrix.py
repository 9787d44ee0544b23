"""Scenario matrices (ship_mission.matrix): one file expanding to the scenarios of a grid.

- the expansion: one scenario per combination of the axes, the first axis slowest; rules apply
  in order to the combinations they match; strings filled in from the variables, a lone
  ``{name}`` keeping the variable's type; bad matrices refused in one line naming the key;
- ship_mission.scenario: load_scenarios gives every scenario of a matrix, load_scenario the one named;
  scenario_text is the mapping of that one scenario;
- scenarios/course_changes_004.yaml expands to exactly the 32 course-change files it replaced
  (read from the repository's history).
"""
import json
import subprocess
from pathlib import Path

import pytest
import yaml

from ship_sim.schema import VESSEL_NODE
from ship_mission.matrix import expand
from ship_mission.scenario import ScenarioError, load_scenario, load_scenarios, scenario_text
from ship_planner.yaml_route_reader import Loader

ROOT = Path(__file__).resolve().parents[2]
COURSE_MATRIX = ROOT / 'scenarios' / 'course_changes_004.yaml'
#: The commit whose scenarios/ still held the 32 course-change files the matrix replaced.
BEFORE_MATRIX = 'fcd045f'


def test_one_scenario_per_combination_first_axis_slowest_rules_in_order():
    data = {'matrix': {
        'axes': {'ship': ['a', 'b'], 'n': [1, 2, 3]},
        'rules': [
            {'vars': {'speed': 5.0}, 'set': {'name': 'x_{ship}_{n}', 'speed': '{speed}',
                                             'deep': {'keep': 1, 'over': 'base'}}},
            {'when': {'ship': 'b'}, 'vars': {'speed': 7.5}},
            {'when': {'n': [2, 3], 'ship': 'a'}, 'set': {'deep': {'over': 'a{n}'}}},
        ]}}
    out = expand(data, 'f.yaml')
    assert [d['name'] for d in out] == ['x_a_1', 'x_a_2', 'x_a_3', 'x_b_1', 'x_b_2', 'x_b_3']
    # a later rule's vars replace an earlier one's; a lone '{speed}' keeps the float
    assert [d['speed'] for d in out] == [5.0] * 3 + [7.5] * 3
    assert all(type(d['speed']) is float for d in out)
    # set merges mappings key by key, only where `when` matches
    assert [d['deep'] for d in out] == [{'keep': 1, 'over': 'base'}, {'keep': 1, 'over': 'a2'},
                                        {'keep': 1, 'over': 'a3'}] + [{'keep': 1, 'over': 'base'}] * 3


def test_variables_fill_each_other_and_keep_their_type_when_alone():
    data = {'matrix': {'axes': {'angle': [30, 90]}, 'rules': [
        {'vars': {'heading': '{angle} deg', 'text': 'turn by {heading}', 'sched': [0.0, '{angle}']},
         'set': {'name': 'c{angle}', 'description': '{text}', 'schedule': '{sched}',
                 'ratio': '{angle:.1f}'}}]}}
    out = expand(data, 'f.yaml')
    assert out[1]['description'] == 'turn by 90 deg'
    assert out[1]['schedule'] == [0.0, 90] and type(out[1]['schedule'][1]) is int
    assert out[0]['ratio'] == '30.0'


def _refusal(data):
    with pytest.raises(ScenarioError) as exc:
        expand(data, 'f.yaml')
    text = str(exc.value)
    assert text.startswith('f.yaml: ') and '\n' not in text
    return text


@pytest.mark.parametrize('matrix, words', [
    ({'axes': {}}, 'matrix.axes'),
    ({'axes': {'a': []}}, 'matrix.axes.a'),
    ({'axes': {'a': [1, 1]}}, 'repeat'),
    ({'axes': {'a': [[1]]}}, 'strings or numbers'),
    ({'axes': {'a': [1]}, 'rules': [{'when': {'b': 1}}]}, 'rules[0].when.b: not an axis'),
    ({'axes': {'a': [1]}, 'rules': [{'when': {'a': 2}}]}, 'is not one of its values'),
    ({'axes': {'a': [1]}, 'rules': [{'sets': {}}]}, 'rules[0].sets: unknown key'),
    ({'axes': {'a': [1]}, 'rules': [{'set': {'name': 'x{b}'}}]}, "scenario.name: no variable 'b'"),
    ({'axes': {'a': [1]}, 'rules': [{'vars': {'p': '{q}', 'q': '{p}'},
                                     'set': {'name': '{p}'}}]},
     'vars.q: variables fill each other in a loop: p -> q -> p'),
    ({'axes': {'a': [1, 2]}, 'rules': [{'set': {'name': 'same'}}]}, 'repeated: same'),
    ({'axes': {'a': [1]}, 'rules': [{'set': {'name': 'x{a!z}'}}]}, 'cannot fill in'),
])
def test_bad_matrices_are_refused_in_one_line_naming_the_key(matrix, words):
    assert words in _refusal({'matrix': matrix})


def test_a_matrix_file_holds_only_the_matrix():
    assert 'name: a matrix file holds only' in _refusal({'name': 'x', 'matrix': {'axes': {'a': [1]}}})


def _matrix_file(tmp_path, extra_rule=None):
    route = ROOT / 'scenarios' / 'routes' / 'flagship_mariner.yaml'
    rules = [{'set': {'name': 'm_{law}', 'duration_s': 10.0,
                      'vessels': {'vessel_0': {'model': 'mariner', 'route': str(route),
                                               'guidance': {'law': '{law}'}}}}}]
    path = tmp_path / 'm.yaml'
    path.write_text(yaml.safe_dump({'matrix': {'axes': {'law': ['los', 'ilos']},
                                               'rules': rules + ([extra_rule] if extra_rule else [])}}))
    return path


def test_load_scenarios_gives_the_matrix_and_load_scenario_the_one_named(tmp_path):
    path = _matrix_file(tmp_path)
    both = load_scenarios(path)
    assert [s.name for s in both] == ['m_los', 'm_ilos']
    assert [s.vessels[0].guidance_params['law'] for s in both] == ['los', 'ilos']
    one = load_scenario(path, 'm_ilos')
    assert one.vessels[0].guidance_params == {'law': 'ilos'} and one.file == path
    # scenario_text: that scenario's mapping, not the matrix
    assert yaml.safe_load(scenario_text(one)) == one.expanded
    assert yaml.safe_load(scenario_text(one))['name'] == 'm_ilos'
    with pytest.raises(ScenarioError, match=r'holds 2 scenarios .*--name'):
        load_scenario(path)
    with pytest.raises(ScenarioError, match="no scenario 'm_x' here"):
        load_scenario(path, 'm_x')


def test_a_bad_scenario_of_a_matrix_is_named_with_its_key(tmp_path):
    path = _matrix_file(tmp_path, {'when': {'law': 'ilos'}, 'set': {'duration_s': -1.0}})
    with pytest.raises(ScenarioError) as exc:
        load_scenarios(path)
    assert str(exc.value) == (f"{path}: scenario 'm_ilos' of the matrix: duration_s: must be "
                              '>= 0.1, got -1.0')


def _files_before_the_matrix():
    """{name: parsed content} of the course-change files at BEFORE_MATRIX, via git."""
    try:
        listing = subprocess.run(['git', '-C', str(ROOT), 'ls-tree', '--name-only',
                                  BEFORE_MATRIX, 'scenarios/'], capture_output=True, text=True,
                                 timeout=30)
    except (OSError, subprocess.TimeoutExpired):
        listing = None
    if listing is None or listing.returncode != 0:
        pytest.skip(f'no git history with commit {BEFORE_MATRIX} (a shallow clone or an export)')
    out = {}
    for p in listing.stdout.split():
        name = Path(p).stem
        if name.startswith('course_') and p.endswith('.yaml'):
            text = subprocess.run(['git', '-C', str(ROOT), 'show', f'{BEFORE_MATRIX}:{p}'],
                                  capture_output=True, text=True, check=True, timeout=30).stdout
            out[name] = yaml.load(text, Loader=Loader)
    return out


def _typed(obj):
    """JSON with each number's type kept (400 and 400.0 differ for the nodes' parameters)."""
    def mark(o):
        if isinstance(o, dict):
            return {k: mark(v) for k, v in o.items()}
        if isinstance(o, list):
            return [mark(v) for v in o]
        return [type(o).__name__, o]
    return json.dumps(mark(obj), sort_keys=True, indent=1)


def test_the_course_matrix_is_the_32_files_it_replaced():
    before = _files_before_the_matrix()
    assert len(before) == 32
    now = {s.name: s.expanded for s in load_scenarios(COURSE_MATRIX)}
    assert sorted(now) == sorted(before)
    for name, content in before.items():
        # the files used vessel_node's names before the renames (depth -> water_depth_m), which
        # the node still takes: compare under the current names
        for spec in content['vessels'].values():
            if 'vessel' in spec:
                spec['vessel'] = VESSEL_NODE.current_names(spec['vessel'])
        # ... and their descriptions pointed at a README section that moved to the results pages
        content['description'] = content['description'].replace(
            'see README, Seed scenarios)', 'see doc/results/seed_scenarios.md)')
        assert _typed(now[name]) == _typed(content), name
