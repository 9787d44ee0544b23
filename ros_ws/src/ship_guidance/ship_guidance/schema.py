"""Parameter schemas of the ship_guidance nodes (ship_sim.param_schema): guidance_node,
follower_node, ais_node, colav_node, nav_display_node, aivdm_out_node, tracker_node.

Pure: the nodes declare from these tables, scripts/gen_param_files.py writes config/*.yaml from
them and the launcher checks scenario values against them before anything starts.
"""
from ship_guidance import colav_io
import math

from ship_guidance.ais import KNOT, STALE_AFTER_S
from ship_guidance.ais_sensor import SensorConfig
from ship_guidance.colav_methods import METHODS
from ship_guidance.colav_params import ColavParams
from ship_guidance.follower import AIMS, MAX_SPEED_CORRECTION, SPACING_KI, SPACING_KP
from ship_guidance.guidance import LAWS
from ship_guidance.nav_display import DEFAULT_DISPLAY_RATE_HZ, DEFAULT_ORIGIN_DEG
from ship_guidance.node_defaults import FOLLOWER_DEFAULTS, GUIDANCE_DEFAULTS
from ship_guidance.own_ship_prediction import OwnShipModel
from ship_guidance.tracker import TrackerConfig
from ship_sim.models import MODEL_NAMES
from ship_sim.param_schema import NodeSchema, Param, readers_param

DEFAULTS = ColavParams()
SHIP = OwnShipModel()
SENSOR_DEFAULTS = SensorConfig()
TRACKER_DEFAULTS = TrackerConfig()
STEPPING_MODES = ('realtime', 'lockstep')


def non_empty_topic(name):
    return None if name.strip() else 'a non-empty topic name'


