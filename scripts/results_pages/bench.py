"""The goals and tables of a benchmark run (scripts/bench.py, its JSON):
doc/results/performance.md and doc/results/batch_closed_loop.md."""
import math

from results_pages.registry import table
from results_pages.tables import fmt, markdown_table


def _value(v, unit):
    """Four significant digits; rates of ten thousand and more in full, thousands separated
    (a rate in 'e+05' notation is hard to read against its target)."""
    if isinstance(v, (int, float)) and not isinstance(v, bool) and abs(v) >= 1e4:
        text = fmt(v, ',.0f')
    else:
        text = fmt(v, '.4g') if isinstance(v, float) else fmt(v, '')
    return f'{text} {unit}' if unit else text


def _load(section):
    """The 1-minute load when the section started (runs before it was recorded: 'n/a')."""
    return fmt(section.get('load_1min_start'), '.1f')


@table('bench', 'goals')
def goals(data):
    """Every goal of every section that ran: the measured value against the target, met or
    missed, and the load the section started at; a failed section says so."""
    lines = ['| section | load at start | goal | measured | target | met |',
             '|---|---:|---|---:|---:|---|']
    for name, s in data['sections'].items():
        if s.get('error'):
            lines.append(f"| {name} | {_load(s)} | section failed: {s['error']} | | | |")
        for g in s.get('goals', []):
            lines.append(f"| {name} | {_load(s)} | {g['text']} | {_value(g['value'], g['unit'])} | "
                         f"{g['relation']} {_value(g['target'], g['unit'])} | "
                         f"{'yes' if g['met'] else '**no**'} |")
    quick = ' (`--quick`: shorter timings)' if data['args'].get('quick') else ''
    return '\n'.join(lines) + (f"\n\nSections {', '.join(data['sections'])}{quick}; "
                               f"CPU {data['machine'].get('cpu_model')}.\n")


def _number(v):
    """A rate or ratio: thousands separated from 1,000, three significant digits below (a
    row without the figure shows 'n/a', markdown_table's cell for None)."""
    if math.isnan(v):
        return 'n/a'
    if isinstance(v, int) or abs(v) >= 1000:
        return f'{v:,.0f}'
    return f'{v:.3g}'


def section_rows(data, name):
    """A section's rows with its own columns (bench.py's table), its title and load above and
    its notes (ratios and conditions the section computed) below."""
    try:
        s = data['sections'][name]
    except KeyError:
        raise KeyError(f"no section '{name}' in the bench run (it has: "
                       f"{', '.join(data['sections'])})") from None
    if s.get('error'):
        return f"Section {name} failed: {s['error']}\n"
    columns = [(head, (lambda r, k=key: r.get(k)), lambda v: v if isinstance(v, str) else _number(v))
               for key, head in s['columns']]
    quick = ', `--quick`' if data['args'].get('quick') else ''
    notes = ''.join(f'- {note}\n' for note in s.get('notes', []))
    return (f"{s['title'][:1].upper()}{s['title'][1:]}; 1-minute load {_load(s)} when the section started{quick}:\n\n"
            + markdown_table(columns, s['rows'])
            + (f'\nThe section\'s notes:\n\n{notes}' if notes else ''))


@table('bench', 'batch_closed_loop')
def batch_closed_loop(data):
    return section_rows(data, 'batch_closed_loop')


@table('bench', 'sweep')
def sweep(data):
    return section_rows(data, 'sweep')
