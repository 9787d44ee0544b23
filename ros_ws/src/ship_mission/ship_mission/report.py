"""Bag -> metrics.json + PNG plots + report.html: what the launcher runs after a mission and replay_bag.py runs later.

Reads the bag with ``ship_mission.bag``, computes ``ship_mission.metrics.vessel_metrics`` per vessel and
draws ``ship_mission.plots`` (with each vessel's settling window as the metrics computed it, and the
route's waypoints from the route file the run's params name: ``route_waypoints``). The rudder
limit for the saturation count and the plot comes from the argument, else from the bag's
custom_data key ``mission.rudder_limit_rad/<vessel>`` (the launcher stores one per vessel with
the recorder's ``--meta``), else ``mission.rudder_limit_rad`` (one for all), else it is left out.

Each vessel's record ends at its own route completion (the guidance's finish flag, else the
first odometry past the route's end, ``vessel_completion``): the launcher stops the graph only
after it has heard every route_complete, so a bag runs on for a few sim seconds (longer for a
platoon's early finishers) on the last leg's extension, and how long depends on process
timing. Metrics and plots cover start to completion, so identical lockstep runs give identical
numbers; the record's ``bag_end_s`` and ``tail_after_finish_s`` say what was cut.

Traffic: the scenario's light targets (each a namespace with odometry only) and each target on
ais_node's ``/targets`` (by child_frame_id) are no vessels; the launcher records which they are
in the bag (``recorded_targets``), from the scenario's ``targets``. ``metrics['traffic']``
holds per target its track metrics (ship_mission.metrics.track_metrics, source ``light`` or ``ais``)
and its closest approach to every vessel (ship_mission.encounter.min_distance: distance, time,
bearing, side), over the time the vessels' own records cover (their completion cut; so
repeated lockstep runs give identical numbers). Plots: the targets' tracks join track.png, the
range from every vessel to every target is range.png; the per-vessel panels leave them out.

Platoons (``platoon`` = {namespace: predecessor namespace or None}, from the launcher):
- times: only the clock master publishes /clock and the followers run behind it in sim time, so
  neither a /clock-based log time nor a wall time says when a follower's unstamped message was
  due. Each vessel's unstamped topics (and the followers' gap_error) are therefore timed by the
  vessel's OWN odometry: exactly by sequence when the topic has as many messages as the odom
  (ship_mission.bag), else (the recorder dropped messages: a reliable keep-last publisher drops the
  oldest ones for a reader that lags too far) by ``_steps_by_log_time``;
- the cut at each vessel's own completion (above) matters most here: the graph runs on until
  the last vessel completes, and past the route's end a follower's law is not meaningful (its
  arc length is clamped at the end);
- ``metrics['platoon']``: per follower the gap error (gap - spacing, from its gap_error topic,
  up to its predecessor's completion: the gap is an arc-length difference, and the route's arc
  length ends there) and the string-stability measure: the ratio of its peak |cross-track
  error| after settling to its predecessor's (ship_mission.metrics.string_ratios; > 1 = the
  deviation grew down the string), the same for the RMS; plots gap_error.png and
  platoon_string.png.
"""
import dataclasses
import json
from pathlib import Path
from types import SimpleNamespace

import numpy as np

from ship_mission import bag as bagmod
from ship_mission import html_report, integrity, metrics, plots

RUDDER_LIMIT_KEY = 'mission.rudder_limit_rad'


