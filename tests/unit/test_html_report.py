"""HTML reports (ship_mission.html_report): self-contained (every image a data URI that decodes to the
plot's own bytes, nothing fetched from anywhere), everything shown escaped, the node logs'
warnings and errors picked out, batch links relative so a copied batch folder keeps working."""
import base64
import math
import html
import re

import pytest

from ship_mission import html_report

PNG_1x1 = base64.b64decode('iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR42mNk+M9QDwADhgGA'
                           'WjR9awAAAABJRU5ErkJggg==')  # a 1 x 1 PNG


def _strip_tags(text):
    return html.unescape(re.sub(r'<[^>]+>', '', text))


def test_log_issues_picks_warnings_errors_and_tracebacks_only(tmp_path):
    (tmp_path / 'a.log').write_text(
        '[INFO] [1.0] [vessel_0.guidance_node]: route received\n'
        '[WARN] [2.0] [vessel_0.guidance_node]: odom stale for 1.2 s\n'
        '/x/y.py:3: RuntimeWarning: invalid value encountered\n'
        'Traceback (most recent call last):\n'
        '  File "z.py", line 1\n'
        'ValueError: bad\n'
        '[ERROR] [3.0] [vessel_0.autopilot_node]: no heading\n')
    (tmp_path / 'b.log').write_text('[INFO] [1.0] [recorder]: 3 topics\n')
    (tmp_path / 'notes.txt').write_text('[ERROR] not a log\n')
    got = html_report.log_issues(tmp_path)
    assert list(got) == ['a.log']
    assert got['a.log'] == ['[WARN] [2.0] [vessel_0.guidance_node]: odom stale for 1.2 s',
                            '/x/y.py:3: RuntimeWarning: invalid value encountered',
                            'Traceback (most recent call last):', 'ValueError: bad',
                            '[ERROR] [3.0] [vessel_0.autopilot_node]: no heading']


@pytest.mark.parametrize('text', [
    'name: a\n# comment <b>\nvessels:\n  vessel_0:\n    route: r#1.yaml  # the <route> & more\n',
    '- x: "1 # 2"\n- y: [1, 2]\nsource: "A & B <2008>"\n'])
def test_yaml_block_shows_the_text_unchanged(text):
    block = html_report.yaml_block(text)
    assert _strip_tags(block) == text.rstrip('\n')
    assert '<b>' not in block and '<route>' not in block


@pytest.fixture
def run_folder(tmp_path):
    run = tmp_path / 'run'
    (run / 'logs').mkdir(parents=True)
    (run / 'logs' / 'vessel_0.guidance_node.log').write_text(
        '[INFO] [0.1] [g]: ok\n' + ''.join(f'[WARN] [{i}.0] [g]: <late> odom {i}\n' for i in range(45)))
    (run / 'logs' / 'recorder.log').write_text('[INFO] [0.1] [recorder]: recording\n')
    (run / 'scenario.yaml').write_text('name: demo <x>\nduration_s: 10.0  # short\n')
    (run / 'run.json').write_text('scenario: scenarios/demo.yaml\noutcome: completed\nsim_time_s: 10.0\n')
    pngs = {'track.png': PNG_1x1, 'rudder.png': PNG_1x1 + b'\x00'}   # distinct bytes per file
    for name, data in pngs.items():
        (run / name).write_bytes(data)
    metrics = {'bag': str(run / 'bag'), 'plots': ['track.png', 'rudder.png'],
               'vessels': {'/vessel_0': {'xte_rms_m': 12.3456789, 'finished': True,
                                         'note': '<script>alert(1)</script>', 'missing_topics': []}},
               'record': {'complete': False, 'missing': 2, 'vessels': {'/vessel_0': {
                   'odom': {'expected': 101, 'received': 99, 'missing': 2, 'gaps': [[1.0, 1.2]]},
                   'missing': 2}}},
               'topics': {'/vessel_0/odom': {'type': 'nav_msgs/msg/Odometry', 'count': 99}}}
    return run, metrics, pngs


def test_run_report_is_self_contained_and_escaped(run_folder):
    run, metrics, pngs = run_folder
    path = html_report.write_run_report(run, metrics, command='run_mission.py demo.yaml')
    text = path.read_text()
    assert path == run / 'report.html'
    # nothing to fetch: no scripts, no stylesheets or fonts by URL, every src is a data URI
    assert '<script' not in text.lower() and '<link' not in text.lower() and 'url(' not in text
    srcs = re.findall(r'src="([^"]*)"', text)
    assert len(srcs) == len(pngs)
    assert all(s.startswith('data:image/png;base64,') for s in srcs)
    decoded = [base64.b64decode(s.split(',', 1)[1]) for s in srcs]
    assert decoded == [pngs['track.png'], pngs['rudder.png']]   # the analysis's order
    assert not re.search(r'href="(https?:|//)', text)
    plain = _strip_tags(text)
    assert '<script>alert(1)</script>' in plain               # shown as text, not run
    assert '12.35' in plain and 'demo <x>' in plain and 'run_mission.py demo.yaml' in plain
    assert 'record INCOMPLETE: 2 messages missing' in plain
    assert 'completed' in plain and 'Run report: demo' in plain
    # the warnings: the first MAX_LOG_LINES shown, the rest counted; the clean log not listed
    n = html_report.MAX_LOG_LINES
    assert f'[WARN] [{n - 1}.0] [g]: <late> odom {n - 1}' in plain
    assert f'[WARN] [{n}.0] [g]' not in plain
    assert f'... and {45 - n} more' in plain
    assert '(1 of 2 logs)' in plain and 'recorder.log' not in plain


