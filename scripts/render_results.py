#!/usr/bin/env python3
"""Render the generated tables of the results pages from their committed results files.

    .venv/bin/python scripts/render_results.py            # rewrite doc/**/*.md in place
    .venv/bin/python scripts/render_results.py --check    # exit 1 naming each page that differs

A study's command writes its results file; copy it to doc/results/data/ (the page names the
file in its markers, see results_pages.blocks), then run this. ``--check`` runs in the tests.
"""
import argparse
import difflib
import sys
from pathlib import Path

from results_pages.blocks import ResultsError, pages_with_blocks, render_page

DOC = Path(__file__).resolve().parent.parent / 'doc'


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--check', action='store_true', help='change nothing; exit 1 if a page differs')
    ap.add_argument('--root', type=Path, default=DOC, help='folder of the pages (default doc/)')
    args = ap.parse_args(argv)
    stale, broken = [], []
    for page in pages_with_blocks(args.root):
        try:
            new = render_page(page)
        except (ResultsError, KeyError) as exc:   # the other pages are still rendered
            print(f'render_results: {exc}', file=sys.stderr)
            broken.append(page)
            continue
        old = page.read_text()
        if new == old:
            continue
        stale.append(page)
        if args.check:
            diff = difflib.unified_diff(old.splitlines(), new.splitlines(), str(page), 'rendered',
                                        lineterm='', n=0)
            print('\n'.join(list(diff)[:20]), file=sys.stderr)
        else:
            page.write_text(new)
            print(f'rendered {page}')
    if args.check and stale:
        print(f'render_results: {len(stale)} page(s) differ from their results files: '
              + ', '.join(str(p) for p in stale)
              + ' (run .venv/bin/python scripts/render_results.py)', file=sys.stderr)
        return 1
    return 2 if broken else 0


if __name__ == '__main__':
    sys.exit(main())
