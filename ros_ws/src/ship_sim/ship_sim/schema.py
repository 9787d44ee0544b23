"""Parameter schemas of the ship_sim nodes (ship_sim.param_schema): vessel_node, traffic_node.

Pure: the nodes declare from these tables, scripts/gen_param_files.py writes config/*.yaml from
them and the launcher checks scenario values against them before anything starts.
"""
from ship_sim.environment.sea_state import SPECTRUM_NAMES
from ship_sim.environment.wind import COEFFICIENTS, WindField
from ship_sim.light_traffic import parse_targets
from ship_sim import models
from ship_sim.param_schema import NodeSchema, Param


def light_targets_problem(text):
    """None if ``text`` is a valid JSON list of light targets, else why not."""
    try:
        parse_targets(text)
    except ValueError as exc:
        return str(exc)
    return None


def registered_model_problem(name):
    """None if ``name`` is a registered vessel card, looked up when asked (cards may be
    registered after this module is imported), else what is allowed."""
    if name in models.MODEL_NAMES:
        return None
    return 'one of ' + ', '.join(repr(n) for n in models.MODEL_NAMES)


VESSEL_NODE = NodeSchema('ship_sim', 'vessel_node', summary='the plant: a ship model, its '
                         'environment and the simulation clock', params=(
    Param.of('model', 'mariner', 'plant model: the name of a registered vessel card (mariner, '
        'tanker, container, nomoto1, nomoto2, nps_auv2, and any card added by SHIPNAV_EXTRA_CARDS)',
        read_only=True, check='registered_model'),
    Param.of('preset', '', "model preset ('' = the model's default; nomoto1/"
        'nomoto2: mariner or tanker)', read_only=True),
    Param.of('nominal_speed_mps', 0.0, 'nominal speed of the model (mariner U0, nomoto/nps_auv2 '
        "U); 0 = the model's default", lo=0.0, hi=30.0, unit='m/s', read_only=True,
        deprecated_names=('U0',)),
    Param.of('water_depth_m', 0.0, "water depth (tanker h >= 18.5 m); 0 = the model's "
        'default (deep water)', lo=0.0, hi=1e4, unit='m', read_only=True,
        deprecated_names=('depth',)),
    Param.of('rudder_max_deg', 0.0, "rudder angle limit override; 0 = the model's", lo=0.0, hi=90.0, unit='deg',
        read_only=True),
    Param.of('rudder_rate_max_deg', 0.0, "rudder rate limit override; 0 = the "
        "model's", lo=0.0, hi=1e3, unit='deg/s', read_only=True),
    Param.of('initial_x', 0.0, 'start position east (ENU x)', lo=-1e7, hi=1e7, unit='m', read_only=True),
    Param.of('initial_y', 0.0, 'start position north (ENU y)', lo=-1e7, hi=1e7, unit='m', read_only=True),
    Param.of('initial_yaw_deg', 90.0, 'start heading as ENU yaw (counter-clockwise '
        'from east; 90 = heading north)', lo=-360.0, hi=360.0, unit='deg', read_only=True),
    Param.of('initial_speed', 0.0, "start speed through the water; 0 = the model's "
        'straight-running trim (MSS ships cannot start at rest)', lo=0.0, hi=30.0, unit='m/s', read_only=True),
    Param.of('shaft_rpm', 0.0, 'shaft speed command held until a shaft_cmd comes '
        "(models with a shaft); 0 = the model's nominal", lo=-1e3, hi=1e3, unit='rpm', read_only=True),
    Param.of('dt', 0.1, 'integration step', lo=1e-4, hi=1.0, unit='s', read_only=True),
    Param.of('publish_rate', 10.0, 'steps per sim second: odom, rudder and /clock '
        'are published (and in lockstep a command is awaited) once per step; '
        '1/publish_rate must be a whole multiple of dt', lo=0.01, hi=1000.0, unit='Hz', read_only=True,
        check='substeps_of_dt'),
    Param.of('stepping_mode', 'realtime', 'realtime: wall-clock paced; '
        'lockstep: advance only when the step\'s rudder_cmd has come', choices=('realtime', 'lockstep'),
        read_only=True),
    Param.of('speedup', 1.0, 'realtime: sim seconds per wall second', lo=0.01, hi=1e4),
    Param.of('lockstep_timeout', 5.0, 'lockstep: wall time to wait for a step\'s rudder_cmd; then '
        'warn and hold the previous command for that step (0 = wait forever)', lo=0.0, hi=3600.0, unit='s'),
    Param.of('lockstep_start_timeout', 30.0, 'lockstep: wall time to wait for an odom subscriber '
        'and a rudder_cmd publisher before step 0 (then start anyway, with a warning)', lo=0.0, hi=3600.0, unit='s',
        read_only=True),
    Param.of('lockstep_max_timeouts', 10, 'lockstep: consecutive steps without their rudder_cmd '
        'after which the run ends with an error (exit code 1; 0 = never end)', lo=0, hi=10**6, read_only=True),
    Param.of('lockstep_record_topic', '', 'lockstep: topic (std_msgs/UInt64) on which a recorder '
        'acknowledges the steps it holds; the node waits for it before step 0 and then runs '
        'at most lockstep_record_window steps ahead of it, so the recording loses nothing '
        "('' = no recorder takes part)", read_only=True),
    Param.of('lockstep_record_window', 4, 'lockstep: steps the simulator may run ahead of the '
        "recorder's acknowledgement (below the /clock queue depth of 10)", lo=0, hi=8, read_only=True),
    Param.of('lockstep_follower_odom_topics', '', "lockstep: comma-separated odom topics of this "
        "vessel's platoon followers; the node runs at most lockstep_follower_window steps "
        "ahead of the slowest, so its odom queue never overwrites a sample a follower has not "
        "taken ('' = none)", read_only=True),
    Param.of('lockstep_follower_window', 50, 'lockstep: steps the simulator may run ahead of its '
        'slowest follower (below the odom queue depth of 100)', lo=1, hi=90, read_only=True),
    Param.of('command_timeout_s', 5.0, 'realtime: sim time without a rudder_cmd after which the '
        'rudder is centred, with a warning, until commands come again (0 = hold the last '
        'command for ever)', lo=0.0, hi=1e6, unit='s', read_only=True),
    Param('lockstep_odom_readers', 'str[]', [''], 'lockstep: full names of the nodes that must '
        "follow odom before step 0 (e.g. /vessel_0/guidance_node); '' = none: any one subscriber",
        read_only=True),
    Param.of('display_every', 0, 'also publish every n-th step\'s odom on odom_display (0 = '
        'never): nav_display_node\'s input, reliable + transient_local with a deep history '
        '(qos.DISPLAY), so the display gets the same frames on every run whatever its lag, '
        'and one callback per frame instead of one per step', lo=0, hi=10**6, read_only=True),
    Param.of('clock_master', True, 'publish /clock (exactly one node '
        'of a graph does)', read_only=True),
    Param.of('max_steps', 0, 'end the run cleanly after this many steps '
        '(0 = run until stopped; lockstep: once the last step is answered and '
        'recorded)', lo=0, hi=10**12, read_only=True),
    Param.of('speed_factor_input', False, 'subscribe speed_factor_cmd (colav_node): the shaft '
        'runs at factor x the shaft command (models with a shaft; lockstep: each step waits '
        'for its factor)', read_only=True),
    Param.of('current_speed', 0.0, 'ocean current mean speed', lo=0.0, hi=10.0, unit='m/s', read_only=True),
    Param.of('current_direction_deg', 0.0, 'direction the current flows towards, '
        'clockwise from north (0 = northwards, 90 = eastwards)', lo=-360.0, hi=360.0, unit='deg', read_only=True),
    Param.of('current_speed_sd', 0.0, 'current variability: stationary standard '
        'deviation of the speed (Gauss-Markov; 0 = constant)', lo=0.0, hi=5.0, unit='m/s', read_only=True),
    Param.of('current_direction_sd_deg', 0.0, 'current variability: stationary '
        'standard deviation of the direction (0 = constant)', lo=0.0, hi=180.0, unit='deg', read_only=True),
    Param.of('current_time_constant', 600.0, 'time constant of the current\'s '
        'Gauss-Markov variations', lo=1.0, hi=1e6, unit='s', read_only=True),
    Param.of('current_seed', 0, 'random seed of the current variations (same '
        'seed, same current)', lo=0, hi=2**31 - 1, read_only=True),
    Param.of('wind_speed', 0.0, 'mean wind speed (0 and no gusts = no wind)', lo=0.0, hi=WindField.MAX_SPEED,
        unit='m/s', read_only=True),
    Param.of('wind_direction_deg', 0.0, 'direction the wind blows FROM, clockwise '
        'from north (meteorological: 0 = a north wind, blowing southwards)', lo=-360.0, hi=360.0, unit='deg',
        read_only=True),
    Param.of('wind_gust_sd', 0.0, 'gusts: stationary standard deviation of the wind '
        'speed (Gauss-Markov; 0 = steady)', lo=0.0, hi=30.0, unit='m/s', read_only=True),
    Param.of('wind_time_constant', 60.0, "time constant of the gusts' Gauss-Markov "
        'process', lo=0.1, hi=1e6, unit='s', read_only=True),
    Param.of('wind_seed', 0, 'random seed of the gusts (same seed, same wind)', lo=0, hi=2**31 - 1, read_only=True),
    Param.of('wind_coefficients', 'blendermann94', 'wind load coefficients: '
        'Blendermann 1994 (with roll) or Isherwood 1972', choices=COEFFICIENTS, read_only=True),
    Param.of('waves_hs', 0.0, 'significant wave height (0 = calm sea; see also '
        'waves_wind_speed)', lo=0.0, hi=20.0, unit='m', read_only=True),
    Param.of('waves_wind_speed', 0.0, 'fully developed sea of this wind speed: Hs = '
        '0.21 V^2 / g (MSS vw2hs), Pierson-Moskowitz peak (0 = use waves_hs)', lo=0.0, hi=40.0, unit='m/s',
        read_only=True),
    Param.of('waves_tp', 0.0, 'peak period (0 = the Pierson-Moskowitz peak of the Hs)', lo=0.0, hi=30.0, unit='s',
        read_only=True),
    Param.of('waves_spectrum', 'jonswap', 'wave spectrum', choices=tuple(SPECTRUM_NAMES), read_only=True),
    Param.of('waves_gamma', 3.3, 'JONSWAP peak enhancement (0 = DNV rule)', lo=0.0, hi=7.0, read_only=True),
    Param.of('waves_direction_deg', 0.0, 'main direction the waves travel '
        'towards, clockwise from north (as the current)', lo=-360.0, hi=360.0, unit='deg', read_only=True),
    Param.of('waves_spreading', False, 'cos^2 directional spreading', read_only=True),
    Param.of('waves_n_frequencies', 100, 'wave components in frequency', lo=1, hi=2000, read_only=True),
    Param.of('waves_n_directions', 16, 'wave directions with spreading', lo=2, hi=100, read_only=True),
    Param.of('waves_omega_max', 3.0, 'highest wave frequency', lo=0.5, hi=6.0, unit='rad/s', read_only=True),
    Param.of('waves_seed', 0, 'random seed of the wave components (same seed, same '
        'waves)', lo=0, hi=2**31 - 1, read_only=True),
), checks={'registered_model': registered_model_problem})
# publish_rate's 'substeps_of_dt' needs dt's value: vessel_node gives it.

TRAFFIC_NODE = NodeSchema('ship_sim', 'traffic_node', summary='light targets on straight '
                          'courses or waypoints', checks={'light_targets': light_targets_problem},
                          params=(
    Param.of('targets', '[]', 'light targets as JSON: a list of {name, x_m, y_m, '
        'course_deg, speed_mps} or {name, waypoints: [[t_s, x_m, y_m], ...]} '
        '(ENU; course clockwise from north), each with an optional behaviour '
        '(straight or no_alteration)', check='light_targets', allowed='a JSON list of light targets',
        read_only=True),
    Param('wait_readers', 'str[]', [''], 'full names of the nodes every target topic must '
        "serve before the node announces that it is ready (the launcher waits for it in lockstep; "
        "'' = none: at once)", read_only=True),
))

SCHEMAS = {s.node: s for s in (VESSEL_NODE, TRAFFIC_NODE)}