def analyse_bag(bag_dir, out_dir=None, settle_s=None, rudder_limit_rad=None, topics=None, namespaces=None,
                reward_step_s=metrics.REWARD_STEP_S, episode_s=None, make_pngs=True, platoon=None,
                extra=None, html=True):
    """Write ``metrics.json`` and the plots for ``bag_dir`` into ``out_dir`` (default: the bag's parent).

    Returns the metrics dict: {'bag', 'time_source', 'topics': {topic: {type, count}},
    'vessels': {namespace: vessel_metrics(...) + 'missing_topics'}, 'plots': [file names]}.
    ``platoon``: {namespace: predecessor namespace or None} for a platoon run (module docstring);
    adds 'platoon' to the result. ``extra``: more top-level entries (e.g. the run's summary).
    ``html``: also write report.html beside metrics.json (ship_mission.html_report; the scenario,
    logs and run summary come from the bag's parent folder, the run folder).
    Raises ``ship_mission.bag.BagError`` when the path is not a bag or has no vessel odometry.
    """
    bag_dir = Path(bag_dir)
    out = Path(out_dir) if out_dir is not None else bag_dir.resolve().parent
    data = bagmod.read_bag(bag_dir, topics=topics, namespaces=namespaces)
    record = integrity.record_integrity(data)  # over the whole bag, before any cut
    gaps, ends, bag_end = prepare_records(bag_dir, data, platoon)
    limits = {ns: rudder_limit_rad if rudder_limit_rad is not None else
              _stored_limit(data.custom_data, ns) for ns in data.vessels}
    result = {'bag': str(bag_dir), 'time_source': data.time_source,
              'topics': {t: {'type': ty, 'count': n} for t, (ty, n) in sorted(data.topics.items())},
              'record': record, 'vessels': {}}
    if data.recovered:
        result['recovered'] = data.recovered
    traffic = traffic_tracks(bag_dir, data)
    for ns, v in data.vessels.items():
        if ns in traffic:
            continue
        if len(v.t) < 2:
            result['vessels'][ns] = {'error': 'fewer than two odometry messages', 'missing_topics': v.missing}
            continue
        m = metrics.vessel_metrics(
            v.t, v.x, v.y, v.yaw,
            xte=v.cross_track_error if len(v.cross_track_error.t) else None,
            rudder=v.rudder if len(v.rudder.t) else None,
            rudder_cmd=v.rudder_cmd if len(v.rudder_cmd.t) else None,
            heading_cmd=v.heading_cmd if len(v.heading_cmd.t) else None,
            route=(v.route.x, v.route.y) if v.route is not None else None,
            settle_s=settle_s, rudder_limit_rad=limits[ns], reward_step_s=reward_step_s, episode_s=episode_s,
            finished=_progress_column(v, 'finished'), remaining=_progress_column(v, 'remaining_m'))
        m['missing_topics'] = v.missing
        # metrics computed over a record with holes say which of their inputs had them
        m['computed_over_gaps'] = sorted(k for k, s in record['vessels'][ns].items()
                                         if isinstance(s, dict) and s.get('missing'))
        m['completion_cut'] = ends[ns][1]
        # How long the graph ran on after the completion (the launcher's reaction time, a
        # wall-clock matter) describes the recording, not the vessel: it goes with the record,
        # so the vessel's metrics repeat bit for bit.
        rec = record['vessels'].setdefault(ns, {})
        rec['bag_end_s'] = metrics.json_float(bag_end[ns] - v.t[0])
        rec['tail_after_finish_s'] = metrics.json_float(bag_end[ns] - v.t[-1]) if ends[ns][0] is not None else 0.0
        result['vessels'][ns] = m
    own = {ns: v for ns, v in data.vessels.items() if ns not in traffic}
    if traffic:
        traffic = _cut_traffic(traffic, own)
        result['traffic'] = traffic_metrics(traffic, own)
    if platoon:
        result['platoon'] = platoon_metrics(result['vessels'], gaps, platoon, settle_s, ends)
    out.mkdir(parents=True, exist_ok=True)
    if make_pngs:
        # the plots shade the settling window the metrics used: their own settle_s, per vessel
        settle = {ns: m.get('settle_s') for ns, m in result['vessels'].items()}
        settle_shown = next((v for v in settle.values() if v), None)
        result['plots'] = [p.name for p in plots.make_plots(
            own, out, limits, settle, traffic={n: tr for n, (_, tr) in traffic.items()},
            waypoints={ns: route_waypoints(bag_dir.resolve().parent, ns) for ns in own})]
        if platoon:
            result['plots'] += [p.name for p in plot_platoon(gaps, result['platoon'], out, settle_shown)]
    result.update(extra or {})
    with open(out / 'metrics.json', 'w') as f:
        json.dump(result, f, indent=2, sort_keys=False, allow_nan=False)
    if html:
        html_report.write_run_report(out, result, source_dir=bag_dir.resolve().parent)
    return result


