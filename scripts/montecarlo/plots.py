"""PNG plots of a sweep table (matplotlib, Agg backend).

- ``cdf_max_cross_track.png``: empirical CDF of the episode's maximum |cross-track| per
  controller, one panel per combination of the other grid axes (e.g. model and current).
- ``<metric>_vs_<parameter>.png``: the metric of every completed episode against each randomly
  drawn parameter, coloured by controller, with the mean in ten equal-count bins.
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
    return ', '.join(f'{a}={k:g}' if isinstance(k, float) else f'{k}'
                     for a, k in zip(axes, key)) or 'all episodes'


def cdf_max_cross_track(rows, grid_axes, path):
    other = [a for a in grid_axes if a != 'controller']
    panels = _panels(rows, other)
    fig, axes = _grid(len(panels))
    for ax, (key, members) in zip(axes, panels):
        for ctrl in dict.fromkeys(r['controller'] for r in members):
            v = np.sort([r['max_abs_e_m'] if r['completed'] == 1 else np.inf
                         for r in members if r['controller'] == ctrl])
            y = np.arange(1, v.size + 1) / v.size
            ax.step(v[np.isfinite(v)], y[np.isfinite(v)], where='post', label=ctrl)
        ax.set_xscale('log')
        ax.set_xlabel('max |cross-track| (m)')
        ax.set_ylabel('fraction of episodes')
        ax.set_title(_label(other, key), fontsize=9)
        ax.grid(True, which='both', alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle('CDF of the maximum cross-track error per episode (not completed: off the '
                 'right edge)', fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def metric_vs_parameter(rows, parameter, metric, path):
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    for ctrl in dict.fromkeys(r['controller'] for r in rows):
        pts = np.array([(r[parameter], r[metric]) for r in rows
                        if r['controller'] == ctrl and r['completed'] == 1], dtype=float)
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


def write_plots(rows, sweep, folder, metrics=('max_abs_e_m', 'reward')):
    """Every plot of a sweep into ``folder``; returns the paths written."""
    paths = [folder / 'cdf_max_cross_track.png']
    cdf_max_cross_track(rows, list(sweep.grid), paths[0])
    for p in sorted(sweep.random):
        if sweep.random[p][0] == 'choice' and not isinstance(sweep.random[p][1][0], float):
            continue
        for m in metrics:
            paths.append(folder / f'{m}_vs_{p}.png')
            metric_vs_parameter(rows, p, m, paths[-1])
    return paths
