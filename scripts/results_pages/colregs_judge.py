"""Tables of the COLREGs judge comparison (scripts/colregs_judge.py): doc/results/colregs_judge.md.
One agreement table and one list of disagreements per reading of the monitor's time intervals
('seconds': as the package ships; 'steps': counts of 10 s samples)."""
from results_pages.registry import table
from results_pages.tables import markdown_table

CLASS_TITLES = (('both compliant', 'both_compliant'), ('both violating', 'both_violating'),
                ('ours only, their rule not triggered', 'ours_only_not_triggered'),
                ('ours only, triggered', 'ours_only_triggered'), ('theirs only', 'theirs_only'))


def agreement_rows(data, reading):
    """Rows (set, rule, counts) of one reading: every set, then all sets together; rules that
    no target of a set meets are left out."""
    res = data['readings_result'][reading]
    titles = {r['id']: f"{r['title']} / {r['their_rule']}" for r in data['rules']}
    rows = []
    for name, per_rule in [*sorted(res['sets'].items()), ('all sets', res['all'])]:
        if name == 'all sets' and len(res['sets']) < 2:
            continue
        for rid, c in per_rule.items():
            if c['n']:
                rows.append({'set': name, 'rule': titles[rid], **c})
    return rows


def _agreement(data, reading):
    cols = [('set', 'set', ''), ('rule (ours / theirs)', 'rule', ''), ('pairs', 'n', 'd'),
            ('agree', 'agree', 'd'), ('agreement', 'agreement', '.2f')]
    cols += [(title, key, 'd') for title, key in CLASS_TITLES]
    return markdown_table(cols, agreement_rows(data, reading))


def disagreement_rows(data, reading):
    titles = {r['id']: r['their_rule'] for r in data['rules']}
    rows = []
    for p in data['readings_result'][reading]['pairs']:
        if p['ours'] == p['theirs']:
            continue
        rows.append({**p, 'rule': titles[p['row']],
                     'our_verdict': ', '.join(p['penalties']) or ('near miss' if p['near_miss']
                                                                  else 'compliant'),
                     'their_verdict': 'compliant' if p['theirs'] else 'violated',
                     'other': ', '.join(p['their_other_violations']) or '-'})
    return sorted(rows, key=lambda r: (r['set'], r['case'], r['target'], r['row']))


def _disagreements(data, reading):
    rows = disagreement_rows(data, reading)
    if not rows:
        return 'No disagreement.\n'
    return markdown_table([
        ('set', 'set', ''), ('case', 'case', 'd'), ('target', 'target', ''),
        ('situation (case file)', 'situation', ''), ('their rule', 'rule', ''),
        ('ours (penalties)', 'our_verdict', ''), ('theirs', 'their_verdict', ''),
        ('class', 'class', ''), ('samples their situation held', 'their_situation_samples', 'd'),
        ('their other rules violated', 'other', '')], rows)


@table('colregs_judge', 'agreement_seconds')
def agreement_seconds(data):
    return _agreement(data, 'seconds')


@table('colregs_judge', 'agreement_steps')
def agreement_steps(data):
    return _agreement(data, 'steps')


@table('colregs_judge', 'disagreements_seconds')
def disagreements_seconds(data):
    return _disagreements(data, 'seconds')


@table('colregs_judge', 'disagreements_steps')
def disagreements_steps(data):
    return _disagreements(data, 'steps')


@table('colregs_judge', 'setup')
def setup(data):
    from imazu.cases import load_cases       # the cases the judge reads (colregs_judge.py)
    judged = data.get('cases') or data.get('cases_in_run_dir')
    rows = [{'what': 'runs judged', 'value': str(data['runs'])}]
    if judged is not None:
        # the set's cases, not the run folder's: a folder may hold a few cases only
        rows.append({'what': 'cases judged', 'value': ', '.join(map(str, judged))})
        rows.append({'what': 'Imazu cases not judged yet',
                     'value': ', '.join(str(c) for c in sorted(load_cases())
                                        if c not in judged) or 'none'})
    rows += [{'what': 'sets (ship/method)',
              'value': ', '.join(sorted(data['readings_result']['seconds']['sets']))},
             {'what': 'monitor package', 'value': f"commonocean-rules {data['package']}"},
             {'what': 'track sample spacing given to the monitor (s)', 'value': f"{data['dt_s']:g}"},
             {'what': 'monitor wall time, all runs, on a loaded machine (s)',
              'value': f"{data['monitor_wall_s']:.0f}"}]
    return markdown_table([('', 'what', ''), ('', 'value', '')], rows)
