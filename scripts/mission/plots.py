"""PNG plots of a recorded run (matplotlib, Agg backend: no display needed).

Inputs are ``mission.bag.VesselData`` objects (or anything with the same attributes), keyed by
namespace; one colour per vessel. Arrays are in SI units and radians; the plots show angles in
degrees (axis labels say so) because people read degrees. Headings are unwrapped for display so
a turn through +-180 deg draws as a continuous line.

Files: ``track.png`` (ENU track vs route, equal axes, start/end markers, heading arrows; with
traffic, the targets' tracks and time marks every 60 s on every track), ``cross_track_error.png``,
``heading.png`` (yaw vs command), ``rudder.png`` (command and actual, with the limit lines),
and with traffic ``range.png`` (range from every vessel to every target over time).
"""
from pathlib import Path

import matplotlib

matplotlib.use('Agg')
import matplotlib.pyplot as plt  # after selecting the backend
import numpy as np

from ship_sim.frames import wrap_angle

DPI = 110


def _colours(n):
    cmap = plt.get_cmap('tab10')
    return [cmap(i % 10) for i in range(n)]


def _label(ns):
    return ns if ns else '/'


def _save(fig, path):
    fig.tight_layout()
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    return Path(path)


def _shade_settle(ax, t0, settle_s):
    if settle_s:
        ax.axvspan(0.0, settle_s, color='0.9', zorder=0, label='settling (excluded)')