def test_batch_page_links_are_relative_and_survive_a_move(tmp_path):
    batch = tmp_path / 'batch'
    reports = []
    for name in ('case_a', 'case_b'):
        (batch / name).mkdir(parents=True)
        reports.append(batch / name / 'report.html')
        reports[-1].write_text('<html></html>')
    page = html_report.batch_page(batch / 'index.html', 'Batch <1>', ['case', 'xte m', 'ok'],
                                  [['case_a', 1.23456, True], ['case_<b>', None, False]],
                                  links=[reports[0], None], intro='two & cases',
                                  sections=[('Claims', ['claim', 'reproduced'], [['x < y', 'yes']])])
    moved = tmp_path / 'elsewhere'
    batch.rename(moved)
    text = (moved / 'index.html').read_text()
    hrefs = re.findall(r'href="([^"]*)"', text)
    assert hrefs == ['case_a/report.html']
    assert (moved / hrefs[0]).is_file()
    plain = _strip_tags(text)
    assert 'case_<b>' in plain and 'x < y' in plain and 'two & cases' in plain
    assert '1.235' in plain and 'yes' in plain and 'no' in plain
    assert page.name == 'index.html'


def test_fmt_shows_numbers_to_four_significant_digits():
    assert [html_report.fmt(v) for v in (1234567.0, 0.000123456, 3, None, True, [1, 2])] == \
        ['1.235e+06', '0.0001235', '3', '-', 'yes', '[1, 2]']


def _cells(text, heading):
    """The rows (lists of cell texts) of the first table after <h2>heading</h2> (or the first
    table of the page with heading None)."""
    start = (re.search(f'<h2[^>]*>{re.escape(heading)}</h2>', text).start() if heading
             else text.index('<table><tr>'))
    tbl = text[start:text.index('</table>', start)]
    return [[_strip_tags(c) for c in re.findall(r'<t[dh][^>]*>(.*?)</t[dh]>', row)]
            for row in re.findall(r'<tr>(.*?)</tr>', tbl, re.S)]


def test_seed_batch_page_links_each_run_and_lists_the_claims(tmp_path):
    import run_seed_scenarios as rs
    done = tmp_path / 'course_change_30_000-1'
    done.mkdir()
    (done / 'report.html').write_text('<html></html>')
    spec = {'model': 'mariner', 'law': 'ilos', 'controller': 'pd', 'current_mps': 0.0}
    results = [{'scenario': 'course_change_30_000', 'spec': spec, 'outcome': 'completed',
                'run_dir': str(done), 'metrics': {'step_rad': 0.5235987755982988}},
               {'scenario': 'quarter_circle_chord_003', 'spec': spec, 'outcome': 'failed',
                'error': 'vessel_0/guidance_node exited with 1', 'run_dir': str(tmp_path / 'gone')}]
    claims = [('claim <a>', True, 'because'), ('claim b', False, 'not so')]
    page = rs.html_index(tmp_path, results, claims, '## Seed scenarios: 2 runs')
    text = page.read_text()
    assert re.findall(r'href="([^"]*)"', text) == ['course_change_30_000-1/report.html'] * 2
    assert _cells(text, None)[1:] == [['course_change_30_000', 'completed', ''],
                                      ['quarter_circle_chord_003', 'failed',
                                       'vessel_0/guidance_node exited with 1']]
    assert _cells(text, 'Seed claims')[1:] == [['claim <a>', 'yes', 'because'], ['claim b', 'NO', 'not so']]
    course = next(h for p, h in rs.GROUPS if 'course_change_30_000'.startswith(p))
    rows = _cells(text, html.escape(course))
    assert rows[0][:6] == [h for h, _ in rs.COURSE_CHANGE_COLUMNS][:6]
    assert rows[1][4] == '30.0'   # the step, in degrees


