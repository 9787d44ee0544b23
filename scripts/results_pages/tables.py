"""Markdown tables from rows of values."""
import math


def fmt(value, spec):
    """A cell: ``spec`` is a format spec ('.3f', '.0f', 'd', '') or a callable; None and
    non-finite numbers show as 'n/a'."""
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return 'n/a'
    return spec(value) if callable(spec) else format(value, spec)


def markdown_table(columns, rows):
    """``columns``: (title, key or callable(row), format spec); ``rows``: dicts."""
    head = '| ' + ' | '.join(c[0] for c in columns) + ' |'
    rule = '|' + '---|' * len(columns)
    lines = [head, rule]
    for row in rows:
        cells = [fmt(c[1](row) if callable(c[1]) else row[c[1]], c[2]) for c in columns]
        lines.append('| ' + ' | '.join(cells) + ' |')
    return '\n'.join(lines) + '\n'
