"""Tables of the degraded-sensor study (scripts/imazu_degraded.py, its results file):
doc/results/degraded_sensors.md."""
from results_pages.registry import table
from results_pages.tables import markdown_table


def _ais(v, key):
    a = v.get('ais')
    return None if a is None else a[key]


def _radar(v):
    r = v.get('radar')
    if r is None:
        return None
    return (f"scan {r['scan_period_s']:g} s, range sigma {r['range_sigma_m']:g} m, bearing "
            f"sigma {r['bearing_sigma_deg']:g} deg, P(detect) {r['detection_probability']:g} "
            f"within {r['detection_range_m'] / 1852.0:g} NM; confirmed after "
            f"{r['confirm_plots']} plots, deleted after {r['coast_s']:g} s without one")


@table('degraded_sensors', 'levels')
def levels(data):
    rows = [{'name': name, **v} for name, v in data['levels'].items()]
    return markdown_table([
        ('level', 'name', ''), ('in short', 'summary', ''),
        ('AIS class', lambda r: _ais(r, 'class'), ''),
        ('reports lost', lambda r: _ais(r, 'loss_probability'), '.0%'),
        ('mean burst (reports)', lambda r: _ais(r, 'mean_burst_length'), 'g'),
        ('position sigma m', lambda r: _ais(r, 'position_sigma_m'), 'g'),
        ('SOG sigma kn', lambda r: _ais(r, 'sog_sigma_kn'), 'g'),
        ('COG sigma deg', lambda r: _ais(r, 'cog_sigma_deg'), 'g'),
        ('latency s', lambda r: None if 'ais' not in r else
         f"{r['ais']['latency_s']:g}-{r['ais']['latency_s'] + r['ais']['latency_jitter_s']:g}",
         ''),
        ('antenna (fwd, stbd) m', lambda r: None if 'ais' not in r else
         '({:g}, {:g})'.format(*r['ais']['antenna_m']), ''),
        ('radar', _radar, ''),
    ], rows)


def _level_rows(data):
    """Per (ship/method, level): the group's totals and the sensing figures over its runs."""
    rows = []
    for key, by_level in data['groups'].items():
        ship, method = key.split('/')
        for lv, g in by_level.items():
            runs = [r for r in data['runs'] if r['ship'] == ship and r['method'] == method
                    and r['level'] == lv]
            err = [r['sensing']['position_error_m_rms'] for r in runs
                   if r['sensing'].get('position_error_m_rms') is not None]
            sig = [r['sensing']['position_sigma_m_max'] for r in runs
                   if r['sensing'].get('position_sigma_m_max') is not None]
            lost = sum(r['sensing'].get('ais_lost', 0) for r in runs)
            sent = sum(r['sensing'].get('ais_sent', 0) for r in runs)
            rows.append({'key': key, 'level': lv, **g,
                         'seeds': len({r['seed'] for r in runs}),
                         'err': sum(err) / len(err) if err else None,
                         'sigma': max(sig) if sig else None,
                         'lost': lost / sent if sent else None})
    return rows


@table('degraded_sensors', 'totals')
def totals(data):
    return markdown_table([
        ('ship / method', 'key', ''), ('level', 'level', ''), ('runs', 'runs', 'd'),
        ('seeds', 'seeds', 'd'), ('collisions (hull contact)', 'collisions', 'd'),
        ('near misses (ship domain)', 'near_misses', 'd'),
        ('targets below r_min', 'below_safe', 'd'),
        ('min distance m (case)', lambda r: f"{r['min_distance_m']:.0f} ({r['min_distance_case']})",
         ''),
        ('mean of the runs\' min distance m', 'mean_min_distance_m', '.0f'),
        ('runs with a last-resort decision', 'last_resort_runs', 'd'),
        ('limit hit', 'limit_hit', 'd'),
        ('AIS reports lost', 'lost', '.0%'),
        ('track error at the decisions, RMS m (mean of runs)', 'err', '.0f'),
        ('largest position sigma seen m', 'sigma', '.0f'),
    ], _level_rows(data))


@table('degraded_sensors', 'cases')
def cases(data):
    """Per case, per level: the smallest minimum distance over the seeds (m), '/' the largest,
    with C (collision) or N (near miss) and how many of its seeds had one."""
    out = []
    for key, by_level in data['groups'].items():
        names = list(by_level)

        def cell(g, case):
            c = g['cases'].get(str(case))
            if c is None:
                return None
            text = f"{c['min_distance_m']:.0f}"
            if c['seeds'] > 1:
                text += f" / {c['max_min_distance_m']:.0f}"
            flags = ''.join(f' {n} {f}' for n, f in (('C', c['collisions']),
                                                      ('N', c['near_misses'])) if f)
            return text + flags
        rows = [{'case': case, **{lv: cell(g, case) for lv, g in by_level.items()}}
                for case in data['cases']]
        out.append(f'**{key}**\n\n' + markdown_table(
            [('case', 'case', 'd')] + [(lv, lv, '') for lv in names], rows))
    return '\n'.join(out)


@table('degraded_sensors', 'breaks')
def breaks(data):
    rows = [{'key': key, 'level': lv, **b}
            for key, by_level in data['breaks'].items() for lv, b in by_level.items()]

    def listed(name):
        return lambda r: ', '.join(map(str, r[name])) or 'none'
    return markdown_table([
        ('ship / method', 'key', ''), ('level', 'level', ''),
        ('cases with a collision or near miss (any seed)',
         listed('cases_with_collision_or_near_miss'), ''),
        (f"cases below r_min = {data['r_min_m']:g} m that are not at perfect",
         listed('cases_newly_below_r_min'), ''),
        ('largest loss of min distance against perfect m (case)',
         lambda r: None if r['largest_loss_m'] is None else
         f"{r['largest_loss_m']:.0f} ({r['largest_loss_case']})", ''),
    ], rows)
