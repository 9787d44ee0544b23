"""The requirements split (issue 27 item 5): `make demo` installs requirements/runtime.txt only.

- Every module of the demo's path (the five packages' nodes and science modules, ship_mission
  among them, and run_mission.py) imports in a fresh interpreter in which every package that only the extras
  install (test, learning, sweep, browser) raises ImportError; the modules that need an extra
  are the few named below, and they are not on the demo's path.
- Pins are exact (==) and each package is pinned in one file; requirements.txt names every
  file of requirements/.
- Without the extras, scripts/sweep.py --ray refuses in one line naming the make target, and
  scripts/ensure_test_tools.py (non-root, no Chromium or gpsdecode on PATH) names the skipped tests and the
  install command; both without a traceback.
"""
import os
import re
import shutil
import subprocess
import sys
import textwrap
from importlib.metadata import packages_distributions
from pathlib import Path

import pytest

from ship_mission.browser_check import find_chromium

REPO = Path(__file__).resolve().parents[2]
REQ = REPO / 'requirements'
EXTRAS = ('test', 'learning', 'sweep', 'browser', 'docs', 'http', 'kernels', 'interop', 'jinja')
#: Modules that need an extra, with the extra: none is imported by the nodes or the launcher.
NEEDS_EXTRA = {'ship_autopilot.learning.env': 'learning',          # gymnasium.Env
               'ship_autopilot.batch_closed_loop': 'learning'}     # builds on learning.env
PIN = re.compile(r'^([A-Za-z0-9_.\-]+)(\[[^\]]*\])?==\S+$')


def norm(name):
    return re.sub(r'[-_.]+', '-', name).lower()


def pins(path):
    """{normalised distribution name: line} of one requirements file's pins (not its -r lines)."""
    out = {}
    for line in path.read_text().splitlines():
        line = line.split('#')[0].strip()
        if not line or line.startswith('-r '):
            continue
        m = PIN.match(line)
        assert m, f'{path.name}: {line!r} is not an exact pin (name==version)'
        out[norm(m.group(1))] = line
    return out


def blocked_modules():
    """Top-level import names whose distributions are all pinned only in the extras."""
    runtime = set(pins(REQ / 'runtime.txt'))
    extra = set().union(*(pins(REQ / f'{e}.txt') for e in EXTRAS)) - runtime
    return sorted(top for top, dists in packages_distributions().items()
                  if {norm(d) for d in dists} <= extra)


def demo_modules():
    mods = []
    for pkg_dir in sorted((REPO / 'ros_ws' / 'src').glob('*/package.xml')):
        root = pkg_dir.parent
        for f in sorted((root / root.name).rglob('*.py')):
            parts = list(f.relative_to(root).with_suffix('').parts)
            mods.append('.'.join(parts[:-1] if parts[-1] == '__init__' else parts))
    return [m for m in mods + ['run_mission'] if m not in NEEDS_EXTRA]


BLOCKER = textwrap.dedent('''
    import importlib.abc, sys
    BLOCKED = set(sys.argv[1].split(','))

    class Blocker(importlib.abc.MetaPathFinder):
        def find_spec(self, name, path=None, target=None):
            if name.split('.')[0] in BLOCKED:
                raise ImportError(f'{name} is not in requirements/runtime.txt')

    sys.meta_path.insert(0, Blocker())
''')


def run_blocked(code, *args, env=None):
    """Run ``code`` in a fresh interpreter with the extras' packages unimportable."""
    blocked = blocked_modules()
    return subprocess.run([sys.executable, '-c', BLOCKER + textwrap.dedent(code),
                           ','.join(blocked), *args], cwd=REPO, capture_output=True, text=True,
                          timeout=120, env=env)


def test_the_extras_are_blocked_when_installed():
    # Guard of the import test below: the blocked set holds the extras' big packages (this venv
    # has them, as make test installs them), and none the runtime pins.
    blocked = set(blocked_modules())
    assert {'ray', 'gymnasium', 'playwright', 'greenlet'} <= blocked
    assert not blocked & {'numpy', 'rclpy', 'yaml', 'rosbags', 'matplotlib', 'pytest'}


def test_the_demo_path_imports_with_the_runtime_requirements_only():
    code = '''
        import importlib, sys
        failed = []
        for m in sys.argv[2].split(','):
            try:
                importlib.import_module(m)
            except ImportError as exc:
                failed.append(f'{m}: {exc}')
        # the named exceptions do need their extra (else the list is stale)
        for m in sys.argv[3].split(','):
            try:
                importlib.import_module(m)
                failed.append(f'{m} imports without its extra: remove it from NEEDS_EXTRA')
            except ImportError:
                pass
        print('\\n'.join(failed))
    '''
    r = run_blocked(code, ','.join(demo_modules()), ','.join(NEEDS_EXTRA))
    assert r.returncode == 0, r.stderr[-2000:]
    assert r.stdout.strip() == '', r.stdout


def test_every_pin_is_exact_and_in_one_file():
    seen = {}
    for f in sorted(REQ.glob('*.txt')):
        for name in pins(f):
            assert name not in seen, f'{name} pinned in {seen.get(name)} and {f.name}'
            seen[name] = f.name
    assert {'ray', 'gymnasium', 'playwright', 'ruff'} <= seen.keys()
    assert seen['numpy'] == 'runtime.txt' and seen['ray'] == 'sweep.txt'
    included = re.findall(r'^-r (\S+)$', (REPO / 'requirements.txt').read_text(), re.M)
    assert sorted(included) == sorted(f'requirements/{f.name}' for f in REQ.glob('*.txt'))


def test_sweep_with_ray_missing_names_the_make_target():
    code = '''
        sys.argv = ['sweep.py', 'scenarios/sweeps/table1.yaml', '--ray', '--out', sys.argv[2]]
        import sweep
        sys.exit(sweep.main(sys.argv[1:]))
    '''
    # scripts/ and the packages' source folders: PYTHONPATH as tests/conftest.py sets it
    r = run_blocked(code, '/nonexistent/sweep-out')
    assert r.returncode == 2, r.stderr[-2000:]
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and 'ray' in lines[0] and 'make venv-sweep' in lines[0], r.stderr
    assert 'Traceback' not in r.stderr


def test_ensure_test_tools_without_them_names_what_is_skipped(tmp_path):
    # Not root and nothing on PATH: nothing is installed, each message names the test that will
    # skip and the install command; exit 0 (a skipped test does not fail the suite).
    code = '''
        import os, runpy, sys
        os.geteuid = lambda: 1000
        sys.argv = ['ensure_test_tools.py']
        runpy.run_path('scripts/ensure_test_tools.py', run_name='__main__')
    '''
    env = dict(os.environ, PATH=str(tmp_path))   # PYTHONPATH: tests/conftest.py's folders
    r = subprocess.run([sys.executable, '-c', textwrap.dedent(code)], cwd=REPO, env=env,
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr[-2000:]
    assert 'tests/integration/test_report_browser.py' in r.stdout
    assert 'apt-get install chromium' in r.stdout
    assert 'tests/unit/test_aivdm_out.py' in r.stdout and 'apt-get install gpsd-clients' in r.stdout
    assert r.stderr == ''


@pytest.mark.skipif(find_chromium() is None or shutil.which('gpsdecode') is None,
                    reason='Chromium or gpsdecode not on PATH')
def test_ensure_test_tools_with_them_says_nothing():
    r = subprocess.run([sys.executable, 'scripts/ensure_test_tools.py'], cwd=REPO,
                       capture_output=True, text=True, timeout=60)
    assert (r.returncode, r.stdout, r.stderr) == (0, '', '')
