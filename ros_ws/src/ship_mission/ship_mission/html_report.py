"""Self-contained HTML pages of runs and batches: one file, images as data URIs, inline CSS, no
scripts, fonts or links to the network, so a report opens offline and can be mailed as it is.

Run report (``write_run_report``, called by ``ship_mission.report.analyse_bag`` wherever it writes
metrics.json: the launcher after a mission, replay_bag.py, the seed batch): report.html beside
metrics.json with the run (date, git commit, command, outcome), the scenario YAML, the metrics
tables (vessels, platoon, encounter when a vessel ran colav_node, record completeness, topics),
every PNG of the folder and the warnings and errors of the node logs (``log_issues``), under a
table of contents. Metric tables give each metric's unit and description from
ship_mission.metric_info (the one table of them); angles are shown in degrees there (metrics.json
keeps radians).

Readable at phone width: the viewport meta tag, images no wider than the page, wide tables
scroll sideways inside their own box instead of widening the page.

Batch page, for any batch script (run_seed_scenarios.py, evaluate_controllers.py, benchmarks)::

    batch_page(path, title, columns, rows, links=None, intro='', sections=(), command=None)

- ``path``: the HTML file to write (its folder is created); returns it as a Path.
- ``columns``: header strings; ``rows``: one sequence of cell values per case (str, number,
  bool or None; floats shown to 4 significant digits, None as '-').
- ``links``: per row the path of that case's report.html (or None): the first cell becomes a
  link, relative to the page's folder so a copied batch folder keeps working; a link that
  starts with '#' stays an anchor on the page (e.g. '#' + figure_id(png) of an embedded plot).
- ``intro``: a paragraph under the title; ``sections``: more tables after the main one, each
  (heading, columns, rows) or (heading, columns, rows, links), e.g. a claims table;
- ``command``: shown in the header (default: this process's command line);
- ``figures``: PNG files embedded (data URIs) under "Plots", each with its caption
  (``{file name: caption}`` in ``captions``).
"""
import base64
import html
import json
import os
import re
import shlex
import subprocess
import sys
from datetime import datetime, timezone
from pathlib import Path

from ship_mission.processes import REPO

#: The node-log lines a report lists: rclpy's levels and Python's warnings and tracebacks.
ISSUE = re.compile(r'\[(WARN|ERROR|FATAL)\]|Warning:|^Traceback|^\w*Error\b')
MAX_LOG_LINES = 40   # per log file; the rest is counted

CSS = """
body{font:14px/1.45 system-ui,sans-serif;margin:1.5em auto;max-width:1200px;padding:0 1em;color:#222}
h1{font-size:1.5em;margin-bottom:.2em}h2{font-size:1.2em;border-bottom:1px solid #ccc;margin-top:1.6em}
table{border-collapse:collapse;margin:.5em 0;font-size:13px}
th,td{border:1px solid #ccc;padding:2px 7px;text-align:left;vertical-align:top}
th{background:#f0f2f5}td.n{text-align:right;font-variant-numeric:tabular-nums}
tr:nth-child(even) td{background:#fafbfc}
pre{background:#f6f8fa;border:1px solid #ddd;padding:.6em;overflow:auto;font-size:12px}
pre .c{color:#6a737d}pre .k{color:#005cc5}
.plots{columns:2 480px;column-gap:.8em}figure{margin:0 0 .8em;break-inside:avoid}
figure img{width:100%;max-width:100%;height:auto;border:1px solid #ddd}
figcaption{font-size:12px;color:#555}img{max-width:100%;height:auto}
.scroll{overflow-x:auto;max-width:100%}.scroll table{margin:0}
td.d{color:#555;font-size:12px;min-width:22em}td.k{font:11px monospace;color:#555}
nav.toc{background:#f6f8fa;border:1px solid #ddd;padding:.3em 1em;display:inline-block}
nav.toc ol{margin:.3em 0;padding-left:1.4em}
.bad{color:#b00020;font-weight:bold}.ok{color:#137333}
.meta td{overflow-wrap:anywhere}.meta td:first-child{font-weight:bold;white-space:nowrap}
p{overflow-wrap:anywhere}
"""


def esc(value):
    return html.escape(str(value), quote=True)


def fmt(value):
    """A cell's text: floats to 4 significant digits, None as '-', lists and dicts as JSON."""
    if value is None:
        return '-'
    if isinstance(value, bool):
        return 'yes' if value else 'no'
    if isinstance(value, float):
        return f'{value:.4g}'
    if isinstance(value, (list, tuple, dict)):
        return json.dumps(value, separators=(', ', ': '), default=str)
    return str(value)


