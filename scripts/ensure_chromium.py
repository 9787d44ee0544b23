#!/usr/bin/env python3
"""Chromium for the report's browser test (`make test` and .ci/run run this before pytest).

tests/integration/test_report_browser.py drives the system's Chromium through Playwright (it
downloads no browser) and skips without one. When none is on PATH (mission.browser_check's
names): as root with apt-get, install Debian's ``chromium``; otherwise, or if that fails, print
which test will be skipped and the command that installs it. Always exits 0: a missing browser
skips one test file, it does not fail the suite.
"""
import os
import shutil
import subprocess
import sys

from mission.browser_check import find_chromium

SKIPPED = 'tests/integration/test_report_browser.py'
INSTALL = 'sudo apt-get install chromium'


def main():
    if find_chromium():
        return 0
    if os.geteuid() == 0 and shutil.which('apt-get'):
        print(f'ensure_chromium: no Chromium on PATH; installing Debian\'s chromium for {SKIPPED}',
              flush=True)
        env = dict(os.environ, DEBIAN_FRONTEND='noninteractive')
        ok = all(subprocess.run(cmd, env=env, stdout=subprocess.DEVNULL).returncode == 0
                 for cmd in (['apt-get', 'update', '-qq'],
                             ['apt-get', 'install', '-y', '-qq', 'chromium']))
        if ok and find_chromium():
            return 0
        print('ensure_chromium: apt-get could not install chromium')
    print(f'ensure_chromium: no Chromium on PATH: {SKIPPED} will be skipped; '
          f'install it with: {INSTALL}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
