"""Section ``controllers``: Martinsen and Lekkas 2018's Table I for our controllers (scripts/evaluate_controllers.py).

Cumulative Gaussian reward per curved-path episode for LOS + PD, ILOS + PD, LOS + fuzzy PID,
the tuned LOS + fast PD + turn-rate lead, and the shipped DDPG policies, on the three MSS ships
at current 0 and 0.9 m/s, from the same fixed start states. The full run (5 starts, 1000 s) takes
~10 min on two cores; ``--quick`` runs 1 start for 300 s (a smoke run: its numbers are not
the results page's). The goal line is the issue's: the learned policy's reward is at least the best
classical controller's, per ship and current. The evaluation's own JSON and Markdown go to
bench/results/controllers.{json,md,html} next to bench.json.
"""
import os

from . import common


def run(quick=False):
    import evaluate_controllers as ec   # scripts/evaluate_controllers.py, beside bench.py

    models, controllers = ec.MODELS, ec.CONTROLLERS
    n_starts, duration = (1, 300.0) if quick else (5, 1000.0)
    _, results = ec.evaluate(models, n_starts, duration, controllers,
                             jobs=min(2, os.cpu_count() or 1))
    out = common.REPO / 'bench' / 'results' / 'controllers'
    out.parent.mkdir(parents=True, exist_ok=True)
    out.with_suffix('.md').write_text(ec.markdown(results, models, controllers, duration,
                                                  n_starts))
    ec.html_page(out.with_suffix('.html'), results, models, controllers, duration, n_starts)
    rows, goals, failed = [], [], False
    classical = [c for c in controllers if c != 'policy']
    for model in models:
        for current in ec.CURRENTS:
            cell = {c: results[f'{model}/{current}/{c}'] for c in controllers}
            failed |= any('error' in r for r in cell.values())
            score = {c: r.get('gaussian', float('nan')) for c, r in cell.items()}
            best = max(classical, key=lambda c: score[c])
            rows.append({'case': f'{model} {current:g} m/s',
                         **{c: round(score[c]) for c in controllers},
                         'best_classical': best,
                         'policy_mean_e': round(cell['policy'].get('mean_abs_e', float('nan')),
                                                1)})
            goals.append(common.goal(f'{model} {current:g} m/s: policy reward / best classical '
                                     f'({ec.LABELS[best]})', score['policy'] / score[best], 1.0,
                                     'ratio', below=False))
    columns = ([['case', 'ship, current']] + [[c, ec.LABELS[c]] for c in controllers]
               + [['best_classical', 'best classical'], ['policy_mean_e', 'policy mean|e| m']])
    return {'title': f'Table I of Martinsen and Lekkas 2018: cumulative Gaussian reward, {n_starts} start(s), '
                     f'{duration:g} s episodes (sum at 0.1 s)',
            'columns': columns, 'rows': rows, 'goals': goals, 'failed': failed,
            'notes': ['quick run: 1 start, 300 s; not comparable to the doc/results/wind_waves.md'] if quick
            else [], 'results': results}
