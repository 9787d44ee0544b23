"""HTML reports (mission.html_report): self-contained (every image a data URI that decodes to the
plot's own bytes, nothing fetched from anywhere), everything shown escaped, the node logs'
warnings and errors picked out, batch links relative so a copied batch folder keeps working."""
import base64
import html
import re

import pytest

from mission import html_report

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
