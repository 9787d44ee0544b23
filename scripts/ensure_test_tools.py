#!/usr/bin/env python3
"""The system programs some tests need (`make test` runs this before pytest).

Each tool below is a Debian package that a test drives as an outside check and skips without:
Chromium for the report's browser test (Playwright drives the system's browser, it downloads
none), gpsd's ``gpsdecode`` as the AIVDM stream's independent decoder. For each one missing:
as root with apt-get, install its package; otherwise, or if that fails, print which test will
be skipped and the command that installs it. Always exits 0: a missing tool skips its tests,
it does not fail the suite.
"""
import os
import shutil
import subprocess
import sys

from ship_mission.browser_check import find_chromium

#: (what, how to find it, Debian package, the test that skips without it)
TOOLS = (
    ('Chromium', find_chromium, 'chromium', 'tests/integration/test_report_browser.py'),
    ('gpsdecode', lambda: shutil.which('gpsdecode'), 'gpsd-clients', 'tests/unit/test_aivdm_out.py'),
)


def _apt_install(package):
    env = dict(os.environ, DEBIAN_FRONTEND='noninteractive')
    return all(subprocess.run(cmd, env=env, stdout=subprocess.DEVNULL).returncode == 0
               for cmd in (['apt-get', 'update', '-qq'],
                           ['apt-get', 'install', '-y', '-qq', package]))


def ensure(what, find, package, skipped):
    if find():
        return True
    if os.geteuid() == 0 and shutil.which('apt-get'):
        print(f"ensure_test_tools: no {what} on PATH; installing Debian's {package} for {skipped}",
              flush=True)
        if _apt_install(package) and find():
            return True
        print(f'ensure_test_tools: apt-get could not install {package}')
    print(f'ensure_test_tools: no {what} on PATH: {skipped} will be skipped (in part); '
          f'install it with: sudo apt-get install {package}')
    return False


def main():
    for tool in TOOLS:
        ensure(*tool)
    return 0


if __name__ == '__main__':
    sys.exit(main())
