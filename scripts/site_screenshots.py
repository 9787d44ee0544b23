#!/usr/bin/env python3
"""Screenshots of the documentation site as a newcomer first sees it: the front page and one
generated results page, taken in headless Chromium from the built site.

    make docs && .venv/bin/python scripts/site_screenshots.py

Serves site/ (what `make docs` builds) on 127.0.0.1 with http.server, so the page loads its
theme's stylesheets and scripts as it does from a web server, and saves each page's first
screen (1280 x 900, scrollbars hidden) as a palette PNG: doc/site_front_page.png and
doc/site_results_page.png. Exit 0 when both were written, 1 when Chromium failed, 2 when the
site is not built or no Chromium is installed.
"""
import argparse
import functools
import http.server
import subprocess
import sys
import tempfile
import threading
from pathlib import Path

from ship_mission.browser_check import CHROMIUM_ARGS, find_chromium

REPO = Path(__file__).resolve().parents[1]
SITE = REPO / 'site'
#: page of the site -> picture in doc/ (the front page, a results page whose tables are generated)
PAGES = {'index.html': 'site_front_page.png', 'results/platoon.html': 'site_results_page.png'}
WIDTH, HEIGHT = 1280, 900
#: a palette of this many colours keeps text and the theme's colours and makes the file a
#: fraction of a full-colour PNG
COLOURS = 64


class QuietHandler(http.server.SimpleHTTPRequestHandler):
    def log_message(self, *args):   # one line per asset would bury the script's own lines
        pass


def serve(folder):
    """An HTTP server of ``folder`` on a free port of 127.0.0.1, in a daemon thread."""
    handler = functools.partial(QuietHandler, directory=str(folder))
    server = http.server.ThreadingHTTPServer(('127.0.0.1', 0), handler)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    return server


def screenshot(chromium, url, out, timeout_s):
    """Chromium's headless screenshot of ``url`` into ``out`` (a fresh profile each time)."""
    with tempfile.TemporaryDirectory(prefix='site-shot-') as profile:
        cmd = [chromium, '--headless', *CHROMIUM_ARGS, f'--user-data-dir={profile}',
               '--hide-scrollbars', f'--window-size={WIDTH},{HEIGHT}',
               '--virtual-time-budget=5000', f'--screenshot={out}', url]
        subprocess.run(cmd, check=True, timeout=timeout_s, capture_output=True)


def shrink(path):
    """Rewrite the PNG with a palette of COLOURS colours, optimised."""
    from PIL import Image
    with Image.open(path) as im:
        small = im.convert('RGB').quantize(COLOURS, method=Image.Quantize.MEDIANCUT)
    small.save(path, optimize=True)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--site', type=Path, default=SITE, help='built site (default site/)')
    ap.add_argument('--out-dir', type=Path, default=REPO / 'doc', help='folder of the PNGs')
    ap.add_argument('--timeout', type=float, default=120.0, help='seconds per page')
    args = ap.parse_args(argv)
    missing = [p for p in PAGES if not (args.site / p).is_file()]
    if missing:
        print(f"error: {args.site} has no {', '.join(missing)}: run `make docs` first",
              file=sys.stderr)
        return 2
    chromium = find_chromium()
    if chromium is None:
        print('error: no Chromium on PATH (Debian: apt-get install chromium)', file=sys.stderr)
        return 2
    server = serve(args.site)
    try:
        for page, name in PAGES.items():
            out = args.out_dir / name
            url = f'http://127.0.0.1:{server.server_port}/{page}'
            try:
                screenshot(chromium, url, out, args.timeout)
            except (subprocess.CalledProcessError, subprocess.TimeoutExpired) as exc:
                print(f'error: Chromium on {url}: {exc}', file=sys.stderr)
                return 1
            shrink(out)
            print(f'{url} -> {out} ({out.stat().st_size // 1024} kB)')
    finally:
        server.shutdown()
    return 0


if __name__ == '__main__':
    sys.exit(main())
