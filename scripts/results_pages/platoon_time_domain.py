"""Tables of the time-domain platoon checks (scripts/platoon_time_domain.py): the stability limit
in the time domain (its summary.json, doc/results/data/platoon_time_domain.json) and the
document's initial conditions (its thesis_ic.json, doc/results/data/platoon_thesis_ic.json),
both on doc/results/string_stability.md."""
import math

from results_pages.registry import table
from results_pages.tables import markdown_table


def _sign(x):
    return math.copysign(1.0, x) if math.isfinite(x) and x != 0.0 else 0.0


@table('platoon_time_domain', 'limits')
def limits(data):
    """Per model: the document's limit, the sampled loop's, and whether every fitted growth rate
    has the sign of the sampled loop's eigenvalue."""
    rows = []
    for m in data['models']:
        own = [r for r in data['rows'] if r['model'] == m['model']]
        rows.append({**m, 'ratio': m['d_crit_sampled_m'] / m['d_crit_doc_m'],
                     'signs': 'yes' if all(_sign(r['sigma_fit']) == _sign(r['re_lambda_sampled'])
                                           for r in own) else 'NO'})
    return markdown_table([
        ('model', 'model', ''), ('vessels', 'vessels', 'd'), ('zeta', 'zeta', 'g'),
        ('omega_n (rad/s)', 'omega_n', '.5f'), ('U (m/s)', 'speed', '.4f'),
        ("document's limit d*_doc = U / (2 zeta omega_n) (m)", 'd_crit_doc_m', '.2f'),
        ('limit of the sampled loop d*_sampled (m)', 'd_crit_sampled_m', '.2f'),
        ('d*_sampled / d*_doc', 'ratio', '.3f'),
        ('every fitted rate has the sign of the sampled eigenvalue', 'signs', ''),
    ], rows)


@table('platoon_time_domain', 'rates')
def rates(data):
    """Per model, limit and side: the look-ahead, the predicted rate (the real part of the
    sampled loop's dominant eigenvalue) against the range of the rates fitted to the vessels'
    envelopes, and the last vessel's largest deviation (a stable case: the leader's start
    amplified down the string; an unstable one: where the fit stopped)."""
    groups = {}
    for r in data['rows']:
        groups.setdefault((r['model'], r['reference'], r['case']), []).append(r)
    rows = []
    for (model, ref, case), rs in groups.items():
        fits = [r['sigma_fit'] for r in rs if math.isfinite(r['sigma_fit'])]
        last = max(rs, key=lambda r: r['vessel'])
        rows.append({'model': model, 'ref': ref, 'case': case,
                     'ratio': rs[0]['ratio_to_doc'], 'lookahead': rs[0]['lookahead_m'],
                     're': rs[0]['re_lambda_sampled'],
                     'fit_lo': min(fits) if fits else None, 'fit_hi': max(fits) if fits else None,
                     'max_last': last['max_abs_dev_m']})
    return markdown_table([
        ('model', 'model', ''), ('limit', 'ref', ''), ('side', 'case', ''),
        ('look-ahead / d*_doc', 'ratio', '.3f'), ('look-ahead (m)', 'lookahead', '.1f'),
        ('predicted rate Re lambda (1/s)', 're', '+.3e'),
        ('fitted rates, smallest (1/s)', 'fit_lo', '+.3e'),
        ('fitted rates, largest (1/s)', 'fit_hi', '+.3e'),
        ("last vessel's largest deviation (m)", 'max_last', '.2e'),
    ], rows)


@table('platoon_time_domain', 'nonlinear')
def nonlinear(data):
    """The cases below each limit run again without a stop: where the ship with its rudder limit
    ends (a limit cycle: the last period's amplitude per vessel; or diverged)."""
    rows = []
    for m in data['models']:
        for key, v in m['nonlinear_below'].items():
            amps = v['last_period_amplitude_m']
            stopped = v['stopped_at_s']
            rows.append({'model': m['model'], 'case': key.replace('_', ' '),
                         'lookahead': v['lookahead_m'], 'ran': v['ran_s'],
                         'end': (f'diverged at {stopped:.0f} s' if math.isfinite(stopped)
                                 else f'{min(amps):.1f} to {max(amps):.1f}')})
    return markdown_table([
        ('model', 'model', ''), ('case', 'case', ''), ('look-ahead (m)', 'lookahead', '.1f'),
        ('simulated (s)', 'ran', '.0f'),
        ("last period's amplitude over the vessels (m)", 'end', ''),
    ], rows)


@table('platoon_time_domain', 'amplification')
def amplification(data):
    """The follower's peak gain sup |G(i nu)| of the document model in the stable cases, and the
    spacing from which no disturbance is amplified."""
    rows = []
    for m in data['models']:
        gains = {k: v for k, v in m['peak_follower_gain'].items() if math.isfinite(v)}
        rows.append({'model': m['model'],
                     'gains': ', '.join(f'{k.replace("_", " ")} {v:.1f}'
                                        for k, v in gains.items()),
                     'spacing': m['no_amplification_spacing_m']})
    return markdown_table([
        ('model', 'model', ''), ("peak follower gain, where the document's model is stable", 'gains', ''),
        ('no amplification from a spacing of (m)', 'spacing', '.1f'),
    ], rows)


@table('platoon_thesis_ic', 'runs')
def thesis_ic_runs(data):
    """Two vessels from the document's initial conditions, per look-ahead ratio, figure and
    vessel: the linear model's fitted envelope rate against its eigenvalue, and the largest and
    final |y| (ship lengths) of the linear model and of the ship with its rudder limit."""
    return markdown_table([
        ('model', 'model', ''), ('d / d*', 'd_over_dstar', '.2f'), ('figure', 'figure', 'd'),
        ('initial condition', 'initial', ''), ('vessel', 'vessel', 'd'),
        ('linear: fitted rate (U/L)', 'sigma_fit_linear', '+.4f'),
        ('linear: Re lambda (U/L)', 're_lambda', '+.4f'),
        ('linear: largest abs y (L)', 'max_abs_y_linear', '.3g'),
        ('linear: final abs y (L)', 'final_abs_y_linear', '.3g'),
        ('ship: largest abs y (L)', 'max_abs_y_ship', '.3g'),
        ('ship: final abs y (L)', 'final_abs_y_ship', '.3g'),
    ], data['rows'])
