#!/usr/bin/env python3
"""Open the live view in a real Foxglove Studio and save a screenshot (a developer's tool, not
part of `make test`): `scripts/live_view_screenshot.py [SCENARIO] [--out PNG]`.

The only runnable Foxglove web app on the npm registry is the library build of
``@foxglove/studio-base`` 1.48.0 (MPL-2.0; ``assets/index.js``, a UMD bundle exporting ``App``
and the data sources, React 17 as an external). Lichtblick's and Foxglove's other packages
(``@lichtblick/suite``, ``@foxglove/studio``) are the extension API's TypeScript sources, not
apps. This script fetches studio-base, React and ReactDOM with ``npm pack`` into a cache folder
(``--cache``; nothing is added to the project's dependencies), writes a page that mounts ``App``
with an in-memory layout store holding scripts/live_view_layout.json, serves it on 127.0.0.1,
starts a lockstep run of SCENARIO with ``--live``, and opens the page in headless Chromium
(Playwright with the system's Chromium, as ship_mission.browser_check) connected to the run.

Studio 1.48 predates the protocol's new name: it offers only the subprotocol
``foxglove.websocket.v1``, which foxglove-sdk servers refuse (HTTP 400; the live view's own
front, ship_mission.live_front, now accepts it too). A relay here accepts the old name and forwards
every frame both ways under the new one; it also lets the page connect before the run serves.

Prints the console errors of the page; exit code 0 when the screenshot was saved and the app
received messages from the run, 1 otherwise, 2 when npm or Chromium is missing.
"""
import argparse
import asyncio
import functools
import http.server
import os
import shutil
import signal
import socket
import subprocess
import sys
import tarfile
import threading
import time
from pathlib import Path

from ship_mission.browser_check import CHROMIUM_ARGS, find_chromium
from ship_mission.live_front import OLD_SUBPROTOCOL, SDK_SUBPROTOCOLS

REPO = Path(__file__).resolve().parents[1]
LAYOUT = REPO / 'scripts' / 'live_view_layout.json'
PACKAGES = {'studio-base': '@foxglove/studio-base@1.48.0', 'react': 'react@17.0.2',
            'react-dom': 'react-dom@17.0.2'}
NEW_SUBPROTOCOL = SDK_SUBPROTOCOLS[0]

# The page: React and ReactDOM under the names the UMD bundle asks of `window`, then App with an
# in-memory app configuration and a layout store whose one layout the URL's layoutId selects.
# The localStorage keys are studio-base 1.48's (WorkspaceContextProvider, the user profile).
PAGE = """<!doctype html>
<html><head><meta charset="utf-8"><title>shipnav live view</title>
<style>html, body, #root { height: 100%; margin: 0; }</style></head>
<body><div id="root"></div>
<script>
  // A clean first view: no sidebars, no onboarding tooltips (the app's own persisted state).
  localStorage.setItem("fox.workspace", JSON.stringify({version: 0, state: {
    sidebarItem: null, leftSidebarOpen: false, rightSidebarOpen: false}}));
  localStorage.setItem("studio.profile-data", JSON.stringify({onboarding: {
    settingsTooltipShownForPanelTypes: ["3D", "map", "Plot"]}}));
</script>
<script src="react/umd/react.production.min.js"></script>
<script src="react-dom/umd/react-dom.production.min.js"></script>
<script>window.react = window.React; window["react-dom"] = window.ReactDOM;</script>
<script src="studio-base/assets/index.js"></script>
<script>
(async () => {
  const data = await (await fetch("layout.json")).json();
  const saved = new Date().toISOString();
  const layouts = new Map([["shipnav", {id: "shipnav", name: "shipnav live view",
    permission: "CREATOR_WRITE", baseline: {data, savedAt: saved}, working: undefined,
    syncInfo: undefined}]]);
  const layoutStorage = {
    list: async () => Array.from(layouts.values()),
    get: async (namespace, id) => layouts.get(id),
    put: async (namespace, layout) => { layouts.set(layout.id, layout); return layout; },
    delete: async (namespace, id) => { layouts.delete(id); },
    importLayouts: async () => {},
  };
  const values = new Map(), listeners = new Map();
  const appConfiguration = {
    get: (key) => values.get(key),
    set: async (key, value) => {
      values.set(key, value); (listeners.get(key) || []).forEach((cb) => cb(value)); },
    addChangeListener: (key, cb) => listeners.set(key, [...(listeners.get(key) || []), cb]),
    removeChangeListener: (key, cb) =>
      listeners.set(key, (listeners.get(key) || []).filter((c) => c !== cb)),
  };
  ReactDOM.render(React.createElement(App, {
    deepLinks: [window.location.href], appConfiguration, layoutStorage, extensionLoaders: [],
    dataSources: [new FoxgloveWebSocketDataSourceFactory()],
    enableLaunchPreferenceScreen: false, enableGlobalCss: true,
  }), document.getElementById("root"));
})();
</script></body></html>
"""