def route_waypoints(run_dir, ns):
    """(x, y) ENU waypoints of a vessel's route as its route file gives them (before the
    fillets: the bag's route has the arcs as chords), read through the route file that the
    run's params/<vessel>.route_node.yaml names; None when the run folder does not say or the
    file cannot be read (a bag copied elsewhere: the plot then marks no waypoints)."""
    import yaml
    from ship_planner.route_loader import RouteError, load_route
    from ship_sim.frames import ned_to_enu_xy
    params = Path(run_dir) / 'params' / f'{ns.strip("/").replace("/", ".")}.route_node.yaml'
    try:
        doc = yaml.safe_load(params.read_text())
        route_file = doc['/**']['ros__parameters']['route_file']
        wp = np.asarray(load_route(route_file).waypoints_ned, dtype=float)
    except (OSError, yaml.YAMLError, KeyError, TypeError, RouteError):
        return None
    if wp.ndim != 2 or wp.shape[0] == 0:
        return None
    return ned_to_enu_xy(wp[:, 0], wp[:, 1])


#: A vessel's topics besides odom: a namespace with none of them (odometry only) is taken for a
#: light target in a bag that does not record its targets (recorded_targets).
VESSEL_TOPICS = ('route', 'rudder', 'rudder_cmd', 'heading_cmd', 'cross_track_error', 'progress')


def recorded_targets(custom_data):
    """The run's targets as the launcher recorded them from its scenario (custom_data key
    ship_mission.scenario.TARGETS_KEY): {'light': [namespace, ...], 'full': [...], 'ais': bool};
    None for a bag without that record (not written by the launcher, or before it kept one)."""
    from ship_mission.scenario import TARGETS_KEY
    text = custom_data.get(TARGETS_KEY)
    return None if text is None else json.loads(text)


def traffic_tracks(bag_dir, data):
    """{name: (source, track)} of the targets of a run: its light targets ('light') and the
    targets on ais_node's /targets ('ais', ship_mission.encounter.target_tracks), as the bag
    records them (recorded_targets). A bag without that record falls back on what it holds: the
    namespaces with odometry only, and /targets if it was recorded."""
    from ship_mission.encounter import target_tracks
    kinds = recorded_targets(data.custom_data)
    if kinds is not None:
        light = [ns for ns in kinds['light'] if ns in data.vessels]
        ais = kinds['ais'] and '/targets' in data.topics
    else:
        light = [ns for ns, v in data.vessels.items() if all(t in v.missing for t in VESSEL_TOPICS)]
        ais = '/targets' in data.topics
    out = {ns: ('light', data.vessels[ns]) for ns in light}
    if ais:
        out.update((name, ('ais', tr)) for name, tr in target_tracks(bag_dir).items())
    return out


def _cut_traffic(traffic, own):
    """The targets' tracks up to the last vessel's (completion-cut) record: a target has no
    completion of its own, and the graph runs on for a time that varies with process timing."""
    ends = [v.t[-1] for v in own.values() if len(v.t)]
    if not ends:
        return traffic
    t_end = max(ends)
    return {name: (source, SimpleNamespace(**{k: getattr(tr, k)[tr.t <= t_end]
                                             for k in ('t', 'x', 'y', 'yaw')}))
            for name, (source, tr) in traffic.items()}


def traffic_metrics(traffic, own):
    """{target: track metrics + source + closest_approach {vessel: min_distance dict}}."""
    from ship_mission.encounter import min_distance
    result = {}
    for name, (source, tr) in traffic.items():
        m = {'source': source, **metrics.track_metrics(tr.t, tr.x, tr.y)}
        m['closest_approach'] = {ns: min_distance(v, tr) for ns, v in own.items()
                                 if len(v.t) and len(tr.t)}
        result[name] = m
    return result


