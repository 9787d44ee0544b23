"""Generated blocks in Markdown pages.

A block is

    <!-- generated: STUDY.TABLE from PATH -->
    ... (written by the renderer) ...
    <!-- end generated -->

PATH is the results file, relative to the page. Everything between the markers is replaced by
what ``studies.render(STUDY, TABLE, data)`` returns.
"""
import json
import re
from pathlib import Path

from results_pages.provenance import provenance_line
from results_pages.studies import render

BLOCK = re.compile(r'(<!-- generated: (?P<study>[\w-]+)\.(?P<table>[\w-]+) from (?P<path>\S+) -->\n)'
                   r'(?P<body>.*?)(?P<end><!-- end generated -->)', re.S)


class ResultsError(ValueError):
    """A page names a results file or table that does not exist, or the file lacks a field."""


def render_page(page: Path) -> str:
    """The page's text with every generated block rendered from its results file."""
    text = page.read_text()

    def fill(m):
        path = (page.parent / m.group('path')).resolve()
        try:
            data = json.loads(path.read_text())
        except FileNotFoundError:
            raise ResultsError(f'{page}: results file {m.group("path")} not found') from None
        if 'provenance' not in data:
            raise ResultsError(f'{path}: no provenance (command, commit, date, load)')
        body = render(m.group('study'), m.group('table'), data)
        return f'{m.group(1)}{body.rstrip()}\n\n{provenance_line(data["provenance"])}\n{m.group("end")}'

    return BLOCK.sub(fill, text)


def pages_with_blocks(root: Path):
    return sorted(p for p in root.rglob('*.md') if BLOCK.search(p.read_text()))
