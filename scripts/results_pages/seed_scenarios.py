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