def fetch_app(cache):
    """Unpack the npm packages into ``cache``/<name>/ (once); returns ``cache``."""
    cache.mkdir(parents=True, exist_ok=True)
    for name, spec in PACKAGES.items():
        if (cache / name / 'package.json').exists():
            continue
        out = subprocess.run(['npm', 'pack', spec, '--pack-destination', str(cache)], check=True,
                             capture_output=True, text=True).stdout.strip().splitlines()[-1]
        with tarfile.open(cache / out) as tar:
            tar.extractall(cache / f'.{name}', filter='data')
        shutil.rmtree(cache / name, ignore_errors=True)
        (cache / f'.{name}' / 'package').rename(cache / name)
        (cache / out).unlink()
    return cache


def serve_page(cache, layout):
    """Serve the page, the layout and the packages on 127.0.0.1; returns (server, port)."""
    files = {'/': PAGE.encode(), '/index.html': PAGE.encode(), '/layout.json': layout.read_bytes()}

    class Handler(http.server.SimpleHTTPRequestHandler):
        def do_GET(self):
            body = files.get(self.path.split('?')[0])
            if body is None:
                return super().do_GET()
            self.send_response(200)
            self.send_header('Content-Type', 'application/json' if self.path.endswith('.json')
                             else 'text/html')
            self.send_header('Content-Length', str(len(body)))
            self.end_headers()
            self.wfile.write(body)

        def log_message(self, *args):
            pass
    server = http.server.ThreadingHTTPServer(
        ('127.0.0.1', 0), functools.partial(Handler, directory=str(cache)))
    threading.Thread(target=server.serve_forever, daemon=True).start()
    return server, server.server_address[1]


class Relay:
    """Accept clients under the protocol's old subprotocol name and relay every frame to
    ``upstream`` under the new one (and back). ``frames``: frames relayed to clients."""

    def __init__(self, upstream):
        self.upstream = upstream
        self.frames = 0
        self.port = None
        self._ready = threading.Event()
        self._loop = None
        threading.Thread(target=lambda: asyncio.run(self._main()), daemon=True).start()
        self._ready.wait(10)

    async def _main(self):
        from websockets.asyncio.server import serve
        self._loop = asyncio.get_running_loop()
        self._stop = asyncio.Event()
        async with serve(self._client, '127.0.0.1', 0, max_size=None,
                         subprotocols=[OLD_SUBPROTOCOL, NEW_SUBPROTOCOL]) as server:
            self.port = server.sockets[0].getsockname()[1]
            self._ready.set()
            await self._stop.wait()

    async def _client(self, ws):
        from websockets.asyncio.client import connect
        up = None
        for _ in range(300):   # the run may not be serving yet
            try:
                up = await connect(self.upstream, subprotocols=[NEW_SUBPROTOCOL], max_size=None)
                break
            except OSError:
                await asyncio.sleep(0.2)
        if up is None:
            return
        async def pump(src, dst, count):
            async for frame in src:
                await dst.send(frame)
                self.frames += count
        try:
            done, pending = await asyncio.wait(
                [asyncio.create_task(pump(ws, up, 0)), asyncio.create_task(pump(up, ws, 1))],
                return_when=asyncio.FIRST_COMPLETED)
            for task in pending:
                task.cancel()
        finally:
            await up.close()

    def close(self):
        if self._loop:
            self._loop.call_soon_threadsafe(self._stop.set)


