"""Tables of the failure search (scripts/failure_search.py): doc/results/failure_search.md."""
from results_pages.registry import table
from results_pages.tables import markdown_table

LABELS = {'uniform': 'uniform Monte Carlo', 'cross_entropy': 'cross-entropy method'}


@table('failure_search', 'settings')
def settings(data):
    s = data['settings']
    rows = [('own ship', s['ship']), ('collision avoidance', s['method']),
            ('simulations per sampler (the budget)', s['budget']),
            ('simulations per generation', s['generation']), ('seed', s['seed']),
            ('failure: evaluator domain index below', s['failure_level']),
            ('longest run (s sim)', f"{s['limit_s']:.0f}"),
            ('wall time of the whole study (s)', f"{data['wall_s']:.0f}")]
    return markdown_table([('setting', 0, ''), ('value', 1, '')],
                          [dict(enumerate(r)) for r in rows])


@table('failure_search', 'box')
def box(data):
    """The searched box: colav_search.encounter's (the code's, not the results file's)."""
    from colav_search import encounter
    specs = [encounter.MEETING] + [(f'per target: {n}', lo, hi, c)
                                   for n, lo, hi, c in encounter.PER_TARGET]
    rows = [{'name': 'target count', 'low': min(encounter.TARGET_COUNTS),
             'high': max(encounter.TARGET_COUNTS), 'circular': 'categorical'}]
    rows += [{'name': n, 'low': lo, 'high': hi, 'circular': 'yes' if c else 'no'}
             for n, lo, hi, c in specs]
    rows.append({'name': 'smallest start range m (rejected below)',
                 'low': encounter.MIN_START_RANGE_M, 'high': None, 'circular': ''})
    return markdown_table([('parameter', 'name', ''), ('low', 'low', 'g'),
                           ('high', 'high', 'g'), ('circular', 'circular', '')], rows)


@table('failure_search', 'comparison')
def comparison(data):
    rows = [{'sampler': LABELS.get(k, k), **v} for k, v in data['samplers'].items()]
    return markdown_table([
        ('sampler', 'sampler', ''), ('simulations', 'sims', 'd'), ('failures', 'failures', 'd'),
        ('distinct failures', 'distinct_failures', 'd'), ('collisions', 'collisions', 'd'),
        ('failures per 1,000 sims', 'failures_per_1000', '.0f'),
        ('distinct failures per 1,000 sims', 'distinct_failures_per_1000', '.0f'),
        ('first failure at sim', 'first_failure_sim', 'd'),
        ('smallest domain index', 'min_domain_index', '.3f'),
        ('smallest distance m', 'min_distance_m', '.0f'),
        ('wall time per sim s (mean)', 'wall_s_mean', '.1f'),
        ('sim time per run s (mean)', 'sim_s_mean', '.0f'),
    ], rows)


def _targets(f):
    return '; '.join(f"{t['situation']} from {t['approach_bearing_deg']:.0f} deg, course "
                     f"{t['course_rel_deg']:+.0f}, speed x{t['speed_ratio']:.2f}, CPA "
                     f"{t['cpa_m']:+.0f} m" for t in f['targets'])


@table('failure_search', 'failures')
def failures(data):
    """Every distinct failure of each sampler (the others are within the tolerance of one)."""
    rows = [{'sampler': LABELS.get(k, k), **f, 'described': _targets(f)}
            for k, v in data['samplers'].items() for f in v['failure_list'] if f['distinct']]
    if not rows:
        return 'No failure was found.\n'
    return markdown_table([
        ('sampler', 'sampler', ''), ('sim', lambda r: r['index'] + 1, 'd'),
        ('generation', 'generation', 'd'), ('meeting s', 'meeting_s', '.0f'),
        ('targets (situation, approach bearing, relative course, speed ratio, CPA offset)',
         'described', ''),
        ('min distance m', 'min_distance_m', '.0f'), ('at s', 't_min_s', '.0f'),
        ('domain index', 'domain_index', '.3f'), ('collision', 'collision', ''),
        ('scenario', lambda r: f"`{r['scenario']}`", ''),
    ], rows)


@table('failure_search', 'levels')
def levels(data):
    """The cross-entropy method's level and elite count per generation."""
    ce = data['samplers'].get('cross_entropy', {})
    rows = [{'generation': g, **lv} for g, lv in enumerate(ce.get('levels', []))]
    return markdown_table([('generation', 'generation', 'd'),
                           ('level gamma (domain index)', 'gamma', '.3f'),
                           ('elites', 'elites', 'd')], rows)
