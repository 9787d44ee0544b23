"""Tables of scenarios run in the node graph (scripts/mission_results.py: per scenario the run's
metrics.json, and the colav alterations and closest approaches): doc/results/platoon.md and
doc/results/encounters.md."""
from results_pages.registry import table
from results_pages.tables import fmt, markdown_table


def _run(data, name):
    try:
        return data['runs'][name]
    except KeyError:
        raise KeyError(f"no run of scenario '{name}' in the results file "
                       f"(it has: {', '.join(data['runs'])})") from None


def _vessel_rows(metrics):
    rows = []
    for ns, v in metrics['vessels'].items():
        p = metrics.get('platoon', {}).get(ns, {})
        rows.append({'vessel': ns.strip('/'), **v,
                     'predecessor': (p.get('predecessor') or '-').strip('/'),
                     'string_peak_ratio': p.get('string_peak_ratio'),
                     'string_rms_ratio': p.get('string_rms_ratio'),
                     'gap_error_rms_m': p.get('gap_error_rms_m')})
    return rows


@table('platoon', 'vessels')
def platoon_vessels(data):
    """Per vessel of the platoon scenario: tracking after settling, the string-stability ratios
    to the predecessor, the gap error."""
    return _platoon_table(_run(data, 'platoon_mariner_5'))


@table('platoon', 'predecessor_law')
def platoon_predecessor_law(data):
    """The same per vessel for the variant with Angelopoulos's follower law."""
    return _platoon_table(_run(data, 'platoon_mariner_5_predecessor'))


@table('flagship', 'slow_autopilot')
def flagship_slow_autopilot(data):
    """The flagship's variant with the gain table's autopilot, a longer look-ahead and no lead:
    its tracking after settling, as the flagship's own line reads."""
    m = _run(data, 'flagship_mariner_slow_autopilot')
    v = m['vessels']['/vessel_0']
    return (f"Route completed in {fmt(v.get('time_to_complete_s'), '.0f')} s; after the "
            f"scenario's settling time: RMS cross-track {fmt(v['xte_rms_m'], '.1f')} m, max "
            f"{fmt(v['xte_max_abs_m'], '.1f')} m.\n")


def _platoon_table(metrics):
    return markdown_table([
        ('vessel', 'vessel', ''), ('follows', 'predecessor', ''),
        ('XTE RMS (m)', 'xte_rms_m', '.1f'), ('XTE peak (m)', 'xte_max_abs_m', '.1f'),
        ('peak / predecessor peak', 'string_peak_ratio', '.2f'),
        ('RMS / predecessor RMS', 'string_rms_ratio', '.2f'),
        ('gap error RMS (m)', 'gap_error_rms_m', '.1f'),
        ('route completed (s)', 'time_to_complete_s', '.1f'),
    ], _vessel_rows(metrics))


def _side(c):
    return f"{c['side']} ({c['bearing_at_min_deg']:.1f} deg from the bow)"


def _closest_rows(metrics):
    """Closest approaches of every colav vessel: to the other vessels (colav summary) and to the
    light and AIS targets (the metrics' traffic)."""
    rows = []
    for own, c in metrics.get('colav', {}).items():
        for other, d in c['closest'].items():
            rows.append({'own': own, 'other': other, **d})
    for name, t in metrics.get('traffic', {}).items():
        for own, d in (t.get('closest_approach') or {}).items():
            if d:
                rows.append({'own': own.strip('/'),
                             'other': f"{name.strip('/')} ({t.get('source')})",
                             **d})
    return rows


@table('encounters', 'closest')
def encounters_closest(data):
    """Per scenario: the closest approach of the own ship to each other ship or target."""
    rows = [{'scenario': name, **r} for name, m in data['runs'].items()
            for r in _closest_rows(m)]
    return markdown_table([
        ('scenario', 'scenario', ''), ('own ship', 'own', ''), ('other', 'other', ''),
        ('closest approach (m)', 'min_distance_m', '.1f'), ('at t (s)', 't_min_s', '.1f'),
        ('other on the own', _side, ''),
    ], rows)


@table('encounters', 'alterations')
def encounters_alterations(data):
    """Per scenario and colav vessel: its first avoiding decision and the offsets, its
    cross-track error after settling and at the end."""
    rows = []
    for name, m in data['runs'].items():
        for own, c in m.get('colav', {}).items():
            a = c['alteration']
            v = m['vessels'].get(f'/{own}', m['vessels'].get(own, {}))
            rows.append({'scenario': name, 'own': own, **a,
                         'first': 'never' if a['first_avoid_s'] is None
                         else f"{a['first_avoid_s']:.1f}",
                         'last_resort': 'yes' if a['last_resort'] else 'no',
                         'xte': f"{fmt(v.get('xte_rms_m'), '.0f')} / "
                                f"{fmt(v.get('xte_max_abs_m'), '.0f')}",
                         'wall': m['run']['wall_time_s'], 'sim': m['run']['sim_time_s']})
    return markdown_table([
        ('scenario', 'scenario', ''), ('own ship', 'own', ''),
        ('first alteration at t (s)', 'first', ''),
        ('its offset (deg, + starboard)', 'first_offset_deg', '+.0f'),
        ('largest offset against the current heading_ref (deg)', 'max_offset_deg', '+.1f'),
        ('last resort', 'last_resort', ''), ('cross-track RMS / max (m)', 'xte', ''),
        ('sim time (s)', 'sim', '.0f'), ('wall time (s)', 'wall', '.0f'),
    ], rows)
