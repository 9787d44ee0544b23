#!/usr/bin/env python3
"""Benchmark suite (``make bench``): prints a table per section and writes all figures to JSON.

    scripts/bench.py [--only SECTION[,SECTION...]] [--quick] [--out PATH] [--list]

Sections (registry: scripts/benchmarks/__init__.py):
  models       single-vessel derivative and RK4 step cost per model (us)
  batched      batched RK4 throughput for the MSS ships (vessel-steps/s)
  batch_closed_loop  batched closed loop (plant + guidance + autopilot) against one vessel and the plant
  wind         cost of the wind loads per simulator step, one vessel and batched
  node_jitter  odom inter-arrival jitter of a realtime vessel_node (needs `make build`)
  lockstep     flagship graph in lockstep: real-time factor, against a bare 3-hop relay floor
  composition  nodes composed in one process vs one each: platoon of 1/3/5, flagship vs the floor
  live_view    flagship lockstep run with and without --live (and a client)
  realtime_latency  flagship graph in realtime: odom -> rudder_cmd latency, missed steps
  closed_loop_inprocess  the flagship loop's pure modules in one process (no ROS)
  batch_closed_loop  N closed-loop episodes as arrays: vessel-steps/s vs one vessel, the plant
  kernels      the batched closed loop per MSS ship on numpy vs numba, plant alone on each
  colav        one collision-avoidance decision with 10 targets, SB-MPC and VO (ms)
  waves        per-step cost of the wave-frequency motion and the wave filter
  imazu        Imazu benchmark runs in process: time per run, decisions/s (mariner, 600 s sim)
  sweep        scripts/sweep.py throughput: local processes and Ray, 1 and 2 workers
  controllers  Martinsen and Lekkas 2018's Table I: classical controllers vs the learned policy (~10 min)

The JSON (default bench/results/bench.json, git-ignored) holds the machine (CPU count and
model, Python, numpy, date), the arguments and, per section, its rows, goals and notes.
A benchmark is not a test: a missed goal is reported, not an error. Exit codes: 0 every
section ran, 1 a section failed (its error is in the JSON and printed), 2 bad arguments.
"""
import argparse
import json
import os
import sys
import time
import traceback
from pathlib import Path

from benchmarks import SECTIONS, section_function
from benchmarks.common import REPO, format_section, machine_info
from results_pages.provenance import provenance
from ship_sim.allocator import tune_allocator

DEFAULT_OUT = REPO / 'bench' / 'results' / 'bench.json'


def parse_args(argv=None):
    listing = '\n'.join(f'  {k:12s} {v[2]}' for k, v in SECTIONS.items())
    p = argparse.ArgumentParser(description=__doc__.split('\n')[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter,
                                epilog='sections:\n' + listing)
    p.add_argument('--only', metavar='SECTION[,SECTION]',
                   help='run only these sections (comma-separated), in registry order')
    p.add_argument('--quick', action='store_true', help='shorter timings (a smoke run)')
    p.add_argument('--out', type=Path, default=DEFAULT_OUT,
                   help='JSON output path (default: %(default)s)')
    p.add_argument('--list', action='store_true', help='list the sections and exit')
    args = p.parse_args(argv)
    if args.only:
        wanted = [s.strip() for s in args.only.split(',') if s.strip()]
        unknown = [s for s in wanted if s not in SECTIONS]
        if unknown:
            p.error(f"unknown section(s) {', '.join(unknown)}; allowed: {', '.join(SECTIONS)}")
        args.sections = [s for s in SECTIONS if s in wanted]
    else:
        args.sections = list(SECTIONS)
    return args


def main(argv=None):
    tune_allocator()   # first: every section's numbers with the same allocator settings
    args = parse_args(argv)
    if args.list:
        for name, (_, _, text) in SECTIONS.items():
            print(f'{name:12s} {text}')
        return 0
    machine = machine_info()
    print(f"machine: {machine['cpu_count']} CPU ({machine['cpu_model']}), "
          f"load {machine.get('load_avg_1min', float('nan')):.2f}, "
          f"Python {machine['python']}, numpy {machine['numpy']}, {machine['date']}"
          + (' [quick]' if args.quick else ''))
    # provenance: doc/results/performance.md renders its generated table from this file
    report = {'provenance': provenance(), 'machine': machine, 'args': {'only': args.sections, 'quick': args.quick},
              'sections': {}}
    failed = []
    for name in args.sections:
        t0 = time.monotonic()
        # each section's own load: a run's sections meet different loads on a shared machine
        load = round(os.getloadavg()[0], 1)
        try:
            result = section_function(name)(quick=args.quick)
        except Exception as exc:  # noqa: BLE001 (one broken section must not hide the others' numbers)
            failed.append(name)
            result = {'title': 'FAILED', 'error': f'{type(exc).__name__}: {exc}',
                      'traceback': traceback.format_exc(), 'rows': [], 'goals': [],
                      'notes': [f'section failed: {type(exc).__name__}: {exc}']}
        if result.get('failed') and name not in failed:  # partly failed, numbers kept
            failed.append(name)
        result['wall_s'] = round(time.monotonic() - t0, 2)
        result['load_1min_start'] = load
        report['sections'][name] = result
        print()
        print(format_section(name, result), flush=True)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(report, indent=1, allow_nan=True) + '\n')
    print(f'\nwrote {args.out}')
    if failed:
        print(f"failed sections: {', '.join(failed)}", file=sys.stderr)
        return 1
    return 0


if __name__ == '__main__':
    sys.exit(main())