def table(columns, rows, links=None, base=None, classes=None):
    """An HTML table in a box that scrolls sideways when the table is wider than the page;
    numbers right-aligned. ``links``: per row an href for the first cell; ``classes``: per
    column a CSS class for its cells (or None)."""
    out = ['<div class="scroll"><table><tr>' + ''.join(f'<th>{esc(c)}</th>' for c in columns) + '</tr>']
    for i, row in enumerate(rows):
        cells = []
        for j, v in enumerate(row):
            text = esc(fmt(v))
            href = links[i] if links and j == 0 else None
            if href:
                text = f'<a href="{esc(_href(href, base))}">{text}</a>'
            num = isinstance(v, (int, float)) and not isinstance(v, bool)
            cls = 'n' if num else (classes[j] if classes and j < len(classes) else None)
            cells.append(f'<td class="{cls}">{text}</td>' if cls else f'<td>{text}</td>')
        out.append('<tr>' + ''.join(cells) + '</tr>')
    return '\n'.join(out) + '</table></div>'


def _href(target, base):
    if base is None or str(target).startswith('#'):   # an anchor on the same page
        return str(target)
    return Path(os.path.relpath(Path(target).resolve(), Path(base).resolve())).as_posix()


def page(title, body, meta=()):
    """A whole HTML document: title, a key/value table ``meta`` and ``body`` (HTML)."""
    head = ('<div class="scroll"><table class="meta">'
            + ''.join(f'<tr><td>{esc(k)}</td><td>{esc(fmt(v))}</td></tr>' for k, v in meta)
            + '</table></div>') if meta else ''
    return (f'<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
            f'<meta name="viewport" content="width=device-width, initial-scale=1">'
            f'<title>{esc(title)}</title><style>{CSS}</style></head>\n<body>\n'
            f'<h1>{esc(title)}</h1>\n{head}\n{body}\n</body></html>\n')


def png_figure(path, caption=None):
    """A <figure> with the PNG inline (data URI), captioned with its file name and ``caption``."""
    data = base64.b64encode(Path(path).read_bytes()).decode('ascii')
    name = esc(Path(path).name)
    text = f'{name}: {esc(caption)}' if caption else name
    return (f'<figure id="{figure_id(path)}"><img src="data:image/png;base64,{data}" alt="{name}">'
            f'<figcaption>{text}</figcaption></figure>')


def figure_id(path):
    """The id of a PNG's <figure> (link to it with '#' + this)."""
    return 'fig-' + re.sub(r'[^A-Za-z0-9_-]+', '-', Path(path).stem)


def figures_block(paths, captions=None):
    """The PNGs as captioned figures in columns (two on a wide screen, one on a phone)."""
    captions = captions or {}
    return ('<div class="plots">' + '\n'.join(png_figure(p, captions.get(Path(p).name))
                                              for p in paths) + '</div>')


class Sections:
    """The <h2> sections of a page, each with an id, and the table of contents linking them."""

    def __init__(self):
        self.entries = []

    def h2(self, text):
        anchor = re.sub(r'[^a-z0-9]+', '-', str(text).lower()).strip('-') or 'section'
        n, base = 2, anchor
        while anchor in (a for a, _ in self.entries):
            anchor, n = f'{base}-{n}', n + 1
        self.entries.append((anchor, text))
        return f'<h2 id="{esc(anchor)}">{esc(text)}</h2>'

    def toc(self):
        items = ''.join(f'<li><a href="#{esc(a)}">{esc(t)}</a></li>' for a, t in self.entries)
        return f'<nav class="toc"><strong>Contents</strong><ol>{items}</ol></nav>'


def metric_table(section, columns):
    """Metrics as rows (metric without its unit suffix, unit, one column per entry of ``columns``
    {name: metrics dict}, description, the metrics.json key), with the unit and description of
    ship_mission.metric_info's ``section``, angles in degrees. A key without an entry there is shown
    with a '?' unit (the tests forbid it)."""
    from ship_mission.metric_info import plain_name, shown
    names = list(columns)
    keys = []
    for m in columns.values():
        keys += [k for k in m if k not in keys]
    rows = []
    for k in keys:
        unit, text = section.get(k, ('?', ''))
        values = [shown(columns[n].get(k), unit) for n in names]
        rows.append([plain_name(k, unit), values[0][1] if values else unit]
                    + [v for v, _ in values] + [text, k])
    return table(['metric', 'unit'] + names + ['description', 'metrics.json key'], rows,
                 classes=[None, None] + [None] * len(names) + ['d', 'k'])


