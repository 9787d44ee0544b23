"""What each key of metrics.json means: its unit and a one-line description, the one table the
report (ship_mission.html_report) and the run's closing lines (ship_mission.console) read.

metrics.json is data and keeps SI units and radians (the unit is the key's suffix); a person
reads angles in degrees, so ``shown`` converts a value of unit 'rad' or 'rad/s' to degrees for
display. Sections: ``VESSEL`` (ship_mission.metrics.vessel_metrics and what ship_mission.report adds per
vessel), ``TRAFFIC`` (per target, ship_mission.report.traffic_metrics) and ``PLATOON`` (per vessel of
a platoon, ship_mission.report.platoon_metrics). A key written without an entry here fails
tests/unit/test_report_plots.py.
"""
import math

# unit '' : a count, a ratio, a flag or a text
_RUDDER = {   # rudder_stats(prefix=...): the same statistics of the actual angle and the command
    'mean_abs_rad': ('rad', 'mean |angle| after settling'),
    'rms_rad': ('rad', 'RMS angle after settling'),
    'max_abs_rad': ('rad', 'largest |angle| after settling'),
    'total_variation_rad_per_s': ('rad/s', 'sum of |angle changes| per second after settling '
                                  '(how busy the steering is)'),
    'saturated_samples': ('', 'samples at the rudder limit after settling'),
    'saturated_fraction': ('', 'share of the samples at the rudder limit after settling'),
    'samples': ('', 'samples after settling'),
}

VESSEL = {
    'duration_s': ('s', 'time from the first odometry sample to the end of the record '
                        '(the route completion)'),
    'start_time_s': ('s', 'sim time of the first odometry sample'),
    'settle_s': ('s', 'settling window from the start that the cross-track, heading and rudder '
                      'statistics leave out (the approach to the path)'),
    'odom_samples': ('', 'odometry messages in the record'),
    'distance_travelled_m': ('m', 'length of the track sailed'),
    'route_length_m': ('m', 'length of the route polyline'),
    'finished': ('', 'whether the route was completed'),
    'completion_source': ('', "what decided the completion: 'guidance' (its finish flag) or "
                              "'route' (the track reached the route's end)"),
    'time_to_complete_s': ('s', 'time from the start to the route completion'),
    'remaining_at_end_m': ('m', 'distance along the route left at the end of the record'),
    'path_yaw_error_max_abs_rad': ('rad', 'largest |heading - path direction| after settling'),
    'xte_source': ('', "where the cross-track error comes from: 'topic' (the guidance's own) or "
                       "'route' (computed from the track and the route)"),
    'xte_rms_m': ('m', 'RMS cross-track error after settling'),
    'xte_max_abs_m': ('m', 'largest |cross-track error| after settling'),
    'xte_mean_m': ('m', 'mean cross-track error after settling (+ = starboard of the path)'),
    'xte_samples': ('', 'cross-track error samples after settling'),
    'reward_gaussian_sum': ('', 'cumulative Gaussian reward of Martinsen and Lekkas 2018 '
                                '(eq. 8, Table I) over the whole record'),
    'reward_gaussian_integral_s': ('s', 'the reward sum times its step: the same figure '
                                        'independent of the sampling'),
    'reward_steps': ('', 'grid points the reward is summed over'),
    'reward_step_s': ('s', 'step of the reward grid'),
    'reward_sigma_m': ('m', 'standard deviation of the Gaussian reward'),
    'reward_episode_s': ('s', 'time the reward covers'),
    'xte_route_rms_m': ('m', 'RMS cross-track error after settling, from the track and the '
                             'route geometry (a check on the guidance\'s own)'),
    **{f'rudder_{k}': (u, f'rudder (actual): {d}') for k, (u, d) in _RUDDER.items()},
    **{f'rudder_cmd_{k}': (u, f'rudder command: {d}') for k, (u, d) in _RUDDER.items()},
    'heading_error_rms_rad': ('rad', 'RMS heading - heading command after settling'),
    'heading_error_max_abs_rad': ('rad', 'largest |heading - heading command| after settling'),
    'heading_error_mean_rad': ('rad', 'mean heading - heading command after settling'),
    'heading_error_samples': ('', 'heading command samples after settling'),
    'rudder_limit_rad': ('rad', 'rudder limit the saturation counts use'),
    'missing_topics': ('', 'topics of the vessel absent from the record'),
    'computed_over_gaps': ('', 'inputs whose record has gaps (their metrics cover less)'),
    'completion_cut': ('', 'what ended the vessel\'s record (its route completion), if anything'),
    'error': ('', 'why no metrics were computed'),
}

TRAFFIC = {
    'source': ('', "'light' (a traffic_node target) or 'ais' (a target of ais_node)"),
    'duration_s': ('s', 'time the target\'s track covers'),
    'start_time_s': ('s', 'sim time of the target\'s first sample'),
    'odom_samples': ('', 'samples of the target\'s track'),
    'distance_travelled_m': ('m', 'length of the target\'s track'),
    'speed_mean_mps': ('m/s', 'mean speed over ground of the target'),
    'closest_approach': ('', 'per vessel: smallest distance (m), its time (s), the target\'s '
                             'relative bearing there (deg) and side'),
}

PLATOON = {
    'predecessor': ('', 'the vessel this one follows (none for the leader)'),
    'xte_peak_m': ('m', 'largest |cross-track error| after settling'),
    'xte_rms_m': VESSEL['xte_rms_m'],
    'time_to_complete_s': VESSEL['time_to_complete_s'],
    'completion_source': VESSEL['completion_source'],
    'string_peak_ratio': ('', 'peak |cross-track error| over the predecessor\'s '
                              '(> 1: the deviation grew down the string)'),
    'string_rms_ratio': ('', 'RMS cross-track error over the predecessor\'s'),
    'gap_error_rms_m': ('m', 'RMS gap error (gap - spacing) after settling'),
    'gap_error_mean_m': ('m', 'mean gap error after settling (+ = too far behind)'),
    'gap_error_max_abs_m': ('m', 'largest |gap error| after settling'),
    'gap_error_samples': ('', 'gap error samples after settling'),
    'gap_error_undefined_samples': ('', 'gap error samples without a value (the follower on '
                                        'its route fallback)'),
}

#: stored unit -> (factor, unit shown) for a person: angles in degrees
DISPLAY = {'rad': (math.degrees(1.0), 'deg'), 'rad/s': (math.degrees(1.0), 'deg/s')}


def shown(value, unit):
    """(value, unit) as a person reads them: radians to degrees; other values unchanged."""
    factor, shown_unit = DISPLAY.get(unit, (1.0, unit))
    if factor != 1.0 and isinstance(value, (int, float)) and not isinstance(value, bool):
        return value * factor, shown_unit
    return value, shown_unit



#: the key suffixes that name a stored unit (ship_mission.metrics: "key names carry units")
_SUFFIXES = {'rad/s': '_rad_per_s', 'rad': '_rad', 'm/s': '_mps', 'm': '_m', 's': '_s'}


def plain_name(key, unit):
    """``key`` without the suffix naming its stored unit, for a line that gives the unit shown
    (xte_rms_m -> xte_rms, rudder_mean_abs_rad -> rudder_mean_abs)."""
    suffix = _SUFFIXES.get(unit)
    return key[:-len(suffix)] if suffix and key.endswith(suffix) else key