# (name, default, description, lo, hi, unit) of the scalar ColavParams / OwnShipModel keys.
SCALARS = (
    ('d_safe_m', DEFAULTS.d_safe_m, 'safe passing distance r_min', 1.0, 1e5, 'm'),
    ('near_miss_m', DEFAULTS.near_miss_m, 'near-miss radius r_nm (evaluation)', 1.0, 1e5, 'm'),
    ('collision_m', DEFAULTS.collision_m, 'collision radius r_col: last resort below it', 1.0,
     1e5, 'm'),
    ('threat_m', DEFAULTS.threat_m, 'a target is a threat within this of the nominal '
     'prediction', 1.0, 1e5, 'm'),
    ('d_close_m', DEFAULTS.d_close_m, 'COLREGs side rules apply to passes closer than this', 1.0,
     1e5, 'm'),
    ('horizon_s', DEFAULTS.horizon_s, 'prediction horizon', 1.0, 7200.0, 's'),
    ('dt_s', DEFAULTS.dt_s, 'prediction step', 0.1, 600.0, 's'),
    ('w_collision', DEFAULTS.w_collision, 'collision-risk weight', 0.0, 1e9, ''),
    ('relative_speed_floor', DEFAULTS.relative_speed_floor, 'floor of v_rel / U', 0.0, 10.0, ''),
    ('risk_time_exponent', DEFAULTS.risk_time_exponent, 'p of the risk', 0.0, 10.0, ''),
    ('risk_distance_exponent', DEFAULTS.risk_distance_exponent, 'q of the risk', 0.0, 10.0, ''),
    ('w_wrong_side', DEFAULTS.w_wrong_side, 'Rule 14/15 wrong-side penalty', 0.0, 1e9, ''),
    ('w_port_turn', DEFAULTS.w_port_turn, 'port-turn penalty (Rules 14, 15, 17(c))', 0.0, 1e9, ''),
    ('w_not_apparent', DEFAULTS.w_not_apparent, 'Rule 8(b) not-apparent penalty', 0.0, 1e9, ''),
    ('w_grounding', DEFAULTS.w_grounding, 'SB-MPC grounding weight (with chart_topic)', 0.0, 1e9,
     ''),
    ('grounding_clearance_m', DEFAULTS.grounding_clearance_m, 'distance kept from charted land '
     '(with chart_topic)', 0.0, 1e5, 'm'),
    ('apparent_course_change_deg', 30.0, 'apparent course change (Rule 8(b))', 0.0, 180.0, 'deg'),
    ('apparent_speed_ratio', DEFAULTS.apparent_speed_ratio, 'apparent speed reduction (Rule '
     '8(b)): predicted speed at the closest point at most this x nominal', 0.0, 1.0, ''),
    ('w_course_starboard', DEFAULTS.w_course_starboard, 'starboard deviation weight', 0.0, 1e9, ''),
    ('w_course_port', DEFAULTS.w_course_port, 'port deviation weight', 0.0, 1e9, ''),
    ('w_speed', DEFAULTS.w_speed, 'speed reduction weight', 0.0, 1e9, ''),
    ('w_change_course_starboard', DEFAULTS.w_change_course_starboard, 'change to starboard '
     'weight', 0.0, 1e9, ''),
    ('w_change_course_port', DEFAULTS.w_change_course_port, 'change to port weight', 0.0, 1e9, ''),
    ('w_change_speed', DEFAULTS.w_change_speed, 'speed change weight', 0.0, 1e9, ''),
    ('stand_on_dcpa_m', DEFAULTS.stand_on_dcpa_m, 'Rule 17(a)(ii): a stand-on ship acts when '
     'the command it keeps (the nominal; after an avoidance, the avoidance\'s) passes closer '
     'than this ...', 0.0, 1e5, 'm'),
    ('stand_on_act_time_s', DEFAULTS.stand_on_act_time_s, '... with the closest point this near '
     '(the give-way ship is late)', 0.0, 7200.0, 's'),
    ('uncertainty_k', DEFAULTS.uncertainty_k, 'a target\'s safe distance is d_safe_m + this x '
     'its position sigma (sqrt of the largest eigenvalue of its pose covariance)', 0.0, 100.0,
     ''),
    ('course_time_constant_s', SHIP.course_time_constant_s, 'own-ship model: Nomoto T, the '
     'turn rate\'s lag', 1e-3, 1e4, 's'),
    ('max_turn_rate', float(SHIP.max_turn_rate), 'own-ship model: turn-rate cap', 1e-6, 10.0, 'rad/s'),
    ('heading_loop_omega_n', SHIP.heading_loop_omega_n, 'own-ship model: natural frequency '
     'of the heading autopilot', 1e-6, 10.0, 'rad/s'),
    ('heading_loop_zeta', SHIP.heading_loop_zeta, 'own-ship model: damping of the heading '
     'autopilot', 1e-3, 10.0, ''),
    ('speed_time_constant_s', SHIP.speed_time_constant_s, 'own-ship model: speed lag', 1e-3, 1e5,
     's'),
    ('stop_turn_authority', SHIP.stop_turn_authority, 'own-ship model: turn authority with '
     'the shaft stopped (1: rudder independent of the shaft)', 0.0, 1.0, ''),
    ('speed_at_factor_one_mps', 0.0, 'own-ship model: speed at factor 1 (0: current speed)', 0.0,
     100.0, 'm/s'),
    ('turn_speed_loss_s', SHIP.turn_speed_loss_s, 'own-ship model: speed lost in a turn, k in '
     'u_dot = (u_c - u) / T_u - k u r^2 (0: none)', 0.0, 1e4, 's'),
)
LISTS = (('course_offsets_deg', [float(v) for v in range(-90, 91, 15)],
          'course offsets from the nominal (deg, + starboard; must hold 0)'),
         ('speed_factors', [1.0, 0.5, 0.0], 'speed multipliers in [0, 1] (must hold 1)'),
         ('target_topics', [''], 'Odometry topics of full vessels stepping in lockstep with '
          'this one (waited for at each decision); empty strings are ignored'))