def yaml_block(text):
    """YAML text as a <pre> with comments and keys coloured (a '#' after a blank starts a comment)."""
    lines = []
    for line in text.splitlines():
        cut = re.search(r'(^|\s)#', line)
        code, comment = (line[:cut.end() - 1], line[cut.end() - 1:]) if cut else (line, '')
        m = re.match(r'^(\s*(?:-\s+)?)([\w./-]+):(\s.*|)$', code)
        body = (f'{esc(m.group(1))}<span class="k">{esc(m.group(2))}</span>:{esc(m.group(3))}'
                if m else esc(code))
        lines.append(body + (f'<span class="c">{esc(comment)}</span>' if comment else ''))
    return '<pre>' + '\n'.join(lines) + '</pre>'


def log_issues(log_dir):
    """{log file name: [lines that warn or report an error]} of every *.log in ``log_dir``."""
    out = {}
    for f in sorted(Path(log_dir).glob('*.log')):
        lines = [ln.rstrip() for ln in f.read_text(errors='replace').splitlines() if ISSUE.search(ln)]
        if lines:
            out[f.name] = lines
    return out


def git_commit():
    """'<short hash>' (+ ' (modified)' with uncommitted changes), or None outside a checkout."""
    try:
        head = subprocess.run(['git', '-C', str(REPO), 'rev-parse', '--short', 'HEAD'],
                              capture_output=True, text=True, timeout=5)
        if head.returncode:
            return None
        dirty = subprocess.run(['git', '-C', str(REPO), 'status', '--porcelain', '--untracked-files=no'],
                               capture_output=True, text=True, timeout=5).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return None
    return head.stdout.strip() + (' (modified)' if dirty else '')


def _utc(ts):
    return datetime.fromtimestamp(ts, timezone.utc).strftime('%Y-%m-%d %H:%M:%S UTC')


def _run_summary(path):
    """run.json (the launcher's YAML summary) as a dict, {} when absent or unreadable."""
    from ship_sim.safe_load import InputError, load_yaml_file
    try:
        return load_yaml_file(path) or {}
    except InputError:
        return {}


def _record_table(record):
    """Completeness per topic (ship_mission.integrity) and each vessel's recording end."""
    rows, ends = [], []
    streams = [('/clock', record['clock'])] if record.get('clock') else []
    for ns, topics in record.get('vessels', {}).items():
        streams += [(f'{ns}/{t}', s) for t, s in topics.items() if isinstance(s, dict)]
        ends.append([ns] + [topics.get(k) for k in ('missing', 'bag_end_s', 'tail_after_finish_s')])
    for name, s in streams:
        rows.append([name] + [s.get(k) for k in ('expected', 'received', 'missing', 'in_flight', 'gaps')])
    state = ('<p class="ok">record complete</p>' if record.get('complete')
             else f'<p class="bad">record INCOMPLETE: {esc(record.get("missing"))} messages missing</p>')
    return (state + table(['topic', 'expected', 'received', 'missing', 'in flight', 'gaps'], rows)
            + table(['vessel', 'missing', 'bag end s', 'after completion s'], ends))


def encounter_rows(bag_dir, metrics):
    """[(own, target, encounter_report dict)] for every vessel with a colav_decision topic
    against every other vessel of the bag; [] without colav."""
    from ship_mission.encounter import encounter_report
    topics = metrics.get('topics', {})
    own = [t.split('/')[1] for t in topics if t.endswith('/colav_decision')]
    others = [t.split('/')[1] for t in topics if t.endswith('/odom')]
    return [(o, t, encounter_report(bag_dir, o, t)) for o in own for t in others if t != o]


