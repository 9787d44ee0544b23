"""The goals of a benchmark run (scripts/bench.py, its JSON): doc/results/performance.md."""
from results_pages.registry import table
from results_pages.tables import fmt


def _value(v, unit):
    text = fmt(v, '.4g') if isinstance(v, float) else fmt(v, '')
    return f'{text} {unit}' if unit else text


@table('bench', 'goals')
def goals(data):
    """Every goal of every section that ran: the measured value against the target, met or
    missed, and the section's wall time; a failed section says so."""
    lines = ['| section | goal | measured | target | met |', '|---|---|---:|---:|---|']
    for name, s in data['sections'].items():
        if s.get('error'):
            lines.append(f"| {name} | section failed: {s['error']} | | | |")
        for g in s.get('goals', []):
            lines.append(f"| {name} | {g['text']} | {_value(g['value'], g['unit'])} | "
                         f"{g['relation']} {_value(g['target'], g['unit'])} | "
                         f"{'yes' if g['met'] else '**no**'} |")
    quick = ' (`--quick`: shorter timings)' if data['args'].get('quick') else ''
    return '\n'.join(lines) + (f"\n\nSections {', '.join(data['sections'])}{quick}; "
                               f"CPU {data['machine'].get('cpu_model')}.\n")
