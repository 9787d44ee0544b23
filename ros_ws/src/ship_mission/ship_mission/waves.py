"""A vessel's ``waves:`` block of a scenario -> vessel_node's waves_* parameters (checked).

    waves: {hs_m: 3.0, tp_s: 9.0, spectrum: jonswap, direction_deg: 45.0, seed: 1}
    waves: {wind_speed_mps: 10.0, spectrum: torsethaugen, spreading: true}

direction_deg is where the waves travel towards, clockwise from north, as the current's.
Omitted keys take the node's defaults (ros_ws/src/ship_sim/config/vessel.yaml). A vessel whose
`autopilot:` block turns `wave_filter` on gets the filter tuned to this sea (peak period and
direction) unless the block tunes it itself.
"""
import math

from ship_mission.fields import need, number, unknown

#: scenario key -> (node parameter, kind, lo, hi)
WAVE_KEYS = {
    'hs_m': ('waves_hs', float, 0.0, 20.0),
    'wind_speed_mps': ('waves_wind_speed', float, 0.0, 40.0),
    'tp_s': ('waves_tp', float, 0.0, 30.0),
    'spectrum': ('waves_spectrum', str, None, None),
    'gamma': ('waves_gamma', float, 0.0, 7.0),
    'direction_deg': ('waves_direction_deg', float, -360.0, 360.0),
    'spreading': ('waves_spreading', bool, None, None),
    'n_frequencies': ('waves_n_frequencies', int, 1, 2000),
    'n_directions': ('waves_n_directions', int, 2, 100),
    'omega_max_rad_s': ('waves_omega_max', float, 0.5, 6.0),
    'seed': ('waves_seed', int, 0, 2**31 - 1),
}
SPECTRA = ('jonswap', 'modified_pm', 'torsethaugen')


def wave_parameters(waves, path, where):
    """The vessel_node parameters of a checked ``waves`` mapping; ScenarioError names the key."""
    need(isinstance(waves, dict), path, where.rstrip('.'), 'a mapping')
    unknown(waves, set(WAVE_KEYS), path, where)
    need(not (waves.get('hs_m') and waves.get('wind_speed_mps')), path, where + 'wind_speed_mps',
         'give hs_m or wind_speed_mps, not both')
    out = {}
    for key, value in waves.items():
        param, kind, lo, hi = WAVE_KEYS[key]
        if kind is float:
            out[param] = number(waves, key, path, None, lo=lo, hi=hi, where=where)
        elif kind is int:
            need(isinstance(value, int) and not isinstance(value, bool) and lo <= value <= hi,
                 path, where + key, f'an integer in [{lo}, {hi}], got {value!r}')
            out[param] = value
        elif kind is bool:
            need(isinstance(value, bool), path, where + key, f'true or false, got {value!r}')
            out[param] = value
        else:
            need(value in SPECTRA, path, where + key, f'one of {", ".join(SPECTRA)}, got '
                 f'{value!r}')
            out[param] = value
    return out


def wave_filter_parameters(wave_params, autopilot_params):
    """Autopilot parameters that tune an enabled wave filter to the vessel's sea: its peak
    period and direction, unless the `autopilot:` block sets the filter's frequency or period
    itself ({} otherwise). The block's own keys still win (the launcher applies them last)."""
    if not autopilot_params.get('wave_filter') or not wave_params or \
            autopilot_params.get('wave_filter_frequency') or \
            autopilot_params.get('wave_filter_peak_period'):
        return {}
    from ship_sim.environment.sea_state_relations import vw2hs
    from ship_sim.environment.sea_state import pm_peak_frequency
    hs = wave_params.get('waves_hs') or float(vw2hs(wave_params.get('waves_wind_speed', 0.0)))
    if not hs:
        return {}
    tp = wave_params.get('waves_tp') or 2.0 * math.pi / pm_peak_frequency(hs)
    return {'wave_filter_peak_period': float(tp),
            'wave_filter_direction_deg': float(wave_params.get('waves_direction_deg', 0.0))}
