"""Write the 22 Imazu cases as maritime-schema TrafficSituation JSON files (one per case).

    .venv/bin/python scripts/export_maritime_schema.py OUT_DIR [--cases 1,2,5]

Each file is imazu_NN.json, validated by reading it back with the schema's classes and
checked to give back the case (positions within a millimetre, courses and speeds within
1e-9). Needs requirements/interop.txt (`make venv-interop`).
"""
import argparse
import math
import sys
from pathlib import Path

from imazu.cases import load_cases
from imazu.maritime_schema_io import dumps, from_traffic_situation, loads, to_traffic_situation

#: Largest position difference (m) of a round trip: the tangent-plane map and its inverse.
POSITION_TOLERANCE_M = 1e-3


def same_case(a, b):
    """True if two case dicts agree (positions within POSITION_TOLERANCE_M)."""
    def close(s, t):
        return (math.hypot(s['north_m'] - t['north_m'], s['east_m'] - t['east_m'])
                <= POSITION_TOLERANCE_M
                and abs((s['course_deg'] - t['course_deg'] + 180.0) % 360.0 - 180.0) < 1e-9
                and abs(s['speed_mps'] - t['speed_mps']) < 1e-9)
    return (close(a['own'], b['own']) and len(a['targets']) == len(b['targets'])
            and all(close(s, t) and s['name'] == t['name'] and s['colregs'] == t['colregs']
                    for s, t in zip(a['targets'], b['targets'])))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('out', type=Path)
    ap.add_argument('--cases', help='case numbers, e.g. 1,2,5 (default all 22)')
    args = ap.parse_args(argv)
    cases = load_cases()
    chosen = [int(c) for c in args.cases.split(',')] if args.cases else sorted(cases)
    args.out.mkdir(parents=True, exist_ok=True)
    for n in chosen:
        text = dumps(to_traffic_situation(n, cases[n]))
        number, back = from_traffic_situation(loads(text))
        if number != n or not same_case(back, cases[n]):
            print(f'case {n}: the written file does not give the case back', file=sys.stderr)
            return 1
        (args.out / f'imazu_{n:02d}.json').write_text(text + '\n')
    print(f'{len(chosen)} maritime-schema files in {args.out}')
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