def test_table_one_page_puts_the_paper_and_our_rewards_in_the_same_columns(tmp_path):
    import evaluate_controllers as ec
    results = {f'mariner/{c}/los': {'gaussian': 1000.0 + c, 'mean_abs_e': 5.0, 'max_abs_e': 9.0,
                                    'mean_abs_e_settled': 4.0, 'rudder_rate_deg_s': 0.5,
                                    'mean_abs_rudder_deg': 2.0} for c in ec.CURRENTS}
    results['mariner/0.0/policy'] = {'error': 'no policy file'}
    text = ec.html_page(tmp_path / 't1.html', results, ['mariner'], ['los', 'policy'], 1000.0, 5).read_text()
    rows = _cells(text, None)
    assert rows[0] == ['controller', 'mariner 0 m/s', 'mariner 0.9 m/s']
    paper = ec.SEED_TABLE['LOS (Martinsen and Lekkas 2018)']['mariner']
    assert rows[1] == ['LOS (Martinsen and Lekkas 2018)', str(paper[0]), str(paper[1])]
    assert rows[3] == [ec.LABELS['los'], '1000', '1001']
    assert rows[4] == [ec.LABELS['policy'], '-', '-']
    every = _cells(text, 'Every case (means over the start states)')
    assert every[2][:3] == ['mariner', '0', ec.LABELS['policy']] and every[2][-1] == 'no policy file'
    assert every[1][3:] == ['1000', '5', '9', '4', '0.5', '2', '']


def test_imazu_index_embeds_the_summary_and_every_case_plot_and_links_rows_to_them(tmp_path):
    import imazu_benchmark as ib
    pngs = {'summary.png': PNG_1x1, 'case_01.png': PNG_1x1 + b'\x01', 'case_05.png': PNG_1x1 + b'\x05'}
    for name, data in pngs.items():
        (tmp_path / name).write_bytes(data)
    run = {'targets': {'t1': {'penalties': []}}, 'min_distance_m': 900.0, 'collisions': 0,
           'near_misses': 0, 'below_safe': 0, 'rule_score': 1.0, 'path_deviation_m': 50.0,
           'time_lost_s': 10.0, 'return_to_route_s': None, 'run_end': 'limit'}
    per_run = {(c, 'mariner', m): run for c in (1, 5) for m in ('sbmpc', 'vo')}
    group = {'runs': 2, 'collisions': 0, 'near_misses': 0, 'below_safe': 0, 'min_distance_m': 900.0,
             'rule_score_mean': 1.0, 'rule_score_single_target_mean': 1.0,
             'path_deviation_m_mean': 50.0, 'time_lost_s_mean': 10.0,
             'return_to_route_s_mean': None, 'never_back_on_route': 2, 'limit_hit': 2}
    summary = {'groups': {'mariner/sbmpc': group, 'mariner/vo': group}, 'limit_s': 4000.0,
               'decision_ms_mean': 1.0, 'load_average_1min': 1.0, 'cpus': 2}
    cases = {c: {'targets': [{'colregs': 'head-on'}]} for c in (1, 5)}
    text = ib.html_page(tmp_path / 'index.html', per_run, summary, cases).read_text()
    figures = dict(re.findall(r'<figure id="([^"]+)"><img src="data:image/png;base64,([^"]+)"', text))
    assert {k: base64.b64decode(v) for k, v in figures.items()} == \
        {html_report.figure_id(n): d for n, d in pngs.items()}
    assert list(figures)[0] == html_report.figure_id('summary.png')   # the overview first
    hrefs = re.findall(r'href="([^"]*)"', text)
    assert len(hrefs) == len(per_run)
    assert all(h.startswith('#') and h[1:] in figures for h in hrefs)   # each row to its case plot
    assert sorted(set(hrefs)) == ['#' + html_report.figure_id(f'case_{c:02d}.png') for c in (1, 5)]


def test_run_report_gives_every_metric_a_unit_and_description_and_shows_angles_in_degrees(run_folder):
    from ship_mission import metric_info
    run, metrics, _ = run_folder
    metrics['vessels']['/vessel_0'] = {'xte_rms_m': 12.5, 'rudder_max_abs_rad': 0.5,
                                       'rudder_total_variation_rad_per_s': 0.01, 'finished': True}
    text = html_report.write_run_report(run, metrics).read_text()
    rows = {r[-1]: r for r in _cells(text, 'Vessels')[1:]}   # by metrics.json key
    assert rows['xte_rms_m'][:3] == ['xte_rms', 'm', '12.5']
    assert rows['rudder_max_abs_rad'][:3] == ['rudder_max_abs', 'deg', f'{math.degrees(0.5):.4g}']
    assert rows['rudder_total_variation_rad_per_s'][1:3] == ['deg/s', f'{math.degrees(0.01):.4g}']
    for key, row in rows.items():
        assert row[-2] == metric_info.VESSEL[key][1]
    # the contents list links every section heading, and only those
    ids = re.findall(r'<h2 id="([^"]+)">', text)
    toc = text[text.index('<nav class="toc">'):text.index('</nav>')]
    assert re.findall(r'href="#([^"]+)"', toc) == ids and 'vessels' in ids and 'plots' in ids