def traffic_lines(result):
    """One console line per target of ``result['traffic']``: its closest approach to each
    vessel."""
    lines = []
    for name, m in result.get('traffic', {}).items():
        close = ', '.join(f"{ns} {c['min_distance_m']:.1f} m at {c['t_min_s']:.1f} s "
                          f"({c['side']})" for ns, c in m['closest_approach'].items() if c)
        lines.append(f"{name} ({m['source']} target): closest approach {close or 'none'}")
    return lines


def prepare_records(bag_dir, data, platoon=None):
    """In place on ``data`` (ship_mission.bag.BagData): time a platoon's unstamped topics by each
    vessel's own odometry, then end every vessel's record at its own completion (module
    docstring). Returns (gaps, ends, bag_end): {follower: Series of gap_error} (None without a
    platoon), {namespace: (completion time or None, source)}, {namespace: last odometry time
    before the cut, or None}."""
    gaps = _prepare_platoon(bag_dir, data, platoon) if platoon else None
    ends = {ns: vessel_completion(v) for ns, v in data.vessels.items()}
    if platoon:
        _cut_gaps(gaps, ends, platoon)
    bag_end = {ns: float(v.t[-1]) if len(v.t) else None for ns, v in data.vessels.items()}
    for ns, (t_end, _) in ends.items():
        if t_end is not None:
            data.vessels[ns] = vessel_until(data.vessels[ns], t_end)
    return gaps, ends, bag_end


def _stored_limit(custom_data, ns):
    """The vessel's rudder limit (rad) from the bag's custom_data, or None (module docstring)."""
    value = custom_data.get(f'{RUDDER_LIMIT_KEY}{ns}', custom_data.get(RUDDER_LIMIT_KEY))
    return None if value is None else float(value)


def _progress_column(vessel, label):
    """(t, column) of the guidance progress array by its layout label, or None."""
    if label in vessel.progress_labels and len(vessel.progress.t):
        return vessel.progress.t, vessel.progress.v[:, vessel.progress_labels.index(label)]
    return None


# -- platoons -------------------------------------------------------------------------------------

SERIES = ('rudder', 'rudder_cmd', 'heading_cmd', 'cross_track_error', 'progress')


def _prepare_platoon(bag_dir, data, platoon):
    """Time the platoon's unstamped topics by each vessel's own odometry and read the followers'
    gap errors (module docstring). Returns {follower namespace: Series of gap_error}."""
    names = {**bagmod.DEFAULT_TOPICS, 'gap_error': 'gap_error'}
    wanted = {f'{ns}/{rel}': (ns, key) for ns in platoon for key, rel in names.items()
              if key != 'route'}
    reader = bagmod.open_bag(bag_dir)
    try:
        conns = [c for c in reader.connections if c.topic in wanted]
        log = {c.topic: [] for c in conns}
        raw = {c.topic: [] for c in conns if wanted[c.topic][1] in ('odom', 'gap_error')}
        for conn, t_ns, msg in reader.messages(connections=conns):
            log[conn.topic].append(t_ns)
            if conn.topic in raw:
                raw[conn.topic].append(msg)
    finally:
        reader.close()
    gaps = {}
    for ns, v in list(data.vessels.items()):
        if ns not in platoon or f'{ns}/odom' not in log:
            continue
        odom_log = np.asarray(log[f'{ns}/odom'], dtype=np.int64)
        odom_t = bagmod.decode_odometry(raw[f'{ns}/odom'])['t']

        def own_time(topic):
            return _steps_by_log_time(np.asarray(log[topic], dtype=np.int64), odom_log, odom_t)

        changes, timing = {}, dict(v.timing)
        for key in SERIES:
            series, topic = getattr(v, key), f'{ns}/{names[key]}'
            if len(series.t) and timing.get(names[key]) != 'odom sequence' and topic in log:
                changes[key] = bagmod.Series(own_time(topic), series.v)
                timing[names[key]] = 'own odom (log time)'
        v = dataclasses.replace(v, timing=timing, **changes)
        topic = f'{ns}/gap_error'
        if platoon[ns] is not None and topic in raw:
            g = bagmod.decode_float64(raw[topic])
            exact = len(g) == len(v.t)
            gaps[ns] = bagmod.Series(v.t.copy() if exact else own_time(topic), g)
            v.timing['gap_error'] = 'odom sequence' if exact else 'own odom (log time)'
        data.vessels[ns] = v
    return gaps