#: The OwnShipModel keys among SCALARS (the rest are ColavParams').
OWN_SHIP_KEYS = ('course_time_constant_s', 'max_turn_rate', 'heading_loop_omega_n',
                 'heading_loop_zeta', 'speed_time_constant_s', 'stop_turn_authority',
                 'speed_at_factor_one_mps', 'turn_speed_loss_s')
#: sensor parameters: (name, description, lo, hi, unit); defaults from SensorConfig (SENSOR_DEFAULTS)
SENSOR_PARAMETERS = (
    ('loss_probability', 'share of reports lost (Gilbert-Elliott chain)', 0.0, 0.99, ''),
    ('mean_burst_length', 'mean number of reports lost in a row', 1.0, 1e6, 'reports'),
    ('position_sigma_m', 'GNSS position noise per axis', 0.0, 1e4, 'm'),
    ('sog_sigma_kn', 'SOG noise', 0.0, 100.0, 'kn'),
    ('cog_sigma_deg', 'COG noise', 0.0, 180.0, 'deg'),
    ('heading_sigma_deg', 'heading noise', 0.0, 180.0, 'deg'),
    ('latency_s', 'reception delay', 0.0, 3600.0, 's'),
    ('latency_jitter_s', 'reception delay spread: + U(0, jitter)', 0.0, 3600.0, 's'),
    ('turn_threshold_deg_min', 'rate of turn from which a vessel is "changing course"', 0.0,
     1e4, 'deg/min'),
)


GUIDANCE_NODE = NodeSchema('ship_guidance', 'guidance_node', summary='path following: LOS / ILOS '
                           'heading commands along the route', config_values={'use_sim_time': True},
                           params=(
    Param.of('law', GUIDANCE_DEFAULTS['law'], 'guidance law (course: follow course_schedule_deg)', choices=LAWS,
        read_only=True),
    Param('course_schedule_deg', 'float[]', [], 'law course: [t0, course0_deg, t1, course1_deg, '
          '...], sim time (s) and NED course (deg, clockwise from north) from that time on',
          read_only=True),
    Param.of('lookahead_m', GUIDANCE_DEFAULTS['lookahead_m'], 'LOS look-ahead distance', lo=1e-3, hi=1e6, unit='m',
        read_only=True),
    Param.of('lookahead_ship_lengths', 0.0, 'look-ahead in ship lengths (0: use lookahead_m)', lo=0.0, hi=1e3,
        read_only=True),
    Param.of('ship_length_m', 0.0, 'ship length for *_ship_lengths', lo=0.0, hi=1e4, unit='m', read_only=True),
    Param.of('acceptance_radius_m', 0.0, 'waypoint acceptance circle radius at '
        'corners (0: switch when passing the corner normal)', lo=0.0, hi=1e6, unit='m', read_only=True),
    Param.of('acceptance_radius_ship_lengths', 0.0, 'acceptance radius in ship '
        'lengths (0: use acceptance_radius_m)', lo=0.0, hi=1e3, read_only=True),
    Param.of('integral_gain', GUIDANCE_DEFAULTS['integral_gain'], 'ILOS integral gain sigma', lo=1e-6, hi=1e3,
        unit='m/s', read_only=True),
    Param.of('autopilot_zeta', 0.0, 'damping of the paired autopilot, for the '
        'stability check (0: no check)', lo=0.0, hi=10.0, read_only=True),
    Param.of('autopilot_omega_n', 0.0, 'natural frequency of the paired autopilot '
        '(0: no check)', lo=0.0, hi=100.0, unit='rad/s', read_only=True),
    Param.of('speed', 0.0, 'vessel speed for the stability check (0: no check)', lo=0.0, hi=100.0, unit='m/s',
        read_only=True),
    Param.of('allow_unstable', False, 'accept a look-ahead below the '
        'stability limit', read_only=True),
    Param.of('publish_path_state', False, 'also publish path_state, the path-relative state of the '
        'learned steering policy (autopilot controller: policy)', read_only=True),
    Param.of('curvature_lead', False, 'lead the heading command by '
        '2 zeta U kappa / omega_n on curves (needs the autopilot '
        'parameters of the stability check)', read_only=True),
    Param.of('arc_los_point', False, 'on circular arcs steer at the '
        'point of the circle one look-ahead ahead (Lee 2004 eq. '
        '4.24; law los, without curvature_lead)', read_only=True),
    Param.of('max_plausible_speed', 50.0, 'odometry implying a faster move '
        'than this since the previous sample is refused as an outlier', lo=1e-3, hi=1e4, unit='m/s', read_only=True),
    readers_param('heading_cmd'),
))

