"""The claim checks of the seed scenarios (scripts/run_seed_scenarios.py, its results.json):
doc/results/seed_scenarios.md."""
from results_pages.registry import table


def _verdict(v):
    return 'n/a (a run it needs is missing)' if v is None else 'yes' if v else '**no**'


@table('seed_scenarios', 'claims')
def claims(data):
    """One row per claim the batch could check: the claim, whether the runs reproduce it, and
    the evidence, as the runner words them."""
    lines = ['| claim | reproduced | evidence |', '|---|---|---|']
    for c in data['claims']:
        cells = (c['claim'], _verdict(c['reproduced']), c['evidence'])
        lines.append('| ' + ' | '.join(s.replace('|', '\\|') for s in cells) + ' |')
    n_yes = sum(1 for c in data['claims'] if c['reproduced'])
    runs = data['runs']
    failed = [r['scenario'] for r in runs if r.get('outcome') not in ('completed', 'duration reached')]
    return ('\n'.join(lines) + f"\n\n{n_yes} of {len(data['claims'])} claims reproduced; "
            f"{len(runs)} runs" + (f", failed: {', '.join(failed)}" if failed else '')
            + f", {data['wall_time_s']:.0f} s wall.\n")


#: The course-change runs (run_seed_scenarios.py, ``course_*``) by name pattern: (ship, gains).
_COURSE_SETS = (('course_change_{a}_{c}_004', 'Mariner', 'gain table'),
                ('course_mariner_{a}_{c}_thesisgains_004', 'Mariner', 'Lee 2004'),
                ('course_tanker_{a}_{c}_004', 'tanker', 'gain table'),
                ('course_tanker_{a}_{c}_thesisgains_004', 'tanker', 'Lee 2004'))
_CONTROLLERS = (('pd', 'PD'), ('fuzzy', 'fuzzy PID'))
_ANGLES = (30, 45, 60, 90)


@table('seed_scenarios', 'course_changes')
def course_changes(data):
    """Every course-change run: the heading step response and the rudder's use from the step
    (the runs' metrics: overshoot, 2 % settling time or 'never', steady error, mean |rudder|,
    mean |rudder rate| = total variation per second, time at the limit)."""
    import math

    from results_pages.tables import markdown_table
    runs = {r['scenario']: r for r in data['runs']}
    rows = []
    for pattern, ship, gains in _COURSE_SETS:
        for code, controller in _CONTROLLERS:
            for a in _ANGLES:
                run = runs.get(pattern.format(a=a, c=code))
                if run is None:
                    continue
                m = run['metrics']
                rows.append({'ship': ship, 'controller': controller, 'gains': gains, 'angle': a,
                             **{k: m.get(k) for k in (
                                 'overshoot_rad', 'settling_time_s', 'steady_error_rad',
                                 'manoeuvre_rudder_mean_abs_rad',
                                 'manoeuvre_rudder_total_variation_rad_per_s',
                                 'manoeuvre_rudder_time_at_limit_s', 'duration_s')}})

    def deg(key, spec):
        return (lambda r: None if r[key] is None else math.degrees(r[key])), spec

    def settling(r):
        return 'never' if r['settling_time_s'] is None else f"{r['settling_time_s']:.0f}"
    return markdown_table([
        ('ship', 'ship', ''), ('controller', 'controller', ''), ('gains', 'gains', ''),
        ('course change deg', 'angle', 'd'), ('run s', 'duration_s', '.0f'),
        ('overshoot deg', *deg('overshoot_rad', '.1f')),
        ('settling s', settling, ''),
        ('steady error deg', *deg('steady_error_rad', '+.2f')),
        ('mean abs rudder deg', *deg('manoeuvre_rudder_mean_abs_rad', '.1f')),
        ('mean abs rudder rate deg/s', *deg('manoeuvre_rudder_total_variation_rad_per_s', '.3f')),
        ('rudder at the limit s', 'manoeuvre_rudder_time_at_limit_s', '.0f'),
    ], rows)


_GA_LAWS = (('tuned', 'tuned by the GA'), ('conventional', 'conventional LOS'),
            ('best_constant', 'best constant look-ahead'))


def _ga_cases(data):
    return [(name, data[name]) for name in ('coastal', 'oceanic') if name in data]


@table('seed_scenarios', 'ga_claims')
def ga_claims(data):
    """Lee 2004's claim per case: the GA-tuned look-ahead law beats conventional LOS in the
    cost it was tuned for (tracking on the coast, energy in the ocean)."""
    lines = ['| case | tuned law beats conventional LOS | costs: tuned, conventional, '
             'best constant |', '|---|---|---|']
    for name, r in _ga_cases(data):
        t, c, b = r['tuned']['cost'], r['conventional']['cost'], r['best_constant']['cost']
        lines.append(f"| {name} | {'yes' if t < c else '**no**'} | {t:.5g}, {c:.5g}, {b:.5g} |")
    return '\n'.join(lines) + '\n'


@table('seed_scenarios', 'ga_laws')
def ga_laws(data):
    """Per case, the tuned law's genes and the three laws' closed-loop figures."""
    from results_pages.tables import markdown_table
    rows = []
    for name, r in _ga_cases(data):
        t = r['tuned']
        law = (f"t_min {t['t_min_s']:.1f} s, t_max {t['t_max_s']:.1f} s, e_s {t['e_scale_m']:.0f} m "
               f"(on the path {t['lookahead_on_path_m']:.0f} m; stability limit "
               f"{r['critical_lookahead_m']:.0f} m)")
        for key, label in _GA_LAWS:
            m = r[key]
            rows.append({'case': name, 'law': label,
                         'look-ahead': law if key == 'tuned' else f"{m['lookahead_m']:.0f} m",
                         **m})
    return markdown_table([
        ('case', 'case', ''), ('law', 'law', ''), ('look-ahead', 'look-ahead', ''),
        ('cost', 'cost', '.5g'), ('RMS cross-track m', 'xte_rms_m', '.1f'),
        ('max cross-track m', 'xte_max_abs_m', '.1f'), ('rudder RMS deg', 'rudder_rms_deg', '.2f'),
        ('mean abs rudder rate deg/s', 'rudder_rate_mean_abs_deg_s', '.3f'),
        ('energy proxy', 'energy_proxy', '.4f'), ('time s', 'time_s', '.0f'),
    ], rows)
