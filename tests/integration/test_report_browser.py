"""report.html in a real browser: a short lockstep run through scripts/run_mission.py, then
scripts/check_report.py opens its report in headless Chromium (Debian's ``chromium``, driven by
Playwright) and the page must load with no console error, no request leaving the file, and every
<img> decoded at the size of the PNG it embeds; every contents link must reach its section, each
metric row must show its unit (angles in degrees) and description, and at a phone's 390 px the
page must not be wider than the window; screenshots are saved in the test's tmp dir. The same
for an Imazu benchmark's index page (two short runs in process). A page with a broken image, a
console error, an external image, a dangling in-page link and a too-wide table must fail the same
check.

The browser runs in scripts/check_report.py's own process group, bounded in time and killed
with everything it started even when the check fails. Skipped (one line) only where no Chromium
is installed: `apt-get install chromium` (.ci/run does it).
"""
import json
import os
import shutil
import signal
import struct
import subprocess
import sys
import tempfile

import pytest

from harness import REPO_ROOT, _die_with_parent
from ship_mission.browser_check import find_chromium
from test_launcher import SCENARIO, run_processes

CHECK = REPO_ROOT / 'scripts' / 'check_report.py'
BROWSER_TIMEOUT_S = 90.0

pytestmark = pytest.mark.skipif(find_chromium() is None,
                                reason='no Chromium on PATH: apt-get install chromium (.ci/run installs it)')


