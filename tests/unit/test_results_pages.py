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
