#!/usr/bin/env python3
"""Replay a recorded AIS log through the tracker: CPA and TCPA of every target over time.

    .venv/bin/python scripts/ais_cpa.py LOG [--own-mmsi MMSI | --own-fixed LAT LON COG SOG]
        [--rate LINES_PER_S] [--period 10] [--max-range 37040] [--out runs/ais_cpa]

LOG is one of the forms of ship_guidance.ais_log (doc/guide/ais_log_replay.md): ``<t_s>
<sentence>`` lines, NMEA 4.0 tag blocks with ``c:`` times, or sentences without times (then
--rate is required). The own ship is the log's AIVDO ship unless --own-mmsi or --own-fixed
names another (ship_guidance.cpa_replay). Writes to the output folder:

    ais_cpa.csv    one row per output time per target (the columns of cpa_replay.Row, with
                   the UTC time after t_s when the log's times are UNIX times)
    ais_cpa.json   the summary: per target the smallest CPA ahead and when, the nearest
                   range seen, its tracks opened and deleted; lines and sentences rejected
                   and why; the settings and the log's SHA-256
    ais_cpa.png    CPA (with its sigma) and TCPA against time of the --plot-targets targets
                   with the smallest CPA
"""
import csv
import hashlib
import json
import shlex
import sys
import time
from datetime import datetime, timezone
from pathlib import Path

from ship_guidance.ais_log import LogFormatError, read_log_file
from ship_guidance.cpa_replay import FIELDS, MAX_RANGE_M, FixedOwnShip, ReplayConfig, \
    ReplayError, replay
from ship_mission.cli_args import OneLineParser, integer, number, out_folder

PROG = 'ais_cpa.py'


def parse_args(argv):
    ap = OneLineParser(prog=PROG, description=__doc__.split('\n')[0])
    ap.add_argument('log', type=Path, help='the recorded AIS log (a text file)')
    own = ap.add_mutually_exclusive_group()
    own.add_argument('--own-mmsi', type=integer(1, 999_999_999), metavar='MMSI',
                     help='the own ship is this MMSI of the log (default: the AIVDO ship)')
    own.add_argument('--own-fixed', type=number(-360.0, 360.0), nargs=4,
                     metavar=('LAT', 'LON', 'COG', 'SOG'),
                     help='the own ship is not in the log: its position (deg) at the first '
                          'time of the log, course over ground (deg) and speed (kn); SOG 0 '
                          'for a shore receiver (default: the AIVDO ship)')
    ap.add_argument('--rate', type=number(above=0.0, hi=1e6), metavar='LINES_PER_S',
                    help='lines per second of a log without times (required for one, '
                         'refused for a log with times; no default)')
    ap.add_argument('--period', type=number(above=0.0, hi=86400.0), default=10.0,
                    help='output period in log seconds (default 10)')
    ap.add_argument('--max-range', type=number(above=0.0, hi=1e7), default=MAX_RANGE_M,
                    metavar='M', help=f'targets farther from the own ship give no rows '
                    f'(default {MAX_RANGE_M:g} m, 20 NM)')
    ap.add_argument('--plot-targets', type=integer(0, 50), default=8, metavar='N',
                    help='targets in the plot, those with the smallest CPA (default 8; 0: '
                         'no plot)')
    ap.add_argument('--out', type=out_folder, default=Path('runs/ais_cpa'),
                    help='output folder (default runs/ais_cpa)')
    a = ap.parse_args(argv)
    if not (a.log.exists() or a.log.is_symlink()):
        ap.error(f'argument log: {a.log}: no such file')
    if a.own_fixed is not None:
        lat, lon, cog, sog = a.own_fixed
        if not (-89.0 < lat < 89.0 and -180.0 <= lon <= 180.0 and 0.0 <= cog < 360.0
                and 0.0 <= sog <= 102.2):
            ap.error('argument --own-fixed: LAT within (-89, 89), LON within [-180, 180], '
                     f'COG within [0, 360) and SOG within [0, 102.2] kn, got {lat:g} {lon:g} '
                     f'{cog:g} {sog:g}')
        a.own_fixed = FixedOwnShip(lat, lon, cog, sog)
    return ap, a