FOLLOWER_NODE = NodeSchema('ship_guidance', 'follower_node', summary='platoon follower: keeps a '
                           'gap to its predecessor', checks={'non_empty_topic': non_empty_topic},
                           params=(
    Param.of('predecessor_odom_topic', '/vessel_0/odom', "the predecessor's odometry topic", check='non_empty_topic',
        read_only=True),
    Param.of('spacing_m', 800.0, 'set along-path gap to the predecessor (the '
        "document's d2 at equilibrium)", lo=1e-3, hi=1e6, unit='m', read_only=True),
    Param.of('min_lookahead_m', FOLLOWER_DEFAULTS['min_lookahead_m'], 'smallest look-ahead used when the gap '
        'shrinks (must be above the stability limit)', lo=1e-3, hi=1e6, unit='m', read_only=True),
    Param.of('max_lookahead_m', FOLLOWER_DEFAULTS['max_lookahead_m'], 'largest look-ahead used when far behind '
        '(0: no cap)', lo=0.0, hi=1e7, unit='m', read_only=True),
    Param.of('lookahead_m', FOLLOWER_DEFAULTS['lookahead_m'], 'route LOS look-ahead (as guidance_node), used '
        'while the predecessor is stale', lo=1e-3, hi=1e6, unit='m', read_only=True),
    Param.of('acceptance_radius_m', 0.0, 'waypoint acceptance circle at corners (0: '
        'switch at the corner normal)', lo=0.0, hi=1e6, unit='m', read_only=True),
    Param.of('predecessor_timeout_s', 5.0, 'predecessor odometry older than this '
        '(sim time) -> route_fallback', lo=1e-3, hi=1e5, unit='s', read_only=True),
    Param.of('stepping_mode', 'realtime', 'lockstep: wait for the '
        "predecessor's sample at the own time (deterministic)", choices=STEPPING_MODES, read_only=True),
    Param.of('predecessor_wait_s', 2.0, 'lockstep: longest wall-time wait '
        'for the predecessor per step', lo=0.0, hi=600.0, unit='s', read_only=True),
    Param.of('spacing_kp', SPACING_KP, 'gap PI: proportional gain', lo=0.0, hi=10.0, unit='1/s', read_only=True),
    Param.of('spacing_ki', SPACING_KI, 'gap PI: integral gain (kp^2/4 is critically '
        'damped)', lo=0.0, hi=10.0, unit='1/s^2', read_only=True),
    Param.of('max_speed_correction', MAX_SPEED_CORRECTION, 'bound of the PI '
        "correction around the predecessor's speed", lo=0.0, hi=50.0, unit='m/s', read_only=True),
    Param.of('shaft_control', False, 'publish shaft_cmd (models with '
        'a shaft: tanker, container)', read_only=True),
    Param.of('shaft_nominal_rpm', 0.0, 'shaft speed giving '
        'speed_at_nominal_rpm (needed with shaft_control)', lo=0.0, hi=1e4, unit='rpm', read_only=True),
    Param.of('speed_at_nominal_rpm', 0.0, 'steady speed at shaft_nominal_rpm '
        '(needed with shaft_control)', lo=0.0, hi=100.0, unit='m/s', read_only=True),
    Param.of('shaft_min_rpm', 1.0, 'lower clip of shaft_cmd', lo=-1e4, hi=1e4, unit='rpm', read_only=True),
    Param.of('shaft_max_rpm', 1e4, 'upper clip of shaft_cmd', lo=-1e4, hi=1e4, unit='rpm', read_only=True),
    Param.of('autopilot_zeta', 0.0, 'damping of the paired autopilot, for the '
        'stability check (0: no check)', lo=0.0, hi=10.0, read_only=True),
    Param.of('autopilot_omega_n', 0.0, 'natural frequency of the paired autopilot '
        '(0: no check)', lo=0.0, hi=100.0, unit='rad/s', read_only=True),
    Param.of('speed', 0.0, 'vessel speed for the stability check (0: no check)', lo=0.0, hi=100.0, unit='m/s',
        read_only=True),
    Param.of('allow_unstable', False, 'accept look-aheads below the stability '
        'limit', read_only=True),
    Param.of('aim', 'predecessor', "steer at the predecessor (Angelopoulos 2011 eq. 31) or "
        'ILOS toward the path with look-ahead = gap (ship_guidance.follower)', choices=AIMS, read_only=True),
    Param.of('integral_gain', FOLLOWER_DEFAULTS['integral_gain'], 'integral action on the own cross-track error '
        '(Borhaug ILOS gain sigma; 0: none, Angelopoulos\'s law)', lo=0.0, hi=100.0, unit='m/s', read_only=True),
    Param.of('curvature_lead', False, 'lead the heading command by 2 zeta U kappa '
        '/ omega_n on curves (needs autopilot_zeta, autopilot_omega_n, speed)', read_only=True),
    Param.of('max_plausible_speed', 50.0, 'odometry (own or predecessor) '
        'implying a faster move than this since the previous sample is '
        'refused as an outlier', lo=1e-3, hi=1e4, unit='m/s', read_only=True),
    readers_param('heading_cmd'),
))

