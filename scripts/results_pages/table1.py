"""Table I of Martinsen and Lekkas 2018 for our controllers (scripts/evaluate_controllers.py):
doc/results/ddpg.md."""
from results_pages.registry import table
from results_pages.tables import fmt


def _columns(data):
    return [(m, c) for m in data['models'] for c in data['currents']]


def _table(data, cell, paper=True):
    cols = _columns(data)
    lines = ['| controller | ' + ' | '.join(f'{m} {c:g} m/s' for m, c in cols) + ' |',
             '|---|' + '---:|' * len(cols)]
    if paper:
        for name, by_model in data['seed_table'].items():
            lines.append(f'| paper: {name} | ' + ' | '.join(
                str(by_model[m][data['currents'].index(c)]) for m, c in cols) + ' |')
    for ctrl, label in data['controllers'].items():
        cells = []
        for m, c in cols:
            r = data['results'].get(f'{m}/{c}/{ctrl}')
            cells.append('-' if r is None else 'error' if 'error' in r else cell(r))
        lines.append(f'| {label} | ' + ' | '.join(cells) + ' |')
    return '\n'.join(lines) + '\n'


@table('table1', 'reward')
def reward(data):
    """Cumulative Gaussian reward per episode, mean over the start states."""
    return _table(data, lambda r: fmt(r['gaussian'], '.0f'))


@table('table1', 'tracking')
def tracking(data):
    """Mean / max |cross-track error| (m) and mean |rudder rate| (deg/s)."""
    return _table(data, lambda r: f"{fmt(r['mean_abs_e'], '.1f')} / {fmt(r['max_abs_e'], '.0f')}"
                                  f" / {fmt(r['rudder_rate_deg_s'], '.2f')}", paper=False)


@table('table1', 'settings')
def settings(data):
    return (f"{len(data['starts'])} start states per ship and current (the same for every "
            f"controller), {data['duration_s']:g} s episodes, reward summed every "
            f"{data['sim_dt_s']:g} s (maximum {data['duration_s'] / data['sim_dt_s']:.0f}); "
            f"wall time of the run {data['wall_s']:g} s.\n")


@table('table1', 'policy_vs_classical')
def policy_vs_classical(data):
    """Per column: the best classical controller by reward, and the policy's reward, mean
    |cross-track error| and rudder activity as multiples of that controller's."""
    lines = ['| ship, current | best classical controller | policy reward / its reward | '
             'its mean abs(e) / policy mean abs(e) | policy rudder rate / its rudder rate |',
             '|---|---|---:|---:|---:|']
    for m, c in _columns(data):
        res = {ctrl: data['results'].get(f'{m}/{c}/{ctrl}') for ctrl in data['controllers']}
        res = {k: r for k, r in res.items() if r is not None and 'error' not in r}
        if 'policy' not in res or len(res) < 2:
            continue
        best = max((k for k in res if k != 'policy'), key=lambda k: res[k]['gaussian'])
        b, p = res[best], res['policy']
        lines.append(f"| {m} {c:g} m/s | {data['controllers'][best]} | "
                     f"{fmt(p['gaussian'] / b['gaussian'], '.1f')} | "
                     f"{fmt(b['mean_abs_e'] / p['mean_abs_e'], '.1f')} | "
                     f"{fmt(p['rudder_rate_deg_s'] / b['rudder_rate_deg_s'], '.1f')} |")
    return '\n'.join(lines) + '\n'
