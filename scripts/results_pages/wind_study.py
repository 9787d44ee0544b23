"""Tables of the wind study (scripts/wind_study.py, its wind_study.json): the flagship's
closed loop at several wind speeds or in the study's wind-and-wave conditions
(doc/results/wind_waves.md), and the flagship scenario itself, which is the study's run without
wind (doc/results/flagship.md)."""
from results_pages.registry import table
from results_pages.tables import fmt, markdown_table


def _finished(r):
    if not r['finished']:
        return 'no'
    return 'yes' if r.get('time_to_complete_s') is None else f"{r['time_to_complete_s']:.1f}"


def _max_rudder(r):
    """The largest rudder angle, '(limit)' when the metrics counted samples at the limit."""
    text = f"{r['rudder_max_abs_deg']:.1f}"
    return text + ' (limit)' if r.get('rudder_saturated_fraction') else text


def _calm(data):
    """The row of the undisturbed run: 0 m/s, or the calm condition."""
    for r in data['rows']:
        if r['condition'] in ('-', 'calm') and r['wind_mps'] == 0:
            return r
    raise KeyError('the wind study has no run without wind')


@table('wind_study', 'speeds')
def speeds(data):
    return markdown_table([
        ('wind (m/s)', 'wind_mps', 'g'), ('finished (s)', _finished, ''),
        ('XTE RMS (m)', 'xte_rms_m', '.2f'), ('XTE max (m)', 'xte_max_m', '.2f'),
        ('heading error RMS (deg)', 'heading_rms_deg', '.2f'),
        ('mean abs rudder (deg)', 'rudder_mean_abs_deg', '.2f'),
        ('max abs rudder (deg)', _max_rudder, ''),
        ('mean abs rudder rate (deg/s)', 'rudder_rate_mean_abs_deg_s', '.3f'),
        ('rudder total variation (deg)', 'rudder_tv_deg', '.0f'),
    ], data['rows'])


@table('wind_study', 'conditions')
def conditions(data):
    return markdown_table([
        ('condition', 'condition', ''), ('finished (s)', _finished, ''),
        ('XTE RMS / max (m)', lambda r: f"{r['xte_rms_m']:.2f} / {r['xte_max_m']:.2f}", ''),
        ('heading error RMS (deg)', 'heading_rms_deg', '.2f'),
        ('mean abs rudder (deg)', 'rudder_mean_abs_deg', '.2f'),
        ('max abs rudder (deg)', _max_rudder, ''),
        ('mean abs rudder rate (deg/s)', 'rudder_rate_mean_abs_deg_s', '.3f'),
        ('rudder TV (deg)', 'rudder_tv_deg', '.0f'),
        ('rudder saturated', lambda r: 100 * r['rudder_saturated_fraction'], '.1f'),
        ('reward', 'reward_gaussian_sum', '.0f'),
    ], data['rows']) + '\n(rudder saturated: % of the samples after settling)\n'


@table('wind_study', 'flagship')
def flagship(data):
    r = _calm(data)
    done = (f"completed in {fmt(r.get('time_to_complete_s'), '.0f')} s" if r['finished']
            else 'not completed')
    return (f"Route {done}; after the scenario's settling "
            f"time: RMS cross-track {r['xte_rms_m']:.1f} m, max {r['xte_max_m']:.1f} m; heading "
            f"error RMS {r['heading_rms_deg']:.2f} deg; mean abs rudder "
            f"{r['rudder_mean_abs_deg']:.2f} deg (max {r['rudder_max_abs_deg']:.1f} deg), mean "
            f"abs rudder rate {r['rudder_rate_mean_abs_deg_s']:.3f} deg/s.\n")
