"""Figures of the Imazu benchmark: per case (tracks with time marks, range to each target) and a
summary (minimum distance and rule score over cases x ship/method)."""
import numpy as np

MARK_S = 300.0   # time marks every 5 min


def case_figure(path, case_no, runs, references, params, dims):
    """``runs``: {(ship, method): RunResult}; ``references``: {ship: RunResult}; ``dims``:
    {ship: ShipDimensions} (the range plot marks r_min and the ship domain's semi-axes, ahead
    and abeam: a target inside the abeam one at the side is a near miss)."""
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    keys = sorted(runs)
    fig, axes = plt.subplots(2, len(keys), figsize=(3.2 * len(keys), 7.0), squeeze=False)
    for j, key in enumerate(keys):
        r = runs[key]
        ax, ax_r = axes[0, j], axes[1, j]
        ref = references.get(key[0])
        if ref is not None:
            ax.plot(ref.own[:, 1], ref.own[:, 0], ':', color='0.6', lw=1, label='no traffic')
        marks = np.flatnonzero(np.isclose(np.mod(r.t + 1e-6, MARK_S), 0.0, atol=1e-3))
        ax.plot(r.own[:, 1], r.own[:, 0], 'k-', lw=1.3, label='own')
        ax.plot(r.own[marks, 1], r.own[marks, 0], 'k.', ms=5)
        for i, (name, tr) in enumerate(sorted(r.targets.items())):
            c = f'C{i}'
            ax.plot(tr[:, 1], tr[:, 0], '-', color=c, lw=1, label=name)
            ax.plot(tr[marks, 1], tr[marks, 0], '.', color=c, ms=5)
            d = np.hypot(tr[:, 0] - r.own[:, 0], tr[:, 1] - r.own[:, 1])
            ax_r.plot(r.t, d, color=c, label=name)
        for m in marks[1:]:
            ax.annotate(f'{r.t[m] / 60:.0f}', (r.own[m, 1], r.own[m, 0]), fontsize=6,
                        xytext=(3, -3), textcoords='offset points')
        ax.set_aspect('equal', adjustable='datalim')
        ax.set_title(f'{key[0]} {key[1]}', fontsize=9)
        ax.set_xlabel('east [m]', fontsize=8)
        ax.tick_params(labelsize=7)
        length = dims[key[0]].length_m
        for radius, style, label in ((params.r_min_m, '--', 'r_min'),
                                     (params.domain_along * length, '-.', 'domain ahead'),
                                     (params.domain_across * length, ':', 'domain abeam')):
            ax_r.axhline(radius, ls=style, color='r', lw=0.8, label=label)
        ax_r.set_ylim(0, 4000)
        ax_r.set_xlabel('t [s]', fontsize=8)
        ax_r.tick_params(labelsize=7)
    axes[0, 0].set_ylabel('north [m]  (dots every 5 min)', fontsize=8)
    axes[1, 0].set_ylabel('range to target [m]', fontsize=8)
    axes[0, 0].legend(fontsize=6)
    axes[1, 0].legend(fontsize=6)
    fig.suptitle(f'Imazu case {case_no}', fontsize=11)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def summary_figure(path, rows, params):
    """Heat maps over cases (rows) x ship/method (columns): run minimum distance, rule score."""
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    from matplotlib.colors import BoundaryNorm, ListedColormap
    cases = sorted({r['case'] for r in rows})
    cols = sorted({(r['ship'], r['method']) for r in rows}, key=lambda k: (k[1], k[0]))
    dmin = np.full((len(cases), len(cols)), np.nan)
    verdict = np.full((len(cases), len(cols)), np.nan)
    score = np.full((len(cases), len(cols)), np.nan)
    for r in rows:
        i, j = cases.index(r['case']), cols.index((r['ship'], r['method']))
        dmin[i, j] = r['run_min_distance_m']
        verdict[i, j] = (0 if r['collisions'] else 1 if r['near_misses'] else
                         2 if r['below_safe'] else 3)
        score[i, j] = r['run_rule_score']
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 7))
    cmap = ListedColormap(['black', 'red', 'orange', 'tab:green'])
    a1.imshow(verdict, cmap=cmap, norm=BoundaryNorm([-0.5, 0.5, 1.5, 2.5, 3.5], cmap.N),
              aspect='auto')
    im = a2.imshow(score, cmap='RdYlGn', vmin=0, vmax=1, aspect='auto')
    for ax, data, fmt in ((a1, dmin, '{:.0f}'), (a2, score, '{:.2f}')):
        for (i, j), v in np.ndenumerate(data):
            if np.isfinite(v):
                ax.text(j, i, fmt.format(v), ha='center', va='center', fontsize=7)
        ax.set_xticks(range(len(cols)), [f'{s}\n{m}' for s, m in cols], fontsize=7)
        ax.set_yticks(range(len(cases)), [str(c) for c in cases], fontsize=7)
        ax.set_ylabel('Imazu case')
    a1.set_title(f'minimum distance [m]: green >= r_min {params.r_min_m:.0f}, orange < r_min,\n'
                 'red: near miss (ship domain), black: collision (hull contact)', fontsize=9)
    a2.set_title('rule compliance score (mean over targets)', fontsize=9)
    fig.colorbar(im, ax=a2, fraction=0.04)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)