def check_report(html, *args):
    """(exit code, JSON result) of check_report.py on ``html``, its browser profile in a fresh
    temporary folder (short: Chromium's socket path there must fit in 108 bytes); the process
    group, and any process naming that folder, killed on the way out whatever happened."""
    tmp = tempfile.mkdtemp(prefix='shipnav-browser-')
    env = dict(os.environ, TMPDIR=tmp)
    proc = subprocess.Popen([sys.executable, str(CHECK), str(html), '--json', *map(str, args)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env, text=True,
                            start_new_session=True, preexec_fn=_die_with_parent)
    try:
        out, err = proc.communicate(timeout=BROWSER_TIMEOUT_S)
    finally:
        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        proc.wait()
        for pid, _argv in run_processes(tmp):   # a browser that left its group
            os.kill(pid, signal.SIGKILL)
        left = run_processes(tmp)
        shutil.rmtree(tmp, ignore_errors=True)
    assert left == [], f'browser processes outlived the check: {left}'
    assert out.strip(), f'check_report.py exit {proc.returncode}, no output; stderr:\n{err[-3000:]}'
    return proc.returncode, json.loads(out)


def png_size(path):
    """(width, height) from a PNG's IHDR chunk."""
    head = path.read_bytes()[:24]
    assert head[:8] == b'\x89PNG\r\n\x1a\n', path
    return struct.unpack('>II', head[16:24])


@pytest.mark.timeout(200)
def test_run_report_loads_in_chromium_with_every_plot_decoded(launch, tmp_path):
    run = launch(SCENARIO, '--duration', 20, '--wall-timeout', 60)
    assert run.wait(75.0) == 0, run.report()
    run_dir = run.run_dir()
    report = run_dir / 'report.html'
    assert report.is_file(), sorted(p.name for p in run_dir.iterdir())
    assert f'report (opens in any browser, offline): {report}' in run.stdout()
    shot = tmp_path / 'report.png'
    code, result = check_report(report, '--screenshot', shot)
    print(json.dumps({k: v for k, v in result.items() if k != 'console'}, indent=1))
    assert result['problems'] == [] and code == 0, result
    assert result['console'] == [] and result['requests'] == []
    pngs = sorted(run_dir.glob('*.png'))
    assert len(pngs) >= 4    # track, cross-track error, heading, rudder
    images = {i['alt']: (i['natural_width'], i['natural_height']) for i in result['images']}
    assert images == {p.name: png_size(p) for p in pngs}
    assert result['title'] == 'Run report: test_auv_closed_loop'   # the scenario's name, as its run folder
    assert png_size(shot) == (1280, 1000)
    # the contents list: one link per section, each reaching its heading
    assert len(result['anchors']) >= 4 and all(a['found'] for a in result['anchors'])
    # each metric row as a reader sees it: name, the unit shown (degrees for angles), the
    # value converted, the description, the metrics.json key
    from ship_mission.metric_info import VESSEL, plain_name, shown
    from ship_mission.html_report import fmt
    metrics = json.loads((run_dir / 'metrics.json').read_text())
    lines = set(result['text'].splitlines())
    for ns, m in metrics['vessels'].items():
        for key, value in m.items():
            unit, text = VESSEL[key]
            v, u = shown(value, unit)
            assert f'{plain_name(key, unit)}\t{u}\t{fmt(v)}\t{text}\t{key}' in lines, key
    assert any(line.startswith('rudder_max_abs\tdeg\t') for line in lines)
    # a phone: nothing wider than the window, every image still decoded
    phone = tmp_path / 'report-390.png'
    code, narrow = check_report(report, '--width', 390, '--height', 844, '--screenshot', phone)
    assert narrow['problems'] == [] and code == 0 and narrow['overflow_px'] == 0, narrow['problems']
    assert all(i['natural_width'] > 0 for i in narrow['images'])
    assert png_size(phone) == (390, 844)


@pytest.mark.timeout(200)
def test_imazu_index_embeds_its_plots_and_reads_on_a_phone(tmp_path):
    """Two short Imazu runs (one case, one method, and the no-traffic reference), in process: the
    index page shows summary.png and the case plot inline, each row's link reaches its plot."""
    out = tmp_path / 'imazu'
    proc = subprocess.Popen([sys.executable, str(REPO_ROOT / 'scripts' / 'imazu_benchmark.py'),
                             '--cases', '1', '--ships', 'mariner', '--methods', 'sbmpc', '--limit',
                             '600', '--jobs', '1', '--out', str(out)], stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, start_new_session=True,
                            preexec_fn=_die_with_parent)
    try:
        log, _ = proc.communicate(timeout=120)
    finally:
        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        proc.wait()
    assert proc.returncode == 0, log[-3000:]
    index = next(out.glob('imazu-2*/index.html'))
    pngs = sorted(index.parent.glob('*.png'))
    assert {p.name for p in pngs} == {'summary.png', 'case_01.png'}
    for width in (1280, 390):
        code, result = check_report(index, '--width', width, '--screenshot', tmp_path / f'imazu-{width}.png')
        assert result['problems'] == [] and code == 0, result['problems']
        assert result['overflow_px'] == 0
        images = {i['alt']: (i['natural_width'], i['natural_height']) for i in result['images']}
        assert images == {p.name: png_size(p) for p in pngs}
        assert result['anchors'] and all(a['found'] for a in result['anchors'])
        assert {a['href'] for a in result['anchors']} == {'#fig-case_01'}


@pytest.mark.timeout(120)
def test_the_check_fails_a_page_with_a_broken_image_a_console_error_and_a_remote_image(tmp_path):
    bad = tmp_path / 'bad.html'
    bad.write_text('<!DOCTYPE html><html><head><title>bad</title></head><body>'
                   '<img alt="truncated" src="data:image/png;base64,iVBORw0KGgoAAAANSUhEUg==">'
                   '<img alt="remote" src="http://192.0.2.1/plot.png">'
                   '<a href="#nowhere">contents</a><h2 id="here">here</h2><a href="#here">ok</a>'
                   '<table style="width:2000px"><tr><td>wide</td></tr></table>'
                   '<script>console.error("boom")</script></body></html>')
    code, result = check_report(bad, '--width', 390)
    assert code == 1
    assert 'link to a missing anchor: #nowhere' in result['problems']
    assert not any('#here' in p for p in result['problems'])
    assert any(p.startswith('page ') and 'wider than the 390 px window' in p for p in result['problems'])
    assert 'console error: boom' in result['problems']
    assert 'image not decoded: truncated' in result['problems']
    assert 'image not decoded: remote' in result['problems']
    assert result['requests'] == ['http://192.0.2.1/plot.png']
