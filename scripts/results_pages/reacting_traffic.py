"""Tables of the target-behaviour study (scripts/imazu_behaviours.py):
doc/results/reacting_traffic.md."""
from results_pages.registry import table
from results_pages.tables import markdown_table


def _alteration(row):
    return ', '.join(f'{n} {v:+.0f}' for n, v in row['target_alteration_deg'].items())


@table('reacting_traffic', 'runs')
def runs(data):
    return markdown_table([
        ('case', 'case', 'd'), ('targets (own view)', 'targets', ''),
        ('behaviour', 'behaviour', ''), ('own ship', 'ship', ''), ('method', 'method', ''),
        ('collisions', 'collisions', 'd'), ('near misses', 'near_misses', 'd'),
        ('min distance m', 'min_distance_m', '.0f'), ('rule score', 'rule_score', '.3f'),
        ('path deviation m', 'path_deviation_m', '.0f'),
        ('target alteration deg (+ starboard)', _alteration, ''),
        ('last-resort decisions', 'last_resort_decisions', 'd'), ('run end', 'run_end', ''),
    ], data['runs'])


@table('reacting_traffic', 'summary')
def summary(data):
    """Per behaviour and ship/method: runs, totals, the smallest distance, mean score and
    deviation (each behaviour over the cases it applies to)."""
    groups = {}
    for r in data['runs']:
        groups.setdefault((r['behaviour'], r['ship'], r['method']), []).append(r)
    rows = [{'behaviour': b, 'ship': s, 'method': m, 'runs': len(g),
             'cases': ', '.join(str(r['case']) for r in g),
             'collisions': sum(r['collisions'] for r in g),
             'near_misses': sum(r['near_misses'] for r in g),
             'min_distance_m': min(r['min_distance_m'] for r in g),
             'rule_score': sum(r['rule_score'] for r in g) / len(g),
             'path_deviation_m': sum(r['path_deviation_m'] for r in g) / len(g)}
            for (b, s, m), g in groups.items()]
    return markdown_table([
        ('behaviour', 'behaviour', ''), ('own ship', 'ship', ''), ('method', 'method', ''),
        ('runs', 'runs', 'd'), ('cases', 'cases', ''), ('collisions', 'collisions', 'd'),
        ('near misses', 'near_misses', 'd'), ('min distance m', 'min_distance_m', '.0f'),
        ('rule score (mean)', 'rule_score', '.3f'),
        ('path deviation m (mean)', 'path_deviation_m', '.0f'),
    ], rows)


@table('reacting_traffic', 'breaks')
def breaks(data):
    """The runs in which the own ship came inside a target's domain (near miss) or hull
    (collision), took a last-resort decision or lost rule score: where the own ship breaks."""
    rows = [r for r in data['runs'] if r['collisions'] or r['near_misses']
            or r['last_resort_decisions'] or r['rule_score'] < 1.0]
    if not rows:
        return ('No run ended in a collision, a near miss, a last-resort decision or a rule '
                'penalty.\n')
    return markdown_table([
        ('case', 'case', 'd'), ('behaviour', 'behaviour', ''), ('own ship', 'ship', ''),
        ('method', 'method', ''), ('collisions', 'collisions', 'd'),
        ('near misses', 'near_misses', 'd'), ('min distance m', 'min_distance_m', '.0f'),
        ('rule score', 'rule_score', '.3f'),
        ('last-resort decisions', 'last_resort_decisions', 'd'),
    ], rows)


@table('reacting_traffic', 'settings')
def settings(data):
    s = data['settings']
    rows = [{'what': 'turns_to_port: trigger range (m)', 'value': f"{s['turns_to_port_trigger_range_m']:.0f}"},
            {'what': 'turns_to_port: port turn (deg)', 'value': f"{s['turns_to_port_turn_deg']:.0f}"},
            {'what': 'cases', 'value': ', '.join(map(str, s['cases']))},
            {'what': 'own ships', 'value': ', '.join(s['ships'])},
            {'what': 'methods', 'value': ', '.join(s['methods'])},
            {'what': 'longest run (s sim)', 'value': f"{s['limit_s']:.0f}"},
            {'what': 'mean run (s wall)', 'value': f"{s['run_wall_s_mean']:.0f}"}]
    rows += [{'what': f'{b} applies to targets seen from themselves as', 'value': ', '.join(v)}
             for b, v in s['applies'].items()]
    return markdown_table([('setting', 'what', ''), ('value', 'value', '')], rows)