def write_run_report(run_dir, metrics, source_dir=None, command=None):
    """Write ``run_dir``/report.html for one run (module docstring) and return its path.

    ``metrics``: the dict of metrics.json; ``source_dir``: the run folder holding scenario.yaml,
    run.json, logs/ and bag/ (default ``run_dir``)."""
    run_dir = Path(run_dir)
    src = Path(source_dir) if source_dir is not None else run_dir
    run = metrics.get('run') or _run_summary(src / 'run.json')
    bag = Path(metrics.get('bag', src / 'bag'))
    scenario = src / 'scenario.yaml'
    title = run.get('name') or Path(run.get('scenario') or src.name).stem
    stamp = max((f.stat().st_mtime for f in bag.glob('*') if f.is_file()), default=None) if bag.is_dir() else None
    meta = [('run folder', str(src.resolve())), ('recorded', _utc(stamp) if stamp else 'unknown'),
            ('report written', _utc(datetime.now().timestamp())),
            ('git commit', git_commit() or 'unknown'),
            ('command', command or shlex.join(sys.argv))]
    if metrics.get('record'):
        from ship_mission.integrity import summary_line
        meta.append(('record', summary_line(metrics['record'])))
    if run:
        meta += [('outcome', run.get('outcome')),
                 ('sim / wall time', f"{fmt(run.get('sim_time_s'))} s / {fmt(run.get('wall_time_s'))} s "
                                     f"(x{fmt(run.get('real_time_factor'))} real time)")]
    from ship_mission import metric_info
    from ship_mission.plots import CAPTIONS
    sec = Sections()
    body = []
    if metrics.get('recovered'):
        body.append(f'<p class="bad">{esc(metrics["recovered"])}</p>')
    listed = metrics.get('plots') or []   # the analysis's own plots first, in its order
    pngs = sorted(run_dir.glob('*.png'), key=lambda f: (listed.index(f.name) if f.name in listed
                                                        else len(listed), f.name))
    body += [sec.h2('Plots'), figures_block(pngs, CAPTIONS) if pngs else '<p>no plots</p>']
    body += [sec.h2('Vessels'), metric_table(metric_info.VESSEL, metrics.get('vessels', {}))]
    if metrics.get('traffic'):
        body += [sec.h2('Traffic'), metric_table(metric_info.TRAFFIC, metrics['traffic'])]
    if metrics.get('platoon'):
        body += [sec.h2('Platoon'), metric_table(metric_info.PLATOON, metrics['platoon'])]
    if bag.is_dir():
        try:
            enc = encounter_rows(bag, metrics)
        except Exception as exc:  # noqa: BLE001 - a report shows what it can, and says why not
            body.append(f'<p class="bad">encounter figures not available: {esc(type(exc).__name__)}: '
                        f'{esc(exc)}</p>')
            enc = []
        if enc:
            keys = list(enc[0][2])
            body += [sec.h2('Encounter'), table(['own', 'target'] + keys,
                                                [[o, t] + [r[k] for k in keys] for o, t, r in enc])]
    logs = src / 'logs'
    if logs.is_dir():
        issues = log_issues(logs)
        n_logs = len(list(logs.glob('*.log')))
        body.append(sec.h2(f'Node logs: warnings and errors ({len(issues)} of {n_logs} logs)'))
        for name, lines in issues.items():
            more = len(lines) - MAX_LOG_LINES
            body.append(f'<h3>{esc(name)} ({len(lines)} lines)</h3><pre>'
                        + esc('\n'.join(lines[:MAX_LOG_LINES]))
                        + (f'\n... and {more} more (logs/{esc(name)})' if more > 0 else '') + '</pre>')
        if not issues:
            body.append(f'<p class="ok">none in {n_logs} logs ({esc(logs)})</p>')
    if scenario.is_file():
        body += [sec.h2('Scenario'), yaml_block(scenario.read_text(errors='replace'))]
    if metrics.get('record'):
        body += [sec.h2('Record'), _record_table(metrics['record'])]
    if metrics.get('topics'):
        body += [sec.h2('Topics'), table(['topic', 'type', 'messages'],
                                         [[t, s.get('type'), s.get('count')]
                                          for t, s in metrics['topics'].items()])]
    body.insert(0, sec.toc())
    path = run_dir / 'report.html'
    path.write_text(page(f'Run report: {title}', '\n'.join(body), meta), encoding='utf-8')
    return path


def batch_page(path, title, columns, rows, links=None, intro='', sections=(), command=None,
               figures=(), captions=None):
    """Write one page with a row per case (module docstring) and return its path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    meta = [('written', _utc(datetime.now().timestamp())), ('git commit', git_commit() or 'unknown'),
            ('command', command or shlex.join(sys.argv))]
    body = [f'<p>{esc(intro)}</p>' if intro else '', table(columns, rows, links, path.parent)]
    for heading, cols, srows, *slinks in sections:
        body += [f'<h2>{esc(heading)}</h2>', table(cols, srows, slinks[0] if slinks else None, path.parent)]
    if figures:
        body += ['<h2 id="plots">Plots</h2>', figures_block(figures, captions)]
    path.write_text(page(title, '\n'.join(body), meta), encoding='utf-8')
    return path
