"""The results pages' generated tables equal what their committed results files render, so no
number in them can drift from the run that produced it (scripts/render_results.py)."""
import json

import pytest

from render_results import DOC, main
from results_pages.blocks import ResultsError, pages_with_blocks, render_page
from results_pages.tables import fmt, markdown_table


def test_every_committed_page_equals_its_rendering(capsys):
    assert pages_with_blocks(DOC), 'no generated blocks found under doc/'
    assert main(['--check']) == 0, capsys.readouterr().err


def _page(tmp_path, body):
    data = tmp_path / 'data'
    data.mkdir()
    (data / 'wf.json').write_text(json.dumps({
        'provenance': {'command': 'cmd', 'commit': 'abc', 'date_utc': 'd', 'load_1min': 1.0,
                       'cpus': 2},
        'runs': {'mariner, calm': {
            'no filter': [{'mean_abs_rudder_rate_deg_s': 2.0, 'rudder_total_variation_deg_per_h': 10,
                           'heading_error_rms_deg': 1.0, 'wave_yaw_rms_deg': 0.0}],
            'wave filter': [{'mean_abs_rudder_rate_deg_s': 0.5, 'rudder_total_variation_deg_per_h': 4,
                             'heading_error_rms_deg': 1.5, 'wave_yaw_rms_deg': 0.0}]}}}))
    page = tmp_path / 'p.md'
    page.write_text(body)
    return page


def test_a_hand_edited_number_is_found(tmp_path, capsys):
    page = _page(tmp_path, 'x\n<!-- generated: wave_filter.ratios from data/wf.json -->\n'
                           '<!-- end generated -->\ny\n')
    assert main(['--root', str(tmp_path)]) == 0
    rendered = page.read_text()
    # 2.0 / 0.5 and the heading error change 1.5 - 1.0, computed, not typed
    assert "| mariner | calm | 4.0 | +0.500 |" in rendered
    assert 'commit `abc`' in rendered and rendered.startswith('x\n') and rendered.endswith('y\n')
    assert main(['--root', str(tmp_path), '--check']) == 0
    assert main(['--root', str(tmp_path)]) == 0 and page.read_text() == rendered   # idempotent
    assert rendered.count('<!-- end generated -->') == 1
    page.write_text(rendered.replace('| 4.0 |', '| 4.5 |'))
    assert main(['--root', str(tmp_path), '--check']) == 1
    assert 'p.md' in capsys.readouterr().err


def test_missing_file_table_or_provenance_are_refused(tmp_path):
    page = _page(tmp_path, '<!-- generated: wave_filter.nope from data/wf.json -->\n'
                           '<!-- end generated -->\n')
    with pytest.raises(KeyError, match='wave_filter.nope'):
        render_page(page)
    page.write_text('<!-- generated: wave_filter.runs from data/missing.json -->\n'
                    '<!-- end generated -->\n')
    with pytest.raises(ResultsError, match='not found'):
        render_page(page)
    (tmp_path / 'data' / 'bare.json').write_text('{}')
    page.write_text('<!-- generated: wave_filter.runs from data/bare.json -->\n'
                    '<!-- end generated -->\n')
    with pytest.raises(ResultsError, match='provenance'):
        render_page(page)


def test_cells_say_n_a_for_undefined_values():
    assert fmt(None, '.3f') == 'n/a' and fmt(float('nan'), '.1f') == 'n/a'
    assert markdown_table([('a', 'a', '.1f')], [{'a': 1.25}]) == '| a |\n|---|\n| 1.2 |\n'


