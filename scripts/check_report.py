#!/usr/bin/env python3
"""Open an HTML report in headless Chromium and check it as a reader would see it.

    scripts/check_report.py runs/latest/report.html [--screenshot shot.png] [--full-page] [--json]

Fails (exit 1, one line per problem) on console errors, uncaught exceptions, images that did not
decode or requests that left the file (ship_mission.browser_check); exit 2 when no Chromium is
installed (Debian: apt-get install chromium). Prints the images' sizes, or the result as JSON.
"""
import argparse
import json
import sys

from ship_mission.browser_check import check_page, find_chromium, problems


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('html', help='the HTML file')
    ap.add_argument('--screenshot', default=None, help='write a PNG screenshot here')
    ap.add_argument('--full-page', action='store_true', help='screenshot the whole page, not the window')
    ap.add_argument('--width', type=int, default=1280, help='window width, px (default 1280)')
    ap.add_argument('--height', type=int, default=1000, help='window height, px (default 1000)')
    ap.add_argument('--chromium', default=None, help='browser executable (default: chromium on PATH)')
    ap.add_argument('--timeout', type=float, default=30.0, help='seconds per browser step (default 30)')
    ap.add_argument('--json', action='store_true', help='print the whole result as JSON')
    a = ap.parse_args(argv)
    if (a.chromium or find_chromium()) is None:
        print('check_report: no Chromium on PATH (Debian: apt-get install chromium)', file=sys.stderr)
        return 2
    from playwright.sync_api import Error as BrowserError
    try:
        result = check_page(a.html, a.screenshot, a.chromium, a.timeout, a.width, a.height, a.full_page)
    except BrowserError as exc:
        print(f'check_report: the browser failed: {str(exc).splitlines()[0]}', file=sys.stderr)
        return 1
    bad = problems(result)
    if a.json:
        print(json.dumps(dict(result, problems=bad), indent=2))
    else:
        print(f"{result['title']}: {len(result['images'])} images "
              + ', '.join(f"{i['alt']} {i['natural_width']}x{i['natural_height']}" for i in result['images']))
        for line in bad:
            print(line)
        if result['screenshot']:
            print(f"screenshot: {result['screenshot']}")
    return 1 if bad else 0


if __name__ == '__main__':
    sys.exit(main())
