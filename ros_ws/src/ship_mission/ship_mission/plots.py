"""PNG plots of a recorded run (matplotlib, Agg backend: no display needed).

Inputs are ``ship_mission.bag.VesselData`` objects (or anything with the same attributes), keyed by
namespace; one colour per vessel. Arrays are in SI units and radians; the plots show angles in
degrees (axis labels say so) because people read degrees. Headings are unwrapped for display so
a turn through +-180 deg draws as a continuous line.

Headings: compass degrees (clockwise from north, ticks 000-360 as the scenario and route files
give courses) on the left axis, the ENU yaw the topics carry (counter-clockwise from east) on the
right one; each axis says which it is.

The settling window (the first ``settle_s`` of each vessel, which the metrics leave out) is
shaded on the time plots. It comes in as the metrics' own ``settle_s`` per vessel
(ship_mission.report passes metrics.json's values), so plot and numbers cannot disagree.

Files: ``track.png`` (ENU track vs route, equal axes, numbered waypoints, start/end markers,
heading arrows; with traffic, the targets' tracks and time marks every 60 s on every track),
``cross_track_error.png``, ``heading.png`` (heading vs command), ``rudder.png`` (command and
actual, with the limit lines), ``over_ground.png`` (speed and course over ground, drift angle)
and with traffic ``range.png`` (range from every vessel to every target over time).
"""
from pathlib import Path

import matplotlib

matplotlib.use('Agg')
import matplotlib.pyplot as plt  # after selecting the backend
import numpy as np

from matplotlib.ticker import FuncFormatter, MultipleLocator

from ship_mission.metrics import over_ground
from ship_sim.frames import wrap_angle

DPI = 110

#: What each plot of a run shows, for a reader of the report (ship_mission.html_report).
CAPTIONS = {
    'track.png': 'track (solid) vs route (dashed), ENU metres east and north; numbered waypoints '
                 'as the route file gives them (the route rounds them with fillets); arrows: '
                 'heading',
    'cross_track_error.png': 'cross-track error, + = starboard of the path; shaded: the settling '
                             'window the metrics leave out',
    'heading.png': 'heading (solid) vs heading command (dashed): compass degrees on the left, '
                   'the same angle as ENU yaw on the right; shaded: settling window',
    'rudder.png': 'rudder angle, + turns to port, with the limit lines; shaded: the settling '
                  'window the metrics (saturation counts included) leave out',
    'over_ground.png': 'speed over ground; course over ground beside the heading (compass '
                       'degrees); drift angle COG - heading, + = the ground track runs to '
                       'starboard of the heading (a current or wind setting the ship)',
    'range.png': 'range from each vessel to each target',
    'gap_error.png': 'platoon gap error along the route, + = too far behind',
    'platoon_string.png': 'peak and RMS cross-track error along the string',
}


def colours(n):
    """``n`` line colours, the plots' cycle (tab10, repeated past ten)."""
    cmap = plt.get_cmap('tab10')
    return [cmap(i % 10) for i in range(n)]


def _label(ns):
    return ns if ns else '/'


def save_figure(fig, path):
    """Write ``fig`` as the PNG ``path`` at the plots' resolution, close it; returns the path."""
    fig.tight_layout()
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    return Path(path)


SETTLE_GID = 'settling'   # the shaded span's matplotlib gid, so a test can find it


def shade_settle(ax, t0, settle_s, start=None):
    """Shade the settling window: ``settle_s`` from ``start`` (the vessel's first sample, s)
    on an axis whose time starts at ``t0``; nothing when settle_s is 0 or None."""
    if settle_s:
        a = 0.0 if start is None else start - t0
        ax.axvspan(a, a + settle_s, color='0.88', zorder=0, gid=SETTLE_GID,
                   label=f'settling {settle_s:g} s (not in the metrics)')


def _settle_of(settle_s, ns):
    """A vessel's settling time from one value for all or {namespace: value}."""
    return settle_s.get(ns) if isinstance(settle_s, dict) else settle_s


def _first_settle(settle_s):
    if isinstance(settle_s, dict):
        return next((v for v in settle_s.values() if v), None)
    return settle_s


def _compass_axis(ax):
    """Left axis in compass degrees (ticks every 45, labelled 000-315 whatever the unwrapped
    value), right axis the same angle as ENU yaw (deg, = 90 - compass, wrapped to +-180)."""
    ax.yaxis.set_major_locator(MultipleLocator(45.0))
    ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f'{v % 360.0:03.0f}'))
    right = ax.secondary_yaxis('right', functions=(lambda c: 90.0 - c, lambda y: 90.0 - y))
    right.yaxis.set_major_locator(MultipleLocator(45.0))
    right.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f'{(v + 180.0) % 360.0 - 180.0:+.0f}'))
    right.set_ylabel('ENU yaw (deg, CCW from east)', fontsize=8)
    return right


def _compass_unwrapped(yaw):
    """Compass heading (deg) of ENU yaw, unwrapped so a turn through north stays continuous
    (the axis labels it modulo 360)."""
    return 90.0 - np.degrees(np.unwrap(np.asarray(yaw, dtype=float)))


