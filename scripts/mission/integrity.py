"""Is a mission bag complete? Lost and missing messages per topic, counted from the stamps.

Every simulator step publishes one odom (and one rudder, and one /clock on the clock master),
and in both stepping modes guidance and autopilot answer each odom once, so a complete record
holds, per vessel, one message of each per-step topic for every step from the first odom stamp
to the last. A step is missing from a stamped stream when two consecutive stamps are more than
one period apart; an unstamped per-step topic (std_msgs/Float64, the progress array) is short by
the difference between the step count and its message count (where in the record its messages
went missing is not known: ``mission.bag`` then times it by log time, never by interpolating
across the gap). One answer fewer than steps is not a loss: the answer to the last step may be
in flight when the launcher stops the graph (``in_flight``).

Pure numpy: ``record_integrity`` takes a ``mission.bag.BagData``.
"""
import numpy as np

#: per-step topics of a vessel (relative names) besides odom, as ``mission.bag`` reads them
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
    """One ``mission.bag.VesselData`` -> {'odom': stamp_gaps, <topic>: {...}, 'missing': total}."""
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
    """``mission.bag.BagData`` -> {'complete': bool, 'missing': int, 'clock': ..., 'vessels': ...}.

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
    out['missing'] = int(total)
    out['complete'] = total == 0
    return out


def summary_line(integrity):
    """One line for the console: 'record complete' or what is missing where."""
    if integrity['complete']:
        return 'record complete: every step of every per-step topic is in the bag'
    parts = []
    if integrity.get('clock', {}).get('missing'):
        parts.append(f"/clock {integrity['clock']['missing']}")
    for ns, v in integrity['vessels'].items():
        for topic, s in v.items():
            if isinstance(s, dict) and s.get('missing'):
                parts.append(f'{ns}/{topic} {s["missing"]}')
    return f"record INCOMPLETE: {integrity['missing']} messages missing ({', '.join(parts)})"