def test_table1_policy_is_compared_with_the_best_classical_loop_of_each_column():
    from results_pages.studies import render

    def r(g, e, rate):
        return {'gaussian': g, 'mean_abs_e': e, 'rudder_rate_deg_s': rate}
    data = {'models': ['mariner'], 'currents': [0.0, 0.9],
            'controllers': {'los': 'LOS + PD', 'los_lead': 'lead', 'policy': 'DDPG'},
            'results': {'mariner/0.0/los': r(100.0, 50.0, 0.1),
                        'mariner/0.0/los_lead': r(400.0, 20.0, 0.2),
                        'mariner/0.0/policy': r(1000.0, 5.0, 0.8),
                        'mariner/0.9/los': r(300.0, 30.0, 0.1),
                        'mariner/0.9/los_lead': {'error': 'diverged'},
                        'mariner/0.9/policy': r(600.0, 10.0, 0.3)}}
    text = render('table1', 'policy_vs_classical', data)
    # 0 m/s: the lead loop is best (400): 1000 / 400, 20 / 5, 0.8 / 0.2; at 0.9 m/s the failed
    # lead loop is left out and LOS is the best classical: 600 / 300, 30 / 10, 0.3 / 0.1
    assert '| mariner 0 m/s | lead | 2.5 | 4.0 | 4.0 |' in text
    assert '| mariner 0.9 m/s | LOS + PD | 2.0 | 3.0 | 3.0 |' in text
    assert 'error' in render('table1', 'reward', {**data, 'seed_table': {}})


def _wind_row(**kw):
    row = {'vessel': '/vessel_0', 'condition': '-', 'wind_mps': 0.0, 'finished': True,
           'time_to_complete_s': 1150.0, 'xte_rms_m': 13.71, 'xte_max_m': 27.04,
           'heading_rms_deg': 4.44, 'rudder_mean_abs_deg': 5.43, 'rudder_max_abs_deg': 36.7,
           'rudder_rate_mean_abs_deg_s': 0.4406, 'rudder_tv_deg': 419.0,
           'rudder_saturated_fraction': 0.0, 'rudder_limit_deg': 40.0,
           'reward_gaussian_sum': 6473.2}
    return {**row, **kw}


def test_the_flagship_sentence_is_the_wind_study_run_without_wind():
    from results_pages.studies import render
    data = {'rows': [_wind_row(wind_mps=10.0, xte_rms_m=99.0), _wind_row()]}
    text = render('wind_study', 'flagship', data)
    assert 'completed in 1150 s' in text and 'RMS cross-track 13.7 m, max 27.0 m' in text
    with pytest.raises(KeyError, match='without wind'):
        render('wind_study', 'flagship', {'rows': data['rows'][:1]})


def test_the_conditions_table_marks_a_rudder_at_its_limit_and_a_run_that_did_not_finish():
    from results_pages.studies import render
    data = {'rows': [_wind_row(condition='calm'),
                     _wind_row(condition='wind20', rudder_max_abs_deg=39.99993, finished=False,
                               rudder_saturated_fraction=0.008)]}
    lines = render('wind_study', 'conditions', data).splitlines()
    assert lines[2].startswith('| calm | 1150.0 | 13.71 / 27.04 |') and '| 36.7 |' in lines[2]
    assert lines[3].startswith('| wind20 | no |') and '| 40.0 (limit) |' in lines[3]
    assert '| 0.8 | 6473 |' in lines[3]      # 0.008 of the samples, in %


def test_platoon_and_encounter_tables_read_the_runs_metrics():
    from results_pages.studies import render
    vessels = {'/vessel_0': {'xte_rms_m': 10.0, 'xte_max_abs_m': 20.0, 'time_to_complete_s': 1300.0},
               '/vessel_1': {'xte_rms_m': 15.0, 'xte_max_abs_m': 30.0, 'time_to_complete_s': None}}
    platoon = {'/vessel_1': {'predecessor': '/vessel_0', 'string_peak_ratio': 1.5,
                             'string_rms_ratio': 1.5, 'gap_error_rms_m': 22.0}}
    data = {'runs': {'platoon_mariner_5': {'vessels': vessels, 'platoon': platoon}}}
    lines = render('platoon', 'vessels', data).splitlines()
    assert lines[2] == '| vessel_0 | - | 10.0 | 20.0 | n/a | n/a | n/a | 1300.0 |'
    assert lines[3] == '| vessel_1 | vessel_0 | 15.0 | 30.0 | 1.50 | 1.50 | 22.0 | n/a |'
    closest = {'min_distance_m': 991.7, 't_min_s': 265.7, 'side': 'port',
               'bearing_at_min_deg': 254.5}
    run = {'vessels': vessels, 'run': {'wall_time_s': 24.0, 'sim_time_s': 500.0},
           'colav': {'vessel_0': {'alteration': {'first_avoid_s': 0.0, 'first_offset_deg': 45.0,
                                                 'max_offset_deg': 89.8, 'last_resort': False},
                                  'closest': {'vessel_1': closest}}},
           'traffic': {'t1': {'source': 'light', 'closest_approach': {'/vessel_0': closest,
                                                                      '/vessel_1': None}}}}
    text = render('encounters', 'closest', {'runs': {'s': run}})
    assert text.count('| 991.7 | 265.7 | port (254.5 deg from the bow) |') == 2
    assert '| s | vessel_0 | t1 (light) |' in text
    text = render('encounters', 'alterations', {'runs': {'s': run}})
    assert '| s | vessel_0 | 0.0 | +45 | +89.8 | no | 10 / 20 | 500 | 24 |' in text


