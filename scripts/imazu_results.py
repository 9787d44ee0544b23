#!/usr/bin/env python3
"""The results file of doc/results/imazu.md (or dnv.md) from finished benchmark folders.

    .venv/bin/python scripts/imazu_results.py [--set imazu|dnv] RUN_DIR [RUN_DIR ...]
        [--out doc/results/data/<set>.json]

Each RUN_DIR is a folder written by scripts/imazu_benchmark.py (summary.json, results.csv),
typically one per ship/method (``--ships tanker --methods vo``), so that sets finished at
different times are merged; a set may be in one folder only. Every set keeps its run's own
provenance; the ship/method sets no folder holds are listed as not run. Then
``.venv/bin/python scripts/render_results.py`` renders the page (imazu.results_file).
"""
import json
import sys
from pathlib import Path

from imazu.cases import SETS, load_set
from imazu.results_file import MergeError, merge
from imazu.runner import METHODS, SHIPS
from results_pages.provenance import provenance
from ship_mission.cli_args import OneLineParser

DATA = Path(__file__).resolve().parent.parent / 'doc' / 'results' / 'data'


def main(argv=None):
    ap = OneLineParser(description=__doc__.split('\n')[0])
    ap.add_argument('folders', type=Path, nargs='+', metavar='RUN_DIR')
    ap.add_argument('--set', choices=SETS, default='imazu', help='encounter set of the folders')
    ap.add_argument('--out', type=Path, help='default doc/results/data/<set>.json')
    args = ap.parse_args(argv)
    args.out = args.out or DATA / f'{args.set}.json'
    try:
        data = merge(args.folders, SHIPS, METHODS, load_set(args.set),
                     provenance(sys.argv if argv is None else [sys.argv[0], *argv]), args.set)
    except MergeError as exc:
        ap.error(str(exc))
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(data, indent=1) + '\n')
    print(f'written {args.out}: {", ".join(data["sets"])}'
          + (f'; not run: {", ".join(data["not_run"])}' if data['not_run'] else ''))
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