def _cut_gaps(gaps, ends, platoon):
    """End each follower's gap error at its own or its predecessor's completion, whichever is
    first: the gap is measured along the route, and once the predecessor has passed the route's
    end its arc length is clamped there and the gap means nothing more."""
    for ns in gaps:
        t_end = ends.get(ns, (None,))[0]
        cut = min((t for t in (t_end, ends.get(platoon[ns], (None,))[0]) if t is not None),
                  default=None)
        if cut is not None:
            keep = gaps[ns].t <= cut
            gaps[ns] = bagmod.Series(gaps[ns].t[keep], gaps[ns].v[keep])


def _steps_by_log_time(msg_log, odom_log, odom_t):
    """Sim times of a vessel's unstamped messages (one per step, in order, some dropped) from
    the recorder's log times and the vessel's own odometry (log times, stamps; some dropped).

    The log time, interpolated between the odom messages logged around it, estimates the step
    each message answers; but a lagging recorder handles its subscriptions in bursts, so the
    estimate scatters by many steps both ways. What is certain: message n answers step
    j(n) = n + D(n), where D, the number of its messages dropped so far, never decreases. So D
    is the non-decreasing least-squares fit (pool adjacent violators) of the estimates minus n,
    rounded; exact when nothing was dropped. Step j is at odom_t[0] + j h, h the step period."""
    n = np.arange(msg_log.size)
    if n.size == 0:
        return np.zeros(0)
    h = float(np.median(np.diff(odom_t))) if odom_t.size > 1 else 1.0
    est = (np.interp(msg_log - odom_log[0], odom_log - odom_log[0], odom_t) - odom_t[0]) / h
    drops = np.maximum(np.rint(_non_decreasing_fit(est - n)), 0.0)
    k_odom = np.rint((odom_t - odom_t[0]) / h).astype(np.int64)
    last = max(int(k_odom[-1]), n.size - 1)
    steps = np.minimum(n + drops, last - (n.size - 1 - n)).astype(np.int64)
    # the odom's own stamp where that step's odom was recorded (exact), else the step grid
    pos = np.minimum(np.searchsorted(k_odom, steps), k_odom.size - 1)
    return np.where(k_odom[pos] == steps, odom_t[pos], odom_t[0] + h * steps)


def _non_decreasing_fit(y):
    """Least-squares non-decreasing fit of y (pool adjacent violators), same length."""
    means, sizes = [], []
    for v in np.asarray(y, dtype=float).tolist():
        m, k = v, 1
        while means and means[-1] > m:
            m = (means[-1] * sizes[-1] + m * k) / (sizes[-1] + k)
            k += sizes.pop()
            means.pop()
        means.append(m)
        sizes.append(k)
    return np.repeat(means, sizes)


def vessel_completion(v):
    """(sim time (s), source) of the vessel's route completion: the first progress message with
    the finish flag set ('guidance'), else (the recorder missed the last messages of a run that
    was stopped at once) the first odometry past the route's end ('route'); (None, None)."""
    col = _progress_column(v, 'finished')
    if col is not None:
        done = np.nonzero(np.asarray(col[1]) >= 0.5)[0]
        if done.size:
            return float(col[0][done[0]]), 'guidance'
    if v.route is not None and len(v.route.x) >= 2 and len(v.t):
        s, _, _, length = metrics.project_on_route(v.x, v.y, v.route.x, v.route.y)
        t_done = metrics.completion_time(v.t, s, length)
        if t_done is not None:
            return t_done, 'route'
    return None, None


def vessel_until(v, t_end):
    """The vessel's record up to and including sim time t_end."""
    k = v.t <= t_end
    cut = {key: getattr(v, key)[k] for key in ('t', 'x', 'y', 'yaw', 'u', 'v', 'r')}
    for key in SERIES:
        s = getattr(v, key)
        keep = s.t <= t_end
        cut[key] = bagmod.Series(s.t[keep], s.v[keep])
    return dataclasses.replace(v, **cut)