AIS_NODE = NodeSchema('ship_guidance', 'ais_node', summary='AIS targets from NMEA (replay file '
                      'or UDP)', config_values={'use_sim_time': True},
                      params=(
    Param.of('file', '', 'AIS replay file (empty: none); format in '
        'ship_guidance.ais.parse_replay', read_only=True),
    Param.of('file_rate_hz', 1.0, 'rate of the file lines without a time', lo=1e-3, hi=1e4, unit='Hz', read_only=True),
    Param.of('file_time_offset_s', 0.0, 'added to every replay time', lo=-1e9, hi=1e9, unit='s', read_only=True),
    Param.of('udp_port', 0, 'UDP port to receive NMEA on (0: no UDP)', lo=0, hi=65535, read_only=True),
    Param.of('udp_address', '127.0.0.1', 'local address to bind the UDP port '
        'to (0.0.0.0: every interface)', read_only=True),
    Param.of('origin_lat_deg', 0.0, 'geodetic origin of the local ENU frame', lo=-89.0, hi=89.0, unit='deg',
        read_only=True),
    Param.of('origin_lon_deg', 0.0, 'geodetic origin of the local ENU frame', lo=-180.0, hi=180.0, unit='deg',
        read_only=True),
    Param.of('stale_after_s', STALE_AFTER_S, 'drop a target after this long '
        'without a report (class A at anchor reports every 180 s)', lo=1.0, hi=86400.0, unit='s', read_only=True),
    Param.of('publish_period_s', 1.0, 'period of the target publication, on '
        'the node clock', lo=1e-3, hi=3600.0, unit='s', read_only=True),
    Param.of('per_target_topics', False, 'also publish each target on '
        'targets/ais_<mmsi>/odom', read_only=True),
    Param.of('publish_on_clock', False, 'publish at every /clock message, '
        'stamped with it, each step followed by targets_sync '
        '(lockstep graphs); else every publish_period_s', read_only=True),
    Param('wait_readers', 'str[]', [''], 'with publish_on_clock: full names of the nodes '
        'targets and targets_sync must serve before the node announces that it is ready (the '
        "launcher waits for it in lockstep; '' = none: at once)", read_only=True),
))