def test_benchmark_goals_show_value_target_verdict_and_load_per_section():
    from results_pages.studies import render
    data = {'args': {'quick': True}, 'machine': {'cpu_model': 'cpu'}, 'sections': {
        'colav': {'load_1min_start': 12.34,
                  'goals': [{'text': 'decision', 'value': 18.591, 'target': 10, 'unit': 'ms',
                             'relation': '<', 'met': False}]},
        'waves': {'goals': [{'text': 'ratio', 'value': 0.97834, 'target': 1.25, 'unit': '',
                             'relation': '<', 'met': True}]},
        'batched': {'load_1min_start': 30.0,
                    'goals': [{'text': 'rate', 'value': 194512.7, 'target': 1e6,
                               'unit': 'steps/s', 'relation': '>=', 'met': False}]},
        'sweep': {'error': 'RuntimeError: no ray', 'goals': [], 'load_1min_start': 3.0}}}
    text = render('bench', 'goals', data)
    assert '| colav | 12.3 | decision | 18.59 ms | < 10 ms | **no** |' in text
    # a run from before sections recorded their load
    assert '| waves | n/a | ratio | 0.9783 | < 1.25 | yes |' in text
    assert '| batched | 30.0 | rate | 194,513 steps/s | >= 1,000,000 steps/s | **no** |' in text
    assert '| sweep | 3.0 | section failed: RuntimeError: no ray |' in text and '`--quick`' in text


def test_a_benchmark_section_table_keeps_its_columns_and_says_its_load():
    from results_pages.studies import render
    section = {'title': 'loop rates', 'load_1min_start': 7.0, 'notes': ['batched 14.7x'],
               'columns': [['loop', 'loop'], ['n', 'N'], ['rate', 'steps/s'], ['ratio', 'ratio']],
               'rows': [{'loop': 'one', 'n': 1, 'rate': 24512.6, 'ratio': 0.012345},
                        {'loop': 'batch', 'n': 10000, 'rate': 1.5e6}]}
    text = render('bench', 'batch_closed_loop', {'args': {}, 'sections': {'batch_closed_loop': section}})
    assert text.startswith('Loop rates; 1-minute load 7.0 when the section started:')
    assert '| loop | N | steps/s | ratio |' in text
    assert '| one | 1 | 24,513 | 0.0123 |' in text and '| batch | 10,000 | 1,500,000 | n/a |' in text
    assert text.endswith("The section's notes:\n\n- batched 14.7x\n")
    with pytest.raises(KeyError, match='it has: batch_closed_loop'):
        render('bench', 'sweep', {'args': {}, 'sections': {'batch_closed_loop': section}})


def test_a_sweep_summary_lays_out_the_cells_sweep_py_formatted():
    from results_pages.studies import render
    data = {'sweep': 's.yaml', 'seed': 3, 'episodes_per_cell': 2, 'group_by': ['controller'],
            'run': {'episodes': 4, 'wall_s': 61.7, 'workers': 2},
            'table': {'header': ['controller', 'n', 'rms_e_m'], 'caption': 'Mean [CI].',
                      'rows': [['los', '2', '1.0 [0.5, 1.5]'], ['ilos', '2', '2.0']]}}
    lines = render('sweeps', 'summary', data).splitlines()
    assert lines[0] == ('`s.yaml`, seed 3: 2 episodes per grid cell, 4 in all, in 62 s on 2 '
                        'workers. Mean [CI].')
    assert lines[2:] == ['| controller | n | rms_<wbr>e_<wbr>m |', '|---|---:|---:|',
                         '| los | 2 | 1.0 [0.5, 1.5] |', '| ilos | 2 | 2.0 |']
