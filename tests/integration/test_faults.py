"""Faults leave a usable record.

1. SIGKILL of the launcher mid-run: every child gets its parent-death signal (SIGTERM), so no
   node or recorder outlives it, and the recorder finalises the bag on that SIGTERM.
2. SIGKILL of the recorder mid-run (realtime): the launcher fails the run (exit 1) and still analyses
   what was recorded: the bag (MCAP without summary nor metadata.yaml) is recovered from its
   flushed chunks, metrics.json covers the steps that reached the disk, and the record is
   reported INCOMPLETE (its end is lost), never complete.
3. Ctrl-C: the interrupted run gets its metrics and plots of what was recorded.
4. A run on a full disk (2 MB tmpfs) fails with exit code 1 and no traceback, and what the
   launcher wrote (parameter files, the scenario copy, run.json if any) is whole.
"""
import json
import os
import signal
import subprocess
import sys
import time

import pytest
import yaml

from ship_mission.bag import read_bag

from harness import REPO_ROOT
from test_launcher import NS, SCENARIO, run_processes, wait_flushed


def wait_gone(marker, timeout):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        left = run_processes(marker)
        if not left:
            return []
        time.sleep(0.2)
    return run_processes(marker)


def started(run, log='vessel_0.vessel_node', text='publishing step 0'):
    assert run.wait_for_log(log, text, timeout=40.0), run.report()
    time.sleep(1.0)   # some steps into the run


@pytest.mark.timeout(120)
def test_killing_the_launcher_leaves_no_orphans_and_a_readable_bag(launch):
    run = launch(SCENARIO, '--duration', 10000, '--wall-timeout', 90)
    started(run)
    assert len(run_processes(str(run.runs))) == 6   # the launcher, 4 nodes, the recorder
    os.kill(run.popen.pid, signal.SIGKILL)
    assert run.wait(10.0) == -signal.SIGKILL
    assert wait_gone(str(run.runs), 15.0) == [], 'children outlived the launcher'
    data = read_bag(run.run_dir() / 'bag')   # finalised on SIGTERM, or recovered
    assert len(data.vessels[NS].t) > 10


@pytest.mark.timeout(120)
def test_a_killed_recorder_fails_the_run_and_its_bag_is_recovered(launch):
    # realtime x1: the route takes minutes, so the run is still going when the recorder dies
    run = launch(SCENARIO, '--duration', 10000, '--wall-timeout', 90, '--stepping', 'realtime')
    started(run, 'recorder', f'recording {NS}/odom')
    assert wait_flushed(run.run_dir() / 'bag', 20.0), 'the recorder flushed no odometry'
    rec = [pid for pid, argv in run_processes(str(run.runs)) if any('recorder.py' in a for a in argv)]
    assert len(rec) == 1
    os.kill(rec[0], signal.SIGKILL)
    assert run.wait(60.0) == 1, run.report()
    out = run.stdout() + run.stderr()
    assert 'recorder exited' in out and 'recovered an interrupted recording' in out, run.report()
    metrics = json.loads((run.run_dir() / 'metrics.json').read_text())
    assert metrics['run']['outcome'] == 'failed'
    assert metrics['vessels'][NS]['odom_samples'] > 10
    # the end of the recording is lost: never reported as a complete record
    assert not metrics['record']['complete'] and 'recovered' in metrics['record']
    assert 'record INCOMPLETE: recovered from an interrupted recording' in out, run.report()
    assert run_processes(str(run.runs)) == []


@pytest.mark.timeout(120)
def test_an_interrupted_run_gets_metrics_of_what_was_recorded(launch):
    run = launch(SCENARIO, '--duration', 10000, '--wall-timeout', 90)
    started(run)
    run.popen.send_signal(signal.SIGINT)
    assert run.wait(30.0) == 130, run.report()
    assert 'metrics and plots of what was recorded written' in run.stdout() + run.stderr()
    metrics = json.loads((run.run_dir() / 'metrics.json').read_text())
    assert metrics['run']['outcome'] == 'interrupted'
    assert metrics['record']['complete'], metrics['record']
    assert any(p.suffix == '.png' for p in run.run_dir().iterdir())


@pytest.mark.timeout(240)
def test_a_run_on_a_full_disk_ends_without_a_traceback_leaving_readable_files(tmp_path):
    """run_mission on a 2 MB tmpfs: the run fails (exit 1) without a traceback, and what the
    launcher wrote (parameters, scenario copy, run.json if any) is whole."""
    disk = tmp_path / 'disk'
    disk.mkdir()
    r = subprocess.run(['mount', '-t', 'tmpfs', '-o', 'size=2m', 'tmpfs', str(disk)],
                       capture_output=True, text=True)
    if r.returncode != 0:
        pytest.skip(f'cannot mount a tmpfs here: {r.stderr.strip()}')
    try:
        out = subprocess.run([sys.executable, str(REPO_ROOT / 'scripts' / 'run_mission.py'),
                              str(REPO_ROOT / 'scenarios' / 'flagship_mariner.yaml'), '--runs',
                              str(disk), '--duration', '600', '--wall-timeout', '150'],
                             capture_output=True, text=True, timeout=200,
                             stdin=subprocess.DEVNULL)
        assert out.returncode == 1, out.stderr
        assert 'Traceback' not in out.stderr + out.stdout, out.stderr
        assert out.stderr.startswith('run_mission: FAILED:'), out.stderr
        run = (disk / 'latest').resolve()
        for f in (run / 'params').iterdir():
            assert yaml.safe_load(f.read_text())['/**']['ros__parameters'], f
        assert (run / 'scenario.yaml').read_bytes() == \
            (REPO_ROOT / 'scenarios' / 'flagship_mariner.yaml').read_bytes()
        if (run / 'run.json').exists():
            assert yaml.safe_load((run / 'run.json').read_text())['outcome']
        else:
            # the run's failure (stderr) when nothing else failed first, else a progress line
            # beside the failure that came first (with zstd bags the 2 MB fill later than they did)
            assert f'cannot write {run / "run.json"}' in out.stdout + out.stderr
        assert not (run / '.run.json.tmp').exists()
    finally:
        subprocess.run(['umount', '-l', str(disk)], capture_output=True)