COLAV_NODE = NodeSchema('ship_guidance', 'colav_node', summary='collision avoidance between '
                        'guidance and autopilot', params=(
    Param.of('method', 'sbmpc', 'decision method', choices=tuple(METHODS), read_only=True),
    Param.of('decision_period_s', 1.0, 'sim time between decisions', lo=1e-3, hi=3600.0, unit='s', read_only=True),
    Param.of('targets_topic', 'targets', 'topic of many targets, each '
        'named by child_frame_id (relative: in this namespace; '
        "'': none)", read_only=True),
    Param.of('targets_sync_topic', '', 'announcements [stamp_ns, count] '
        "of the targets_topic's steps (ais_node's targets_sync with "
        "publish_on_clock): lockstep decisions wait until every "
        "target up to their stamp has come ('': none)", read_only=True),
    Param.of('target_stale_s', 30.0, 'a target state older than this (sim time) is '
        'not used', lo=0.0, hi=1e5, unit='s', read_only=True),
    Param.of('max_targets', colav_io.DEFAULT_MAX_TARGETS, 'live targets '
        'considered at most; beyond, the farthest from the own ship are '
        'left out (bounds the cost of a decision)', lo=1, hi=100000, read_only=True),
    Param.of('lockstep_target_timeout_s', 10.0, 'wall time a decision '
        'waits for a silent lockstep target before going on '
        'without it', lo=0.01, hi=1e4, unit='s', read_only=True),
    Param.of('pairing', 'sequence', 'sequence: the n-th odom with the n-th '
        'heading_ref, lockstep targets waited for (lockstep); latest: '
        'each odom with the last heading_ref, no waiting (realtime)', choices=('sequence', 'latest'), read_only=True),
    Param.of('has_shaft', True, 'own ship has a speed (shaft) command', read_only=True),
    Param.of('chart_topic', '', 'nav_msgs/OccupancyGrid of the chart (ENU '
        "map frame, unrotated, latched; cells >= 50 are land): SB-MPC's "
        "grounding cost ('': none)", read_only=True),
    *(Param.of(name, default, desc, lo=lo, hi=hi, unit=unit, read_only=True)
      for name, default, desc, lo, hi, unit in SCALARS),
    *(Param(name, f'{type(default[0]).__name__}[]', default, desc, read_only=True)
      for name, default, desc in LISTS),
    readers_param('heading_cmd'),
    readers_param('speed_factor_cmd'),
))

NAV_DISPLAY_NODE = NodeSchema('ship_guidance', 'nav_display_node', summary="the live view's "
                              'frames: fix, hull, wake trail and route', config_values={'use_sim_time': False},
                              params=(
    Param.of('model', 'mariner', 'ship model whose length the hull outline has', choices=MODEL_NAMES, read_only=True),
    Param.of('length_m', 0.0, 'hull length (0: the model\'s length between '
        'perpendiculars)', lo=0.0, hi=1e4, unit='m', read_only=True),
    Param.of('display_rate_hz', DEFAULT_DISPLAY_RATE_HZ, 'fix and markers per second of sim time', lo=0.01, hi=100.0,
        unit='Hz', read_only=True),
    Param.of('trail_length_s', 600.0, 'sim time the wake trail covers', lo=0.0, hi=1e6, unit='s', read_only=True),
    Param.of('trail_period_s', 5.0, 'sim time between wake trail points (the '
        'trail is sent when it gains one)', lo=0.01, hi=3600.0, unit='s', read_only=True),
    Param.of('route_period_s', 10.0, 'sim time between two frames that carry '
        'the route (a viewer that connects late gets it within that)', lo=0.01, hi=3600.0, unit='s', read_only=True),
    Param.of('origin_lat_deg', DEFAULT_ORIGIN_DEG[0], 'geodetic origin of the '
        'ENU frame: latitude', lo=-89.0, hi=89.0, unit='deg', read_only=True),
    Param.of('origin_lon_deg', DEFAULT_ORIGIN_DEG[1], 'geodetic origin of the '
        'ENU frame: longitude', lo=-180.0, hi=360.0, unit='deg', read_only=True),
    Param.of('odom_topic', 'odom_display', 'odometry input: '
        'odom_display (vessel_node display_every, qos DISPLAY) or '
        'a per-step stream (qos STREAM)', read_only=True),
    Param.of('wait_for_route', True, 'subscribe odometry only once the route '
        'has come (every frame then shows it)', read_only=True),
))

