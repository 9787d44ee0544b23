"""Open an HTML page in headless Chromium and report what a reader would see go wrong: console
errors, uncaught exceptions, images that did not decode, requests that left the file, in-page
links (a table of contents) whose anchor is missing, a page wider than the window (it scrolls
sideways: unreadable on a phone), and a screenshot. Driven by Playwright (its Python package
only; the browser is the system's Chromium, e.g. Debian's ``chromium``: no browser is
downloaded).

``check_page`` runs in the calling process; scripts/check_report.py wraps it as a command whose
process group a caller can bound in time and kill (the browser test does).
"""
import shutil
import tempfile
from pathlib import Path

#: Flags that keep a headless Chromium off the network and quiet on a bare machine (root, no GPU).
CHROMIUM_ARGS = ('--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
                 '--disable-background-networking', '--disable-component-update', '--disable-sync')


def find_chromium():
    """The path of a Chromium executable on PATH, or None."""
    for name in ('chromium', 'chromium-browser', 'google-chrome'):
        path = shutil.which(name)
        if path:
            return path
    return None


def check_page(html_path, screenshot=None, executable=None, timeout_s=30.0, width=1280, height=1000,
               full_page=False):
    """Load ``html_path`` (file) in headless Chromium; returns a dict:

    - 'console': [(type, text)] of console messages of type error or warning;
    - 'page_errors': uncaught exceptions; 'requests': URLs requested other than the page itself
      and data: URIs (a self-contained page has none; they are answered with an abort);
    - 'images': [{'alt', 'natural_width', 'natural_height', 'complete'}] per <img>;
    - 'anchors': [{'href', 'found'}] per in-page link (href "#id"): whether the id exists;
    - 'overflow_px': how much wider than the window the page is (0: no sideways scrolling);
    - 'width': the window width (px); 'text': the page's visible text;
    - 'title', 'browser' (version), 'screenshot' (path or None).

    RuntimeError when no Chromium is found."""
    from playwright.sync_api import sync_playwright
    executable = executable or find_chromium()
    if executable is None:
        raise RuntimeError('no Chromium found on PATH (Debian: apt-get install chromium)')
    page_url = Path(html_path).resolve().as_uri()
    out = {'console': [], 'page_errors': [], 'requests': [], 'screenshot': None}
    with tempfile.TemporaryDirectory(prefix='report-browser-') as profile, sync_playwright() as pw:
        context = pw.chromium.launch_persistent_context(
            profile, executable_path=executable, headless=True, args=list(CHROMIUM_ARGS),
            viewport={'width': width, 'height': height}, timeout=timeout_s * 1000, offline=True)
        try:
            page = context.new_page()
            page.on('console', lambda m: out['console'].append((m.type, m.text))
                    if m.type in ('error', 'warning') else None)
            page.on('pageerror', lambda e: out['page_errors'].append(str(e)))

            def route(r):
                if r.request.url != page_url:
                    out['requests'].append(r.request.url)
                    return r.abort()
                return r.continue_()
            page.route('**/*', route)
            page.goto(page_url, wait_until='load', timeout=timeout_s * 1000)
            out['images'] = page.evaluate(
                '() => Array.from(document.images).map(i => ({alt: i.alt, complete: i.complete, '
                'natural_width: i.naturalWidth, natural_height: i.naturalHeight}))')
            out['anchors'] = page.evaluate(
                '() => Array.from(document.querySelectorAll(\'a[href^="#"]\')).map(a => ({href: '
                'a.getAttribute("href"), found: document.getElementById(decodeURIComponent('
                'a.getAttribute("href").slice(1))) !== null}))')
            out['overflow_px'] = page.evaluate(
                '() => Math.max(document.documentElement.scrollWidth, document.body.scrollWidth)'
                ' - document.documentElement.clientWidth')
            out['width'] = width
            out['text'] = page.evaluate('() => document.body.innerText')
            out['title'] = page.title()
            out['browser'] = context.browser.version if context.browser else None
            if screenshot:
                Path(screenshot).parent.mkdir(parents=True, exist_ok=True)
                page.screenshot(path=str(screenshot), full_page=full_page, timeout=timeout_s * 1000)
                out['screenshot'] = str(screenshot)
        finally:
            context.close()
    return out


def problems(result):
    """One line per problem of a check_page result ([] = the page is fine)."""
    lines = [f'console {kind}: {text}' for kind, text in result['console'] if kind == 'error']
    lines += [f'uncaught: {e}' for e in result['page_errors']]
    lines += [f'network request: {u}' for u in result['requests']]
    lines += [f'image not decoded: {i["alt"]}' for i in result.get('images', [])
              if not i['complete'] or i['natural_width'] <= 0]
    lines += [f'link to a missing anchor: {a["href"]}' for a in result.get('anchors', [])
              if not a['found']]
    if result.get('overflow_px', 0) > 0:
        lines.append(f'page {result["overflow_px"]} px wider than the {result.get("width")} px '
                     'window (scrolls sideways)')
    return lines