def free_port():
    with socket.socket() as s:
        s.bind(('127.0.0.1', 0))
        return s.getsockname()[1]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('scenario', nargs='?', default='scenarios/crossing_light_target_mariner.yaml')
    ap.add_argument('--out', default='doc/live_view_screenshot.png')
    ap.add_argument('--cache', default=os.path.expanduser('~/.cache/shipnav/foxglove-studio'),
                    help='folder for the npm packages')
    ap.add_argument('--shot-after', type=float, default=0.5,
                    help='take the screenshot at this fraction of the run (by sim time)')
    ap.add_argument('--timeout', type=float, default=600.0, help='s for the whole check')
    ap.add_argument('--width', type=int, default=1600)
    ap.add_argument('--height', type=int, default=1000)
    args = ap.parse_args(argv)
    chromium = find_chromium()
    if shutil.which('npm') is None or chromium is None:
        print('live_view_screenshot: needs npm and Chromium on PATH', file=sys.stderr)
        return 2
    cache = fetch_app(Path(args.cache))
    server, http_port = serve_page(cache, LAYOUT)
    live_port = free_port()
    relay = Relay(f'ws://127.0.0.1:{live_port}')
    url = (f'http://127.0.0.1:{http_port}/?ds=foxglove-websocket'
           f'&ds.url=ws://127.0.0.1:{relay.port}&layoutId=shipnav')
    scenario = Path(args.scenario)
    errors = []
    run = None
    from playwright.sync_api import sync_playwright
    deadline = time.monotonic() + args.timeout
    with sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=chromium, headless=True,
                                     args=[*CHROMIUM_ARGS, '--use-gl=swiftshader',
                                           '--enable-unsafe-swiftshader'])
        try:
            page = browser.new_page(viewport={'width': args.width, 'height': args.height})
            page.on('console', lambda m: errors.append(m.text) if m.type == 'error' else None)
            page.on('pageerror', lambda e: errors.append(f'uncaught: {e}'))
            # Map tiles come from the internet; the app shows the ship without them.
            page.route('**/*', lambda r: r.continue_() if r.request.url.startswith(
                'http://127.0.0.1') else r.abort())
            page.goto(url, timeout=180_000)
            page.wait_for_selector('text=cross-track error', timeout=180_000)
            run = subprocess.Popen(
                [sys.executable, str(REPO / 'scripts' / 'run_mission.py'), str(scenario),
                 '--live', '--live-port', str(live_port)], cwd=REPO, start_new_session=True,
                stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
            for line in run.stdout:
                print(line, end='')
                sim_s, duration = _progress(line)
                if sim_s >= args.shot_after * duration or time.monotonic() > deadline:
                    break
            page.wait_for_timeout(3000)   # let the panels draw what arrived
            Path(args.out).parent.mkdir(parents=True, exist_ok=True)
            page.screenshot(path=args.out)
            print(f'saved {args.out}; relayed {relay.frames} frames; console errors:')
            for e in errors:
                print(f'  {e[:300]}')
        finally:
            if run is not None and run.poll() is None:
                os.killpg(run.pid, signal.SIGINT)
                try:
                    run.wait(60)
                except subprocess.TimeoutExpired:
                    os.killpg(run.pid, signal.SIGKILL)
            browser.close()
            relay.close()
            server.shutdown()
    return 0 if relay.frames > 0 and Path(args.out).exists() else 1


def _progress(line):
    """(sim time, duration) in s of a launcher progress line ``  t =   123.4 / 1250 s ...``,
    else (0, inf)."""
    words = line.split()
    if len(words) > 5 and words[:2] == ['t', '='] and words[3] == '/':
        try:
            return float(words[2]), float(words[4])
        except ValueError:
            pass
    return 0.0, float('inf')


if __name__ == '__main__':
    sys.exit(main())
