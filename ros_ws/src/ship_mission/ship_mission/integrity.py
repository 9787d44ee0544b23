"""Is a mission bag complete? Lost and missing messages per topic, counted from the stamps.

Every simulator step publishes one odom (and one rudder, and one /clock on the clock master),
and in both stepping modes guidance and autopilot answer each odom once, so a complete record
holds, per vessel, one message of each per-step topic for every step from the first odom stamp
to the last. A step is missing from a stamped stream when two consecutive stamps are more than
one period apart; an unstamped per-step topic (std_msgs/Float64, the progress array) is short by
the difference between the step count and its message count (where in the record its messages
went missing is not known: ``ship_mission.bag`` then times it by log time, never by interpolating
across the gap). One answer fewer than steps is not a loss: the answer to the last step may be
in flight when the launcher stops the graph (``in_flight``).

A bag recovered from an interrupted recording (``ship_mission.bag_recovery``) is never complete: its
end is lost. When a metadata.yaml survived, its message counts say how much: per vessel the
odom steps after the last one recovered (``lost_at_end``), per topic the messages; without one
how much is not known, and the report says so.

Pure numpy: ``record_integrity`` takes a ``ship_mission.bag.BagData``.
"""
import json

import numpy as np

from ship_mission import bag_recovery

#: per-step topics of a vessel (relative names) besides odom, as ``ship_mission.bag`` reads them
PER_STEP = ('rudder', 'rudder_cmd', 'heading_cmd', 'cross_track_error', 'progress')
MAX_GAPS_LISTED = 20


def stamp_gaps(t, period=None):
    """Stamps ``t`` (s, one per step) -> {'period_s', 'expected', 'received', 'missing', 'gaps'}.

    ``period``: the step (s); default the median spacing. ``gaps``: up to MAX_GAPS_LISTED
    [first missing stamp, last missing stamp] pairs (s), first ones first.
    """
    t = np.sort(np.asarray(t, dtype=float))
    if t.size < 2:
        return {'period_s': period, 'expected': int(t.size), 'received': int(t.size), 'missing': 0, 'gaps': []}
    dt = np.diff(t)
    period = float(np.median(dt)) if period is None else float(period)
    steps = np.rint(dt / period).astype(np.int64)   # 1 where consecutive
    lost = np.maximum(steps - 1, 0)
    where = np.flatnonzero(lost)
    gaps = [[float(t[i] + period), float(t[i + 1] - period)] for i in where[:MAX_GAPS_LISTED]]
    expected = int(steps.sum()) + 1
    return {'period_s': period, 'expected': expected, 'received': int(t.size),
            'missing': int(lost.sum()), 'gaps': gaps}


def vessel_integrity(vessel, period=None):
    """One ``ship_mission.bag.VesselData`` -> {'odom': stamp_gaps, <topic>: {...}, 'missing': total}."""
    odom = stamp_gaps(vessel.t, period)
    out = {'odom': odom}
    total = odom['missing']
    for key in PER_STEP:
        n = len(getattr(vessel, key).t)
        if n == 0:
            continue  # not published in this graph (e.g. a follower has no heading_cmd): not a loss
        in_flight = int(n == odom['expected'] - 1)
        short = max(odom['expected'] - in_flight - n, 0)
        out[key] = {'expected': odom['expected'], 'received': n, 'missing': short, 'in_flight': in_flight}
        total += short
    out['missing'] = total
    return out


def record_integrity(data):
    """``ship_mission.bag.BagData`` -> {'complete': bool, 'missing': int, 'clock': ..., 'vessels': ...}.

    ``clock`` counts the clock master's /clock stamps against its period (the master is the
    vessel whose odom stamps /clock follows: the first vessel with the same period).
    """
    vessels = {ns: vessel_integrity(v) for ns, v in data.vessels.items()}
    total = sum(v['missing'] for v in vessels.values())
    out = {'vessels': vessels}
    if data.clock is not None and len(data.clock):
        period = next((v['odom']['period_s'] for v in vessels.values() if v['odom']['period_s']), None)
        out['clock'] = stamp_gaps(data.clock, period)
        total += out['clock']['missing']
    recovered = _recovered(data)
    if recovered is not None:
        out['recovered'] = recovered
        lost_steps = recovered['lost_steps'] or {}
        for ns, v in vessels.items():
            if ns in lost_steps:
                v['odom']['lost_at_end'] = lost_steps[ns]
        total += sum(n for _, n in (recovered['lost'] or {}).values())
    out['missing'] = int(total)
    out['complete'] = total == 0 and recovered is None
    return out


def _recovered(data):
    """What a recovered bag lost at its end, from its custom data (ship_mission.bag_recovery), or None
    for a bag that was not recovered: {'end_s', 'lost': {topic: [received, lost]} or None
    (not known), 'lost_steps': {namespace: odom steps lost} or None}."""
    custom = getattr(data, 'custom_data', None) or {}
    if bag_recovery.RECOVERED not in custom and not getattr(data, 'recovered', None):
        return None
    end_s = int(custom.get(bag_recovery.END_NS, 0)) / 1e9
    expected = custom.get(bag_recovery.EXPECTED)
    if expected is None:
        return {'end_s': end_s, 'lost': None, 'lost_steps': None}
    expected = json.loads(expected)
    got = {t: count for t, (_type, count) in data.topics.items()}
    lost = {t: [g, e - g] for t, (g, e) in bag_recovery.lost(expected, got).items()}
    steps = {ns: lost[f'{ns.rstrip("/")}/odom'][1] for ns in data.vessels
             if f'{ns.rstrip("/")}/odom' in lost}
    return {'end_s': end_s, 'lost': lost, 'lost_steps': steps}


def summary_line(integrity):
    """One line for the console: 'record complete' or what is missing where."""
    if integrity['complete']:
        return 'record complete: every step of every per-step topic is in the bag'
    rec = integrity.get('recovered')
    if rec is not None:
        head = f"record INCOMPLETE: recovered from an interrupted recording that ends at {rec['end_s']:.1f} s"
        if rec['lost'] is None:
            tail = 'the steps after it are lost, how many is not known (no metadata.yaml survived)'
        else:
            steps = ', '.join(f'{ns} {n} odom steps' for ns, n in rec['lost_steps'].items())
            n_lost = sum(n for _, n in rec['lost'].values())
            tail = (f'lost after it: {n_lost} messages' + (f' ({steps})' if steps else '')
                    + ' of the counts metadata.yaml gave')
        inside = integrity['missing'] - sum(n for _, n in (rec['lost'] or {}).values())
        return f'{head}; {tail}' + (f'; {inside} messages missing before it' if inside else '')
    parts = []
    if integrity.get('clock', {}).get('missing'):
        parts.append(f"/clock {integrity['clock']['missing']}")
    for ns, v in integrity['vessels'].items():
        for topic, s in v.items():
            if isinstance(s, dict) and s.get('missing'):
                parts.append(f'{ns}/{topic} {s["missing"]}')
    return f"record INCOMPLETE: {integrity['missing']} messages missing ({', '.join(parts)})"
