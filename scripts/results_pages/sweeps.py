"""A Monte Carlo sweep's summary (scripts/sweep.py's summary.json): doc/results/sweeps.md.

The cells come as sweep.py formats them (montecarlo.results.summary_rows, the same text as
summary.md and index.html); this lays them out with the run's size and time."""
from results_pages.registry import table


@table('sweeps', 'summary')
def summary(data):
    """The summary table of one sweep run, with how many episodes it ran and how long it took."""
    t, run = data['table'], data['run']
    # a break opportunity after each underscore: the column names are long snake_case words,
    # which would otherwise widen the table past the page
    lines = ['| ' + ' | '.join(h.replace('_', '_<wbr>') for h in t['header']) + ' |',
             '|' + '---|' * len(data['group_by']) + '---:|' * (len(t['header']) - len(data['group_by']))]
    lines += ['| ' + ' | '.join(cells) + ' |' for cells in t['rows']]
    per_cell = data['episodes_per_cell']
    return (f"`{data['sweep']}`, seed {data['seed']}: {per_cell} episode{'s' * (per_cell != 1)} "
            f"per grid cell, {run['episodes']} in all, in {run['wall_s']:.0f} s on {run['workers']} "
            f"workers. {t['caption']}\n\n" + '\n'.join(lines) + '\n')
