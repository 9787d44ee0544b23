"""Tables of an encounter set's benchmark (scripts/imazu_benchmark.py folders merged by
scripts/imazu_results.py): doc/results/imazu.md for the Imazu cases, doc/results/dnv.md for
DNV's baseline situations (the same tables, registered under both names)."""
from results_pages.registry import table
from results_pages.tables import markdown_table

#: The command that runs one set; the page lists it for every set not yet run.
RUN_COMMAND = ('.venv/bin/python scripts/imazu_benchmark.py{set_option} --ships {ship} '
               '--methods {method} --jobs 2 --no-plots --out runs')


def _set_option(data):
    name = data.get('set', 'imazu')
    return '' if name == 'imazu' else f' --set {name}'


def _seconds(value):
    return 'never' if value is None else f'{value:.0f}'


def _first_action_mean(cases):
    """Mean time of the first manoeuvre over the cases with one, and how many had none."""
    starts = [c['first_action_s'] for c in cases.values() if c['first_action_s'] is not None]
    return (sum(starts) / len(starts) if starts else None), len(cases) - len(starts)


@table('imazu', 'totals')
def totals(data):
    rows = []
    for key, s in data['sets'].items():
        first, none = _first_action_mean(s['cases'])
        rows.append({'key': key, **s['totals'], 'first': first, 'no_action': none})
    return markdown_table([
        ('ship / method', 'key', ''), ('runs', 'runs', 'd'),
        ('collisions (hull contact)', 'collisions', 'd'),
        ('near misses (ship domain)', 'near_misses', 'd'), ('below r_min', 'below_safe', 'd'),
        ('min distance m', 'min_distance_m', '.0f'), ('rule score (all)', 'rule_score_mean', '.3f'),
        ('rule score (single-target cases)', 'rule_score_single_target_mean', '.3f'),
        ('path deviation m (mean)', 'path_deviation_m_mean', '.0f'),
        ('time lost s (mean)', 'time_lost_s_mean', '.0f'),
        ('first action s (mean)', 'first', '.0f'), ('no action found', 'no_action', 'd'),
        ('back on route s (mean)', 'return_to_route_s_mean', '.0f'),
        ('never back on route', 'never_back_on_route', 'd'), ('limit hit', 'limit_hit', 'd'),
    ], rows)


@table('imazu', 'runs')
def runs(data):
    """Where each set's numbers come from: its run's command, code and load."""
    rows = [{'key': key, **s['run'], 'commit': s['run']['commit'][:10]
             + (f" (scored at {s['run']['rescored_at_commit'][:10]})"
                if s['run'].get('rescored_at_commit') else '')}
            for key, s in data['sets'].items()]
    return markdown_table([
        ('ship / method', 'key', ''), ('command', lambda r: f"`{r['command']}`", ''),
        ('commit', lambda r: f"`{r['commit']}`", ''), ('started (UTC)', 'date_utc', ''),
        ('1-minute load at the start', 'load_1min', '.1f'), ('CPUs', 'cpus', 'd'),
        ('run limit s', 'limit_s', '.0f'), ('wall time per run s (mean)', 'run_wall_s_mean', '.0f'),
        ('wall time per decision ms (mean)', 'decision_ms_mean', '.1f'),
    ], rows)


@table('imazu', 'not_run')
def not_run(data):
    if not data['not_run']:
        return 'Every ship/method set is run.\n'
    lines = ['Not yet run (each set is one command, then `.venv/bin/python scripts/imazu_results.py'
             f"{_set_option(data)}` with every finished folder and "
             '`.venv/bin/python scripts/render_results.py`):', '']
    for key in data['not_run']:
        ship, method = key.split('/')
        command = RUN_COMMAND.format(set_option=_set_option(data), ship=ship, method=method)
        lines.append(f'- {key}: `{command}`')
    return '\n'.join(lines) + '\n'


def _penalties(case):
    return '; '.join(f"{n}: {', '.join(p)}" for n, p in sorted(case['penalties'].items()))


@table('imazu', 'cases')
def cases(data):
    """One table per set: every case's figures, the penalties per target and how it ended."""
    out = []
    for key, s in data['sets'].items():
        rows = [{'case': int(c), 'targets': ', '.join(data['cases'][c]), **v}
                for c, v in s['cases'].items()]
        out.append(f'**{key}**\n\n' + markdown_table([
            ('case', 'case', 'd'), ('targets (own view)', 'targets', ''),
            ('collisions', 'collisions', 'd'), ('near misses', 'near_misses', 'd'),
            ('min distance m', 'min_distance_m', '.0f'), ('rule score', 'rule_score', '.2f'),
            ('penalties', _penalties, ''), ('path deviation m', 'path_deviation_m', '.0f'),
            ('time lost s', 'time_lost_s', '.0f'),
            ('first action s', lambda r: _seconds(r['first_action_s']), ''),
            ('back on route s', lambda r: _seconds(r['return_to_route_s']), ''),
            ('run end s', lambda r: f"{r['run_end']} {r['run_end_s']:.0f}", ''),
        ], rows))
    return '\n'.join(out)


@table('imazu', 'by_case')
def by_case(data):
    """Per case, 'min distance m / rule score' of every set side by side."""
    keys = list(data['sets'])

    def cell(key, c):
        v = data['sets'][key]['cases'].get(c)
        return None if v is None else f"{v['min_distance_m']:.0f} / {v['rule_score']:.2f}"
    rows = [{'case': int(c), 'targets': ', '.join(t), **{k: cell(k, c) for k in keys}}
            for c, t in data['cases'].items()]
    return markdown_table([('case', 'case', 'd'), ('targets (own view)', 'targets', '')]
                          + [(k, (lambda r, k=k: r[k]), '') for k in keys], rows)


#: Issue 13's goal for SB-MPC: no collision and no near miss on any case, and at least this mean
#: rule score on the single-target cases.
SINGLE_TARGET_SCORE_GOAL = 0.95


@table('imazu', 'goals')
def goals(data):
    """Issue 13's goal per set (it is set for SB-MPC; the other method is shown against it)."""
    rows = []
    for key, s in data['sets'].items():
        t = s['totals']
        unsafe = t['collisions'] + t['near_misses']
        single = t['rule_score_single_target_mean']
        rows.append({'key': key, 'unsafe': unsafe, 'single': single,
                     'met': 'yes' if unsafe == 0 and single is not None
                     and single >= SINGLE_TARGET_SCORE_GOAL else '**no**'})
    return markdown_table([
        ('ship / method', 'key', ''), ('collisions + near misses (goal 0)', 'unsafe', 'd'),
        (f'rule score, single-target cases (goal >= {SINGLE_TARGET_SCORE_GOAL:g})', 'single',
         '.3f'),
        ('met', 'met', ''),
    ], rows)


# DNV's baseline situations: the same tables over doc/results/data/dnv.json.
for _fn in (totals, runs, not_run, cases, by_case, goals):
    table('dnv', _fn.__name__)(_fn)