AIVDM_OUT_NODE = NodeSchema('ship_guidance', 'aivdm_out_node', summary='vessels as NMEA AIS '
                            'sentences for chart plotters', config_values={'use_sim_time': False},
                            params=(
    Param.of('vessels', '[]', 'JSON list of vessels: topic, mmsi and optional '
        'class, own, name, callsign, ship_type, length_m, beam_m, antenna_x_m, '
        'antenna_y_m', read_only=True),
    Param.of('udp', '127.0.0.1:10110', 'host:port to send the sentences to (empty: '
        'none)', read_only=True),
    Param.of('file', '', 'file to append the sentences to (empty: none)', read_only=True),
    Param.of('origin_lat_deg', 0.0, 'geodetic origin of the ENU frame', lo=-89.0, hi=89.0, unit='deg', read_only=True),
    Param.of('origin_lon_deg', 0.0, 'geodetic origin of the ENU frame', lo=-180.0, hi=180.0, unit='deg',
        read_only=True),
    Param.of('seed', SENSOR_DEFAULTS.seed, 'seed of the sensor model (with each MMSI)', lo=0, hi=2**62, read_only=True),
    *(Param.of(name, float(getattr(SENSOR_DEFAULTS, name)), desc, lo=lo, hi=hi, unit=unit,
               read_only=True)
      for name, desc, lo, hi, unit in SENSOR_PARAMETERS),
))

TRACKER_NODE = NodeSchema('ship_guidance', 'tracker_node', summary='AIS over UDP to Kalman tracks '
                          'with covariance', params=(
    Param.of('udp_port', 0, 'UDP port to receive AIS NMEA on', lo=0, hi=65535, read_only=True),
    Param.of('udp_address', '127.0.0.1', 'local address to bind the UDP port to (0.0.0.0: every '
             'interface)', read_only=True),
    Param.of('origin_lat_deg', 0.0, 'geodetic origin of the local ENU frame', lo=-89.0, hi=89.0,
             unit='deg', read_only=True),
    Param.of('origin_lon_deg', 0.0, 'geodetic origin of the local ENU frame', lo=-180.0,
             hi=180.0, unit='deg', read_only=True),
    Param.of('publish_period_s', 1.0, 'period of the track publication, on the node clock',
             lo=1e-3, hi=3600.0, unit='s', read_only=True),
    Param.of('process_noise', TRACKER_DEFAULTS.process_noise, 'acceleration power spectral '
             'density q of the nearly-constant-velocity model', lo=0.0, hi=100.0,
             unit='m^2/s^3', read_only=True),
    Param.of('position_sigma_m', TRACKER_DEFAULTS.position_sigma_m, 'AIS position noise per '
             'axis', lo=0.01, hi=1e4, unit='m', read_only=True),
    Param.of('sog_sigma_kn', TRACKER_DEFAULTS.sog_sigma_mps / KNOT, 'AIS SOG noise', lo=0.0,
             hi=100.0, unit='kn', read_only=True),
    Param.of('cog_sigma_deg', math.degrees(TRACKER_DEFAULTS.cog_sigma_rad), 'AIS COG noise',
             lo=0.0, hi=180.0, unit='deg', read_only=True),
    Param.of('reprocess_window_s', TRACKER_DEFAULTS.reprocess_window_s, 'a report up to this '
             "much older than its track's newest is retrodicted; older ones are dropped",
             lo=0.0, hi=3600.0, unit='s', read_only=True),
))

SCHEMAS = {s.node: s for s in (GUIDANCE_NODE, FOLLOWER_NODE, AIS_NODE, COLAV_NODE,
                               NAV_DISPLAY_NODE, AIVDM_OUT_NODE, TRACKER_NODE)}
