"""Bag -> metrics.json + PNG plots: what the launcher runs after a mission and replay_bag.py runs later.

Reads the bag with ``mission.bag``, computes ``mission.metrics.vessel_metrics`` per vessel and
draws ``mission.plots``. The rudder limit for the saturation count and the plot comes from the
argument, else from the bag's custom_data key ``mission.rudder_limit_rad`` (the launcher can
store it with the recorder's ``--meta``), else it is left out.
"""
import json
from pathlib import Path

from mission import bag as bagmod
from mission import metrics, plots

RUDDER_LIMIT_KEY = 'mission.rudder_limit_rad'


def analyse_bag(bag_dir, out_dir=None, settle_s=None, rudder_limit_rad=None, topics=None, namespaces=None,
                reward_step_s=metrics.REWARD_STEP_S, episode_s=None, make_pngs=True):
    """Write ``metrics.json`` and the plots for ``bag_dir`` into ``out_dir`` (default: the bag's parent).

    Returns the metrics dict: {'bag', 'time_source', 'topics': {topic: {type, count}},
    'vessels': {namespace: vessel_metrics(...) + 'missing_topics'}, 'plots': [file names]}.
    Raises ``mission.bag.BagError`` when the path is not a bag or has no vessel odometry.
    """
    bag_dir = Path(bag_dir)
    out = Path(out_dir) if out_dir is not None else bag_dir.resolve().parent
    data = bagmod.read_bag(bag_dir, topics=topics, namespaces=namespaces)
    if rudder_limit_rad is None and RUDDER_LIMIT_KEY in data.custom_data:
        rudder_limit_rad = float(data.custom_data[RUDDER_LIMIT_KEY])
    result = {'bag': str(bag_dir), 'time_source': data.time_source,
              'topics': {t: {'type': ty, 'count': n} for t, (ty, n) in sorted(data.topics.items())},
              'vessels': {}}
    for ns, v in data.vessels.items():
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
            settle_s=settle_s, rudder_limit_rad=rudder_limit_rad, reward_step_s=reward_step_s, episode_s=episode_s,
            finished=_progress_column(v, 'finished'), remaining=_progress_column(v, 'remaining_m'))
        m['missing_topics'] = v.missing
        result['vessels'][ns] = m
    out.mkdir(parents=True, exist_ok=True)
    if make_pngs:
        settle_shown = next((m.get('settle_s') for m in result['vessels'].values() if m.get('settle_s')), None)
        result['plots'] = [p.name for p in plots.make_plots(data.vessels, out, rudder_limit_rad, settle_shown)]
    with open(out / 'metrics.json', 'w') as f:
        json.dump(result, f, indent=2, sort_keys=False, allow_nan=False)
    return result


def _progress_column(vessel, label):
    """(t, column) of the guidance progress array by its layout label, or None."""
    if label in vessel.progress_labels and len(vessel.progress.t):
        return vessel.progress.t, vessel.progress.v[:, vessel.progress_labels.index(label)]
    return None
