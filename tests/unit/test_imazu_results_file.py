"""The Imazu page's results file merged from benchmark folders (imazu.results_file) and its
tables (results_pages.imazu): each set keeps its own run's provenance, the first action is the
earliest manoeuvre of any target, and the sets no folder holds are named with their command."""
import csv
import json

import pytest

from imazu.results_file import MergeError, merge
from results_pages.studies import render

CASES = {1: {'targets': [{'colregs': 'head-on'}]},
         2: {'targets': [{'colregs': 'crossing-give-way'}, {'colregs': 'overtaking'}]}}


def _case(distance, back):
    return {'min_distance_m': distance, 'collisions': 0, 'near_misses': 1, 'rule_score': 0.5,
            'path_deviation_m': 10.0, 'time_lost_s': 20.0, 'min_hull_clearance_m': 1.0,
            'last_cpa_s': 30.0, 'return_to_route_s': back, 'run_end_s': 40.0,
            'run_end': 'clear', 'penalties': {'ts1': ['late']}}


def _folder(tmp_path, name, ship, method, commit):
    folder = tmp_path / name
    folder.mkdir()
    totals = {'runs': 2, 'collisions': 0, 'near_misses': 2, 'below_safe': 1,
              'min_distance_m': 300.0, 'rule_score_mean': 0.5,
              'rule_score_single_target_mean': 0.5, 'path_deviation_m_mean': 10.0,
              'time_lost_s_mean': 20.0, 'return_to_route_s_mean': 5.0,
              'never_back_on_route': 1, 'limit_hit': 0}
    summary = {'groups': {f'{ship}/{method}': {**totals, 'cases': {
                   '1': _case(300.0, 5.0), '2': _case(400.0, None)}}},
               'limit_s': 4000.0, 'run_wall_s_mean': 50.0, 'decision_ms_mean': 3.0,
               'provenance': {'command': f'bench --ships {ship}', 'commit': commit,
                              'date_utc': 'today', 'load_1min': 7.0, 'cpus': 2}}
    (folder / 'summary.json').write_text(json.dumps(summary))
    with open(folder / 'results.csv', 'w', newline='') as f:
        w = csv.DictWriter(f, fieldnames=['case', 'ship', 'method', 'target',
                                          'manoeuvre_start_s'])
        w.writeheader()
        w.writerows([{'case': 1, 'ship': ship, 'method': method, 'target': 'ts1',
                      'manoeuvre_start_s': ''},
                     {'case': 2, 'ship': ship, 'method': method, 'target': 'ts1',
                      'manoeuvre_start_s': 250.0},
                     {'case': 2, 'ship': ship, 'method': method, 'target': 'ts2',
                      'manoeuvre_start_s': 120.0}])
    return folder


def _data(tmp_path):
    folders = [_folder(tmp_path, 'b', 'tanker', 'sbmpc', 'b' * 40),
               _folder(tmp_path, 'a', 'mariner', 'sbmpc', 'a' * 40)]
    prov = {'command': 'merge', 'commit': 'c', 'date_utc': 'd', 'load_1min': 1.0, 'cpus': 2}
    return merge(folders, ['mariner', 'tanker'], ['sbmpc', 'vo'], CASES, prov)


def test_sets_keep_their_runs_provenance_and_the_missing_ones_are_listed(tmp_path):
    data = _data(tmp_path)
    assert list(data['sets']) == ['mariner/sbmpc', 'tanker/sbmpc']   # ships, then methods
    assert data['not_run'] == ['mariner/vo', 'tanker/vo']
    assert data['sets']['tanker/sbmpc']['run']['commit'] == 'b' * 40
    assert data['cases'] == {'1': ['head-on'], '2': ['crossing-give-way', 'overtaking']}
    runs = render('imazu', 'runs', data)
    assert f"`{'a' * 10}`" in runs and '`bench --ships tanker`' in runs
    missing = render('imazu', 'not_run', data)
    assert '--ships tanker --methods vo' in missing and 'mariner/vo' in missing
    assert 'tanker/sbmpc' not in missing


def test_first_action_is_the_earliest_manoeuvre_of_any_target(tmp_path):
    data = _data(tmp_path)
    case1, case2 = (data['sets']['mariner/sbmpc']['cases'][c] for c in ('1', '2'))
    assert case1['first_action_s'] is None and case2['first_action_s'] == 120.0
    table = render('imazu', 'cases', data)
    # case 1: no manoeuvre found, back on route at 5 s; case 2: 120 s, never back on route
    assert '| 1 | head-on | 0 | 1 | 300 | 0.50 | ts1: late | 10 | 20 | never | 5 | clear 40 |' \
        in table
    assert '| 120 | never |' in table
    totals = render('imazu', 'totals', data)
    assert '| 120 | 1 |' in totals    # the mean over the one case with a manoeuvre, one without


def test_one_set_in_two_folders_is_refused(tmp_path):
    folders = [_folder(tmp_path, 'a', 'mariner', 'vo', 'a' * 40),
               _folder(tmp_path, 'b', 'mariner', 'vo', 'b' * 40)]
    with pytest.raises(MergeError, match='mariner/vo'):
        merge(folders, ['mariner'], ['vo'], CASES, {})
    with pytest.raises(MergeError, match='no summary.json'):
        merge([tmp_path], ['mariner'], ['vo'], CASES, {})


def test_a_folder_of_the_other_encounter_set_is_refused_and_the_dnv_commands_name_it(tmp_path):
    imazu = _folder(tmp_path, 'a', 'mariner', 'sbmpc', 'a' * 40)      # no 'set': an Imazu run
    with pytest.raises(MergeError, match='a run of the imazu set, not of dnv'):
        merge([imazu], ['mariner'], ['sbmpc'], CASES, {}, 'dnv')
    dnv = _folder(tmp_path, 'b', 'tanker', 'sbmpc', 'b' * 40)
    summary = json.loads((dnv / 'summary.json').read_text())
    (dnv / 'summary.json').write_text(json.dumps({**summary, 'set': 'dnv'}))
    data = merge([dnv], ['tanker'], ['sbmpc', 'vo'], CASES, {}, 'dnv')
    assert data['set'] == 'dnv' and data['not_run'] == ['tanker/vo']
    missing = render('dnv', 'not_run', data)
    assert '--set dnv --ships tanker --methods vo' in missing
    assert 'imazu_results.py --set dnv' in missing