def platoon_metrics(vessel_metrics, gaps, platoon, settle_s=None, ends=None):
    """{'predecessor', 'string_peak_ratio', 'string_rms_ratio', per-follower gap statistics}.

    vessel_metrics: the per-vessel metrics (already cut at each vessel's completion); gaps:
    {follower: Series}; platoon: {vessel: predecessor or None}; ends: {vessel: (completion
    sim time, source)} from ``vessel_completion`` (default: the per-vessel metrics' completion)."""
    peak = {ns: m.get('xte_max_abs_m') for ns, m in vessel_metrics.items()}
    rms_ = {ns: m.get('xte_rms_m') for ns, m in vessel_metrics.items()}
    peak_ratio = metrics.string_ratios(peak, platoon)
    rms_ratio = metrics.string_ratios(rms_, platoon)
    out = {}
    for ns, pred in platoon.items():
        m = vessel_metrics.get(ns, {})
        row = {'predecessor': pred, 'xte_peak_m': peak.get(ns), 'xte_rms_m': rms_.get(ns),
               'time_to_complete_s': m.get('time_to_complete_s'),
               'completion_source': m.get('completion_source')}
        t_end, source = (ends or {}).get(ns, (None, None))
        if t_end is not None:
            row['time_to_complete_s'] = t_end - (m.get('start_time_s') or 0.0)
            row['completion_source'] = source
        if pred is not None:
            row.update({'string_peak_ratio': peak_ratio.get(ns),
                        'string_rms_ratio': rms_ratio.get(ns)})
            g = gaps.get(ns)
            if g is not None and len(g.t):
                t_from = metrics.settle_cutoff(g.t, settle_s)
                row.update(metrics.gap_error_stats(g.t, g.v, t_from))
            else:
                row['gap_error_samples'] = 0
        out[ns] = row
    return out


def plot_platoon(gaps, rows, out_dir, settle_s=None):
    """gap_error.png (each follower's gap error vs time) and platoon_string.png (peak and RMS
    cross-track error of each vessel, in platoon order, with the ratio to the predecessor)."""
    import matplotlib.pyplot as plt
    out = Path(out_dir)
    fig, ax = plt.subplots(figsize=(9, 4))
    t0 = min((g.t[0] for g in gaps.values() if len(g.t)), default=0.0)
    plots.shade_settle(ax, t0, settle_s)
    for colour, (ns, g) in zip(plots.colours(len(rows))[1:], gaps.items()):
        if len(g.t):
            ax.plot(g.t - t0, g.v, color=colour, lw=1.2, label=f'{ns} (after {rows[ns]["predecessor"]})')
    ax.axhline(0.0, color='k', lw=0.8)
    ax.set_xlabel('time (s)')
    ax.set_ylabel('gap - spacing (m), + = too far behind')
    ax.set_title('Platoon gap error (along the route)')
    ax.grid(True, alpha=0.3)
    ax.legend(loc='best', fontsize=8)
    files = [plots.save_figure(fig, out / 'gap_error.png')]

    names = list(rows)
    peak = [rows[n]['xte_peak_m'] or 0.0 for n in names]
    rms_ = [rows[n]['xte_rms_m'] or 0.0 for n in names]
    fig, ax = plt.subplots(figsize=(max(5.0, 1.3 * len(names) + 2), 4))
    x = np.arange(len(names))
    ax.bar(x - 0.2, peak, 0.4, label='peak |xte| after settling')
    ax.bar(x + 0.2, rms_, 0.4, label='RMS xte after settling')
    for i, n in enumerate(names):
        r = rows[n].get('string_peak_ratio')
        if r is not None:
            ax.annotate(f'x{r:.2f}', (x[i] - 0.2, peak[i]), ha='center', va='bottom', fontsize=8)
    ax.set_xticks(x, [n.strip('/') for n in names])
    ax.set_ylabel('cross-track error (m)')
    ax.set_title('Along the string (labels: peak ratio to the predecessor)')
    ax.grid(True, axis='y', alpha=0.3)
    ax.legend(loc='best', fontsize=8)
    files.append(plots.save_figure(fig, out / 'platoon_string.png'))
    return files
