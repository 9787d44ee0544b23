"""PNG plots of a sweep table (matplotlib, Agg backend).

- ``cdf_max_cross_track.png``: empirical CDF of the episode's maximum |cross-track| per
  controller, one panel per combination of the other grid axes (e.g. model and current).
- ``<metric>_vs_<parameter>.png``: the metric of every completed episode against each randomly
  drawn parameter, coloured by controller, with the mean in ten equal-count bins.

Encounter sweeps (spec.Sweep.kind 'encounter'): ``cdf_min_distance.png``, the CDF of the
episode's minimum distance per colav method, one panel per combination of the other grid axes
(case, own ship), with r_col, r_nm and r_min marked; ``<metric>_vs_<parameter>.png`` for the
minimum distance and the rule score, coloured by colav method.
"""
import matplotlib

matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402 (after selecting the backend)
import numpy as np  # noqa: E402

MAX_PANELS = 12


def _panels(rows, axes):
    groups = {}
    for r in rows:
        groups.setdefault(tuple(r[a] for a in axes), []).append(r)
    return list(groups.items())[:MAX_PANELS]


def _grid(n):
    cols = min(n, 3)
    rows = -(-n // cols)
    fig, ax = plt.subplots(rows, cols, figsize=(4.6 * cols, 3.6 * rows), squeeze=False)
    for a in ax.flat[n:]:
        a.set_visible(False)
    return fig, ax.flat


def _label(axes, key):
    return ', '.join(f'{a}={k:g}' if isinstance(k, (int, float)) else f'{k}'
                     for a, k in zip(axes, key)) or 'all episodes'


def _kept(row):
    """Rows a route-following plot shows (completed); every encounter row."""
    return row.get('completed', 1) == 1


def cdf_per_group(rows, grid_axes, path, metric, by, xlabel, title, log=True, marks=()):
    """CDF of ``metric`` per value of ``by``, a panel per combination of the other grid axes;
    rows not kept (_kept) count at +inf; ``marks``: (x, label) vertical lines."""
    other = [a for a in grid_axes if a != by]
    panels = _panels(rows, other)
    fig, axes = _grid(len(panels))
    for ax, (key, members) in zip(axes, panels):
        for value in dict.fromkeys(r[by] for r in members):
            v = np.sort([r[metric] if _kept(r) else np.inf for r in members if r[by] == value])
            y = np.arange(1, v.size + 1) / v.size
            ax.step(v[np.isfinite(v)], y[np.isfinite(v)], where='post', label=value)
        for x, text in marks:
            ax.axvline(x, color='0.4', lw=0.8, ls='--')
            ax.text(x, 0.98, f' {text}', fontsize=7, color='0.3', rotation=90, va='top',
                    transform=ax.get_xaxis_transform())
        if log:
            ax.set_xscale('log')
        ax.set_ylim(0.0, 1.02)
        ax.set_xlabel(xlabel)
        ax.set_ylabel('fraction of episodes')
        ax.set_title(_label(other, key), fontsize=9)
        ax.grid(True, which='both', alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def cdf_max_cross_track(rows, grid_axes, path):
    cdf_per_group(rows, grid_axes, path, 'max_abs_e_m', 'controller', 'max |cross-track| (m)',
                  'CDF of the maximum cross-track error per episode (not completed: off the '
                  'right edge)')


def cdf_min_distance(rows, grid_axes, path):
    from ship_guidance.colav_evaluation import EvaluationParams
    p = EvaluationParams()
    cdf_per_group(rows, grid_axes, path, 'min_distance_m', 'colav_method',
                  'minimum distance to a target (m)',
                  'CDF of the minimum distance per episode', log=False,
                  marks=((p.r_min_m, 'r_min'),))


def metric_vs_parameter(rows, parameter, metric, path, by='controller'):
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    for ctrl in dict.fromkeys(r[by] for r in rows):
        pts = np.array([(r[parameter], r[metric]) for r in rows
                        if r[by] == ctrl and _kept(r)], dtype=float)
        if not len(pts):
            continue
        line = ax.plot(pts[:, 0], pts[:, 1], '.', ms=2, alpha=0.3)[0]
        order = np.argsort(pts[:, 0], kind='stable')
        bins = np.array_split(order, min(10, len(order)))
        ax.plot([pts[b, 0].mean() for b in bins], [pts[b, 1].mean() for b in bins], '-o',
                ms=3, color=line.get_color(), label=ctrl)
    ax.set_xlabel(parameter)
    ax.set_ylabel(metric)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
    ax.set_title(f'{metric} against {parameter} (dots: episodes; lines: bin means)',
                 fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def write_plots(rows, sweep, folder):
    """Every plot of a sweep into ``folder``; returns the paths written."""
    if sweep.kind == 'encounter':
        paths, by, metrics = [folder / 'cdf_min_distance.png'], 'colav_method', (
            'min_distance_m', 'rule_score')
        cdf_min_distance(rows, list(sweep.grid), paths[0])
    else:
        paths, by, metrics = [folder / 'cdf_max_cross_track.png'], 'controller', (
            'max_abs_e_m', 'reward')
        cdf_max_cross_track(rows, list(sweep.grid), paths[0])
    for p in sorted(sweep.random):
        if sweep.random[p][0] == 'choice' and not isinstance(sweep.random[p][1][0], float):
            continue
        for m in metrics:
            paths.append(folder / f'{m}_vs_{p}.png')
            metric_vs_parameter(rows, p, m, paths[-1], by)
    return paths
