"""Tables of the Imazu cases beside a coast (scripts/imazu_land.py): doc/results/land.md."""
from results_pages.registry import table
from results_pages.tables import markdown_table


def _yes(value):
    return 'yes' if value else 'no'


@table('land', 'runs')
def runs(data):
    return markdown_table([
        ('case', 'case', 'd'), ('targets (own view)', 'targets', ''),
        ('coast in the cost', 'land_in_cost', _yes), ('collisions', 'collisions', 'd'),
        ('near misses', 'near_misses', 'd'), ('below safe distance', 'below_safe', 'd'),
        ('min distance to target m', 'min_distance_m', '.0f'),
        ('min distance to land m', 'min_land_distance_m', '.0f'), ('grounded', 'grounded', _yes),
        ('time on land s', 'time_on_land_s', '.0f'),
        ('farthest to starboard m', 'max_starboard_m', '.0f'),
        ('rule score', 'rule_score', '.3f'), ('path deviation m', 'path_deviation_m', '.0f'),
        ('last-resort decisions', 'last_resort_decisions', 'd'), ('run end', 'run_end', ''),
    ], data['runs'])


@table('land', 'changes')
def changes(data):
    """Per case and ship: what putting the coast into SB-MPC's cost changed (with minus without)."""
    pairs = {}
    for r in data['runs']:
        pairs.setdefault((r['case'], r['ship']), {})[r['land_in_cost']] = r
    rows = []
    for (case, ship), p in sorted(pairs.items()):
        if set(p) != {False, True}:
            continue
        off, on = p[False], p[True]
        rows.append({'case': case, 'ship': ship,
                     'grounded': f"{_yes(off['grounded'])} / {_yes(on['grounded'])}",
                     'd_target': on['min_distance_m'] - off['min_distance_m'],
                     'd_land': f"{off['min_land_distance_m']:.0f} / {on['min_land_distance_m']:.0f}",
                     'd_starboard': on['max_starboard_m'] - off['max_starboard_m'],
                     'd_score': on['rule_score'] - off['rule_score'],
                     'd_deviation': on['path_deviation_m'] - off['path_deviation_m'],
                     'safety': f"{off['collisions'] + off['near_misses']} / "
                               f"{on['collisions'] + on['near_misses']}",
                     'below_safe': f"{off['below_safe']} / {on['below_safe']}"})
    return markdown_table([
        ('case', 'case', 'd'), ('own ship', 'ship', ''),
        ('grounded (without / with)', 'grounded', ''),
        ('min distance to land m (without / with)', 'd_land', ''),
        ('collisions + near misses (without / with)', 'safety', ''),
        ('targets passed below the safe distance (without / with)', 'below_safe', ''),
        ('change in min distance to target m', 'd_target', '+.0f'),
        ('change in farthest to starboard m', 'd_starboard', '+.0f'),
        ('change in rule score', 'd_score', '+.3f'),
        ('change in path deviation m', 'd_deviation', '+.0f'),
    ], rows)


@table('land', 'settings')
def settings(data):
    s = data['settings']
    rows = [{'what': 'coast: distance to starboard of the route (m)', 'value': f"{s['coast_offset_m']:.0f}"},
            {'what': 'channel through the coast (north, m)',
             'value': f"{s['channel_north_m'][0]:.0f} to {s['channel_north_m'][1]:.0f}"},
            {'what': 'chart cell (m)', 'value': f"{s['chart_resolution_m']:g}"},
            {'what': 'grounding clearance (m)', 'value': f"{s['grounding_clearance_m']:.1f}"},
            {'what': 'grounding weight / collision weight',
             'value': f"{s['w_grounding']:g} / {s['w_collision']:g}"},
            {'what': 'method', 'value': s['method']},
            {'what': 'cases', 'value': ', '.join(map(str, s['cases']))},
            {'what': 'own ships', 'value': ', '.join(s['ships'])},
            {'what': 'longest run (s sim)', 'value': f"{s['limit_s']:.0f}"},
            {'what': 'mean run (s wall)', 'value': f"{s['run_wall_s_mean']:.0f}"}]
    return markdown_table([('setting', 'what', ''), ('value', 'value', '')], rows)