def plot_track(vessels, path, arrows=20, traffic=None):
    """Track vs route, equal axes; ``arrows`` heading arrows per vessel; the ``traffic``
    targets' tracks ({name: track with t, x, y}) thin and grey-toned, with time marks every
    60 s on every track."""
    traffic = traffic or {}
    fig, ax = plt.subplots(figsize=(8, 7))
    xs = [a for v in vessels.values() for a in (v.x, v.route.x if v.route is not None else [])]
    ys = [a for v in vessels.values() for a in (v.y, v.route.y if v.route is not None else [])]
    xs += [tr.x for tr in traffic.values()]
    ys += [tr.y for tr in traffic.values()]
    xs, ys = np.concatenate([np.ravel(a) for a in xs]), np.concatenate([np.ravel(a) for a in ys])
    arrow_len = 0.035 * max(np.ptp(xs) if xs.size else 0.0, np.ptp(ys) if ys.size else 0.0, 1.0)
    routes_drawn = []
    for colour, (ns, v) in zip(_colours(len(vessels)), vessels.items()):
        r = v.route
        if r is not None and len(r.x) and not any(
                len(o.x) == len(r.x) and np.array_equal(o.x, r.x) and np.array_equal(o.y, r.y) for o in routes_drawn):
            # waypoint markers only for sparse routes: arcs arrive as many short chords
            ax.plot(r.x, r.y, '--', color='0.35', lw=1.2, marker='o' if len(r.x) <= 40 else None, ms=3,
                    label='route' if not routes_drawn else None)
            routes_drawn.append(r)
        if len(v.x) == 0:
            continue
        ax.plot(v.x, v.y, '-', color=colour, lw=1.6, label=_label(ns))
        ax.plot(v.x[0], v.y[0], 'o', color=colour, ms=8, mfc='white', mew=2)
        ax.plot(v.x[-1], v.y[-1], 's', color=colour, ms=8)
        step = max(1, len(v.x) // max(1, arrows))
        k = np.arange(0, len(v.x), step)
        ax.quiver(v.x[k], v.y[k], arrow_len * np.cos(v.yaw[k]), arrow_len * np.sin(v.yaw[k]), color=colour,
                  angles='xy', scale_units='xy', scale=1.0, width=0.004, alpha=0.85, zorder=3)
        if traffic:
            _time_marks(ax, v, colour)
    for colour, (name, tr) in zip(_colours(len(vessels) + len(traffic))[len(vessels):],
                                  traffic.items()):
        if len(tr.x):
            ax.plot(tr.x, tr.y, '-', color=colour, lw=1.0, alpha=0.8, label=f'{name} (target)')
            ax.plot(tr.x[-1], tr.y[-1], 's', color=colour, ms=6)
            _time_marks(ax, tr, colour)
    ax.plot([], [], 'o', color='k', mfc='white', label='start')
    ax.plot([], [], 's', color='k', label='end')
    ax.set_aspect('equal', adjustable='datalim')
    ax.set_xlabel('x east (m)')
    ax.set_ylabel('y north (m)')
    ax.set_title('Track vs route (ENU), arrows: heading')
    ax.grid(True, alpha=0.3)
    ax.legend(loc='best', fontsize=8)
    return _save(fig, path)


TIME_MARK_S = 60.0


def _time_marks(ax, track, colour):
    """Dots on a track every TIME_MARK_S of its time (the same times on every track, so
    where two ships were at once can be read off)."""
    t = np.asarray(track.t)
    if t.size < 2:
        return
    marks = np.arange(np.ceil(t[0] / TIME_MARK_S), np.floor(t[-1] / TIME_MARK_S) + 1) * TIME_MARK_S
    ax.plot(np.interp(marks, t, track.x), np.interp(marks, t, track.y), '.', color=colour, ms=6)


def plot_cross_track(vessels, path, settle_s=None):
    """Cross-track error (m, + = starboard of the path) vs time."""
    fig, ax = plt.subplots(figsize=(9, 4))
    t0 = _t0(vessels)
    _shade_settle(ax, t0, settle_s)
    for colour, (ns, v) in zip(_colours(len(vessels)), vessels.items()):
        e = v.cross_track_error
        if len(e.t):
            ax.plot(e.t - t0, e.v, color=colour, lw=1.2, label=_label(ns))
    ax.axhline(0.0, color='k', lw=0.8)
    ax.set_xlabel('time (s)')
    ax.set_ylabel('cross-track error (m), + = starboard')
    ax.set_title('Cross-track error')
    ax.grid(True, alpha=0.3)
    ax.legend(loc='best', fontsize=8)
    return _save(fig, path)


def _t0(vessels):
    starts = [v.t[0] for v in vessels.values() if len(v.t)]
    return min(starts) if starts else 0.0


def _rows(vessels, title):
    n = max(1, len(vessels))
    fig, axes = plt.subplots(n, 1, figsize=(9, 2.8 * n + 0.6), sharex=True, squeeze=False)
    fig.suptitle(title)
    return fig, axes[:, 0]


def plot_heading(vessels, path):
    """Vessel yaw and heading command (deg, ENU, unwrapped) vs time, one panel per vessel."""
    fig, axes = _rows(vessels, 'Heading (ENU yaw, unwrapped) vs command')
    t0 = _t0(vessels)
    for ax, colour, (ns, v) in zip(axes, _colours(len(vessels)), vessels.items()):
        if len(v.t):
            yaw = np.unwrap(v.yaw)
            ax.plot(v.t - t0, np.degrees(yaw), color=colour, lw=1.4, label=f'{_label(ns)} yaw')
            c = v.heading_cmd
            if len(c.t):
                # unwrap the command onto the same branch as the yaw for the plot
                ref = np.interp(c.t, v.t, yaw)
                cmd = ref + wrap_angle(np.asarray(c.v) - ref)
                ax.plot(c.t - t0, np.degrees(cmd), '--', color='k', lw=1.0, label='command')
        ax.set_ylabel('yaw (deg)')
        ax.grid(True, alpha=0.3)
        ax.legend(loc='best', fontsize=8)
    axes[-1].set_xlabel('time (s)')
    return _save(fig, path)


def plot_rudder(vessels, path, limit_rad=None):
    """Rudder command and actual angle (deg, + = to port) vs time with the +-limit lines.
    ``limit_rad``: one limit (rad) for all vessels, or {namespace: limit or None}."""
    fig, axes = _rows(vessels, 'Rudder (+ turns to port)')
    t0 = _t0(vessels)
    for ax, colour, (ns, v) in zip(axes, _colours(len(vessels)), vessels.items()):
        if len(v.rudder_cmd.t):
            ax.plot(v.rudder_cmd.t - t0, np.degrees(v.rudder_cmd.v), '--', color='k', lw=1.0, label='command')
        if len(v.rudder.t):
            ax.plot(v.rudder.t - t0, np.degrees(v.rudder.v), color=colour, lw=1.4, label=f'{_label(ns)} actual')
        limit = limit_rad.get(ns) if isinstance(limit_rad, dict) else limit_rad
        if limit is not None:
            for sign in (1, -1):
                ax.axhline(sign * np.degrees(limit), color='r', lw=0.9, ls=':',
                           label='limit' if sign > 0 else None)
        ax.set_ylabel('rudder (deg)')
        ax.grid(True, alpha=0.3)
        if ax.get_legend_handles_labels()[0]:   # a light target has no rudder: no legend
            ax.legend(loc='best', fontsize=8)
    axes[-1].set_xlabel('time (s)')
    return _save(fig, path)


def make_plots(vessels, out_dir, rudder_limit_rad=None, settle_s=None, traffic=None):
    """Write the four PNGs into ``out_dir`` (created), and range.png when there is
    ``traffic`` ({target name: track with t, x, y, yaw}); returns their paths."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = [plot_track(vessels, out / 'track.png', traffic=traffic),
             plot_cross_track(vessels, out / 'cross_track_error.png', settle_s),
             plot_heading(vessels, out / 'heading.png'),
             plot_rudder(vessels, out / 'rudder.png', rudder_limit_rad)]
    if traffic:
        paths.append(plot_ranges(vessels, traffic, out / 'range.png'))
    return paths


def plot_ranges(vessels, traffic, path):
    """Range (m) from every vessel to every target over time, at the vessel's stamps within
    the target's time span (the target interpolated: mission.encounter.relative_positions)."""
    from mission.encounter import relative_positions
    fig, ax = plt.subplots(figsize=(9, 4))
    t0 = _t0(vessels)
    styles = ('-', '--', ':', '-.')
    for colour, (ns, v) in zip(_colours(len(vessels)), vessels.items()):
        for i, (name, tr) in enumerate(traffic.items()):
            sel, dx, dy = relative_positions(v, tr)
            if not sel.size:
                continue
            ax.plot(v.t[sel] - t0, np.hypot(dx, dy), styles[i % len(styles)], color=colour,
                    lw=1.3, label=f'{_label(ns)} to {name}')
    ax.set_ylim(bottom=0.0)
    ax.set_xlabel('time (s)')
    ax.set_ylabel('range (m)')
    ax.set_title('Range to each target')
    ax.grid(True, alpha=0.3)
    ax.legend(loc='best', fontsize=8)
    return _save(fig, path)