def _utc(t):
    return datetime.fromtimestamp(t, timezone.utc).strftime('%Y-%m-%dT%H:%M:%SZ')


def write_csv(path, rows, unix_time):
    with open(path, 'w', newline='') as f:
        w = csv.writer(f)
        w.writerow(FIELDS[:1] + (('utc',) if unix_time else ()) + FIELDS[1:])
        for r in rows:
            values = [getattr(r, k) for k in FIELDS]
            values = [round(v, 3) if isinstance(v, float) else v for v in values]
            w.writerow(values[:1] + ([_utc(r.t_s)] if unix_time else []) + values[1:])


def plot(path, rows, summary, n):
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    chosen = [d['mmsi'] for d in summary['targets'] if d['rows']][:n]
    if not chosen:
        return False
    t0 = min(r.t_s for r in rows if r.mmsi in chosen)
    fig, (ax_c, ax_t) = plt.subplots(2, 1, sharex=True, figsize=(10, 7))
    for d in summary['targets']:
        if d['mmsi'] not in chosen:
            continue
        mine = [r for r in rows if r.mmsi == d['mmsi']]
        x = [(r.t_s - t0) / 60.0 for r in mine]
        cpa = [r.cpa_m for r in mine]
        sig = [r.cpa_sigma_m for r in mine]
        label = f'{d["mmsi"]} {d["name"]}'.strip()
        line, = ax_c.plot(x, cpa, label=label)
        ax_c.fill_between(x, [c - s for c, s in zip(cpa, sig)], [c + s for c, s in zip(cpa, sig)],
                          color=line.get_color(), alpha=0.2, linewidth=0)
        ax_t.plot(x, [r.tcpa_s / 60.0 for r in mine], color=line.get_color())
    ax_c.set_ylabel('CPA distance (m), band +-1 sigma')
    ax_c.set_ylim(bottom=0.0)
    ax_t.axhline(0.0, color='k', linewidth=0.5)
    ax_t.set_ylabel('TCPA (min); < 0: opening')
    since = _utc(t0) if summary['log']['unix_time'] else f't = {t0:g} s'
    ax_t.set_xlabel(f'minutes since {since}')
    ax_c.legend(fontsize='small', ncol=2)
    ax_c.set_title(f'{len(chosen)} target(s) with the smallest CPA ahead; own ship: '
                   f'{summary["own_ship"]["source"]} {summary["own_ship"]["mmsi"] or ""}')
    for ax in (ax_c, ax_t):
        ax.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return True


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    ap, a = parse_args(argv)
    t_wall = time.perf_counter()

    def progress(done, total):
        print(f'{PROG}: {done}/{total} sentences replayed', file=sys.stderr, flush=True)

    try:
        log = read_log_file(a.log, a.rate)
        result = replay(log, a.own_mmsi, a.own_fixed, ReplayConfig(a.period, a.max_range),
                        progress)
    except (LogFormatError, ReplayError) as exc:
        ap.error(f'{a.log}: {exc}')
    a.out.mkdir(parents=True, exist_ok=True)
    summary = result.summary
    summary['provenance'] = {
        'command': ' '.join(shlex.quote(x) for x in ['scripts/ais_cpa.py', *argv]),
        'log': str(a.log), 'log_sha256': hashlib.sha256(a.log.read_bytes()).hexdigest()}
    write_csv(a.out / 'ais_cpa.csv', result.rows, log.unix_time)
    with open(a.out / 'ais_cpa.json', 'w') as f:
        json.dump(summary, f, indent=1)
        f.write('\n')
    plotted = a.plot_targets > 0 and plot(a.out / 'ais_cpa.png', result.rows, summary,
                                          a.plot_targets)
    rejected = sum(summary['log']['rejected'].values()) + sum(
        summary['decoder']['rejected'].values())
    print(f'{len(summary["targets"])} targets, {len(result.rows)} rows, {rejected} lines or '
          f'sentences rejected, in {time.perf_counter() - t_wall:.1f} s: {a.out}/ais_cpa.csv, '
          f'ais_cpa.json{", ais_cpa.png" if plotted else ""}')
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