def plot_track(vessels, path, arrows=20, traffic=None, waypoints=None):
    """Track vs route, equal axes; ``arrows`` heading arrows per vessel; the ``traffic``
    targets' tracks ({name: track with t, x, y}) thin and grey-toned, with time marks every
    60 s on every track. ``waypoints``: {namespace: (x, y)} ENU waypoints of the route as its
    file gives them (before the fillets), drawn numbered; without them a sparse route's
    vertices are marked."""
    traffic = traffic or {}
    waypoints = {ns: w for ns, w in (waypoints or {}).items() if w is not None and len(w[0])}
    fig, ax = plt.subplots(figsize=(8, 7))
    xs = [a for v in vessels.values() for a in (v.x, v.route.x if v.route is not None else [])]
    ys = [a for v in vessels.values() for a in (v.y, v.route.y if v.route is not None else [])]
    xs += [tr.x for tr in traffic.values()]
    ys += [tr.y for tr in traffic.values()]
    xs, ys = np.concatenate([np.ravel(a) for a in xs]), np.concatenate([np.ravel(a) for a in ys])
    arrow_len = 0.035 * max(np.ptp(xs) if xs.size else 0.0, np.ptp(ys) if ys.size else 0.0, 1.0)
    routes_drawn = []
    for colour, (ns, v) in zip(colours(len(vessels)), vessels.items()):
        r = v.route
        if r is not None and len(r.x) and not any(
                len(o.x) == len(r.x) and np.array_equal(o.x, r.x) and np.array_equal(o.y, r.y) for o in routes_drawn):
            # waypoint markers only for sparse routes: arcs arrive as many short chords
            sparse = len(r.x) <= 40 and not waypoints
            ax.plot(r.x, r.y, '--', color='0.35', lw=1.2, marker='o' if sparse else None, ms=3,
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
    for colour, (name, tr) in zip(colours(len(vessels) + len(traffic))[len(vessels):],
                                  traffic.items()):
        if len(tr.x):
            ax.plot(tr.x, tr.y, '-', color=colour, lw=1.0, alpha=0.8, label=f'{name} (target)')
            ax.plot(tr.x[-1], tr.y[-1], 's', color=colour, ms=6)
            _time_marks(ax, tr, colour)
    drawn = []
    for ns, (wx, wy) in waypoints.items():
        if any(np.array_equal(wx, a) and np.array_equal(wy, b) for a, b in drawn):
            continue
        ax.plot(wx, wy, 'D', color='k', mfc='yellow', ms=7, zorder=4,
                label='waypoint' if not drawn else None)
        for i, (a, b) in enumerate(zip(wx, wy), 1):
            ax.annotate(f'WP{i}', (a, b), xytext=(6, 4), textcoords='offset points', fontsize=8,
                        fontweight='bold')
        drawn.append((wx, wy))
    ax.plot([], [], 'o', color='k', mfc='white', label='start')
    ax.plot([], [], 's', color='k', label='end')
    ax.set_aspect('equal', adjustable='datalim')
    ax.set_xlabel('x east (m)')
    ax.set_ylabel('y north (m)')
    ax.set_title('Track vs route (ENU), arrows: heading')
    ax.grid(True, alpha=0.3)
    ax.legend(loc='best', fontsize=8)
    return save_figure(fig, path)


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
    shade_settle(ax, t0, settle_s)
    for colour, (ns, v) in zip(colours(len(vessels)), vessels.items()):
        e = v.cross_track_error
        if len(e.t):
            ax.plot(e.t - t0, e.v, color=colour, lw=1.2, label=_label(ns))
    ax.axhline(0.0, color='k', lw=0.8)
    ax.set_xlabel('time (s)')
    ax.set_ylabel('cross-track error (m), + = starboard')
    ax.set_title('Cross-track error')
    ax.grid(True, alpha=0.3)
    ax.legend(loc='best', fontsize=8)
    return save_figure(fig, path)


def _t0(vessels):
    starts = [v.t[0] for v in vessels.values() if len(v.t)]
    return min(starts) if starts else 0.0


def _rows(vessels, title):
    n = max(1, len(vessels))
    fig, axes = plt.subplots(n, 1, figsize=(9, 2.8 * n + 0.6), sharex=True, squeeze=False)
    fig.suptitle(title)
    return fig, axes[:, 0]


def plot_heading(vessels, path, settle_s=None):
    """Vessel heading and heading command vs time, one panel per vessel: compass degrees on the
    left axis, ENU yaw on the right (module docstring); the settling window shaded."""
    fig, axes = _rows(vessels, 'Heading vs command')
    t0 = _t0(vessels)
    for ax, colour, (ns, v) in zip(axes, colours(len(vessels)), vessels.items()):
        if len(v.t):
            shade_settle(ax, t0, _settle_of(settle_s, ns), v.t[0])
            yaw = np.unwrap(v.yaw)
            ax.plot(v.t - t0, _compass_unwrapped(yaw), color=colour, lw=1.4,
                    label=f'{_label(ns)} heading')
            c = v.heading_cmd
            if len(c.t):
                # unwrap the command onto the same branch as the yaw for the plot
                ref = np.interp(c.t, v.t, yaw)
                cmd = ref + wrap_angle(np.asarray(c.v) - ref)
                ax.plot(c.t - t0, 90.0 - np.degrees(cmd), '--', color='k', lw=1.0, label='command')
            _compass_axis(ax)
        ax.set_ylabel('heading (compass deg)')
        ax.grid(True, alpha=0.3)
        ax.legend(loc='best', fontsize=8)
    axes[-1].set_xlabel('time (s)')
    return save_figure(fig, path)


def plot_rudder(vessels, path, limit_rad=None, settle_s=None):
    """Rudder command and actual angle (deg, + = to port) vs time with the +-limit lines and
    the settling window shaded (the saturation counts of the metrics start after it).
    ``limit_rad``: one limit (rad) for all vessels, or {namespace: limit or None}; ``settle_s``:
    one settling time (s) or {namespace: settling time}, from each vessel's first sample."""
    fig, axes = _rows(vessels, 'Rudder (+ turns to port)')
    t0 = _t0(vessels)
    for ax, colour, (ns, v) in zip(axes, colours(len(vessels)), vessels.items()):
        if len(v.t):
            shade_settle(ax, t0, _settle_of(settle_s, ns), v.t[0])
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
    return save_figure(fig, path)


def plot_over_ground(vessels, path, settle_s=None):
    """Speed over ground (kn, m/s on the right), course over ground beside the heading (compass
    deg) and the drift angle COG - heading (deg, + = ground track to starboard of the heading)
    vs time, all vessels on the same three panels (ship_mission.metrics.over_ground)."""
    fig, (a_sog, a_cog, a_drift) = plt.subplots(3, 1, figsize=(9, 8.4), sharex=True)
    fig.suptitle('Over ground: speed, course, drift')
    t0 = _t0(vessels)
    shade_settle(a_sog, t0, _first_settle(settle_s))
    for colour, (ns, v) in zip(colours(len(vessels)), vessels.items()):
        if len(v.t) < 2:
            continue
        sog, cog, drift = over_ground(v.t, v.x, v.y, v.yaw)
        t = v.t - t0
        a_sog.plot(t, sog / KNOT_MPS, color=colour, lw=1.3, label=_label(ns))
        heading = _compass_unwrapped(v.yaw)
        # the course on the heading's branch, so both lines run side by side
        course = heading + np.degrees(wrap_angle(np.radians(90.0 - np.degrees(cog) - heading)))
        a_cog.plot(t, heading, color=colour, lw=1.0, ls='--', label=f'{_label(ns)} heading')
        a_cog.plot(t, course, color=colour, lw=1.4, label=f'{_label(ns)} COG')
        a_drift.plot(t, np.degrees(drift), color=colour, lw=1.3, label=_label(ns))
    a_sog.set_ylabel('SOG (kn)')
    a_sog.secondary_yaxis('right', functions=(lambda kn: kn * KNOT_MPS, lambda ms: ms / KNOT_MPS)
                          ).set_ylabel('SOG (m/s)', fontsize=8)
    a_cog.set_ylabel('course / heading\n(compass deg)')
    _compass_axis(a_cog)
    a_drift.axhline(0.0, color='k', lw=0.8)
    a_drift.set_ylabel('drift COG - heading\n(deg, + = to starboard)')
    a_drift.set_xlabel('time (s)')
    for ax in (a_sog, a_cog, a_drift):
        ax.grid(True, alpha=0.3)
        if ax.get_legend_handles_labels()[0]:
            ax.legend(loc='best', fontsize=8)
    return save_figure(fig, path)


KNOT_MPS = 1852.0 / 3600.0


def make_plots(vessels, out_dir, rudder_limit_rad=None, settle_s=None, traffic=None, waypoints=None):
    """Write the five PNGs into ``out_dir`` (created), and range.png when there is
    ``traffic`` ({target name: track with t, x, y, yaw}); returns their paths. ``settle_s``:
    one settling time (s) or {namespace: the metrics' settle_s}; ``waypoints``: {namespace:
    (x, y)} ENU waypoints of each vessel's route (plot_track)."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = [plot_track(vessels, out / 'track.png', traffic=traffic, waypoints=waypoints),
             plot_cross_track(vessels, out / 'cross_track_error.png', _first_settle(settle_s)),
             plot_heading(vessels, out / 'heading.png', settle_s),
             plot_rudder(vessels, out / 'rudder.png', rudder_limit_rad, settle_s),
             plot_over_ground(vessels, out / 'over_ground.png', settle_s)]
    if traffic:
        paths.append(plot_ranges(vessels, traffic, out / 'range.png'))
    return paths


def plot_ranges(vessels, traffic, path):
    """Range (m) from every vessel to every target over time, at the vessel's stamps within
    the target's time span (the target interpolated: ship_mission.encounter.relative_positions)."""
    from ship_mission.encounter import relative_positions
    fig, ax = plt.subplots(figsize=(9, 4))
    t0 = _t0(vessels)
    styles = ('-', '--', ':', '-.')
    for colour, (ns, v) in zip(colours(len(vessels)), vessels.items()):
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
    return save_figure(fig, path)
