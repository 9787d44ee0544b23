"""Parameter schema of autopilot_node (ship_sim.param_schema).

Pure: the node declares from this table, scripts/gen_param_files.py writes config/autopilot.yaml
from it and the launcher checks scenario values against it before anything starts.
"""
from ship_autopilot.gains import CONTROLLERS, FUZZY_SCALING_PARAMETERS, ZETA
from ship_sim.models import MODEL_NAMES
from ship_sim.param_schema import NodeSchema, Param, readers_param

AUTOPILOT_NODE = NodeSchema('ship_autopilot', 'autopilot_node', summary='heading autopilot: '
                            'rudder commands from heading commands',
                            config_values={'use_sim_time': True}, params=(
    Param.of('vessel_model', 'mariner', 'vessel model the gains and rudder limits '
        'are taken from', choices=MODEL_NAMES, read_only=True),
    Param.of('controller', 'pd', 'heading controller (policy: learned steering on '
        'the guidance node\'s path_state)', choices=CONTROLLERS + ('policy',), read_only=True),
    Param.of('policy_file', '', 'controller policy: policy file (.npz; empty: '
        'the one shipped for vessel_model)', read_only=True),
    Param.of('k1', 0.0, 'PD heading gain (0: from the gain table)', lo=0.0, hi=1e3, unit='rad/rad', read_only=True),
    Param.of('k2', 0.0, 'PD yaw-rate gain (0: from the gain table)', lo=0.0, hi=1e5, unit='rad/(rad/s)',
        read_only=True),
    *(Param.of(name, 0.0, f"fuzzy PID scaling {field} (0: the gain table's; GE, GR, GA, GU all > 0 "
               'or all 0; L 0 = 1)', lo=0.0, hi=1e6, unit=unit, read_only=True)
      for (name, field), unit in zip(FUZZY_SCALING_PARAMETERS.items(),
                                     ('1/rad', 's/rad', '1/(rad s)', 'rad', ''))),
    Param.of('omega_n', 0.0, 'redesign PD gains for this natural frequency '
        '(0: gain table)', lo=0.0, hi=100.0, unit='rad/s', read_only=True),
    Param.of('zeta', ZETA, 'damping ratio used with omega_n', lo=0.05, hi=5.0, read_only=True),
    Param.of('rudder_max_deg', 0.0, 'rudder angle limit (0: the model\'s)', lo=0.0, hi=90.0, unit='deg',
        read_only=True),
    Param.of('rudder_rate_max_deg', 0.0, 'rudder rate limit (0: the model\'s)', lo=0.0, hi=1e3, unit='deg/s',
        read_only=True),
    Param.of('saturation', 'hard', 'rudder saturation form (tanh: Angelopoulos '
        '2011, eq. 15)', choices=('hard', 'tanh'), read_only=True),
    Param.of('pairing', 'sequence', 'how odom and heading_cmd are paired', choices=('sequence', 'latest'),
        read_only=True),
    Param.of('heading_timeout_s', 5.0, 'sim time without heading_cmd after '
        'which the command counts as stale (latest pairing)', lo=0.01, hi=1e4, unit='s', read_only=True),
    Param.of('policy_recovery', True, 'controller policy: steer with ILOS + the '
        'gain-table PD while the vessel is outside the policy\'s training '
        'region (|e| beyond its start range, or heading > 90 deg off the '
        'path), hand back within half that range', read_only=True),
    Param.of('wave_filter', False, 'filter the wave-frequency yaw out of the heading '
        'and yaw rate the controller sees (notch at the encounter frequency + '
        'low-pass; classical controllers)', read_only=True),
    Param.of('wave_filter_frequency', 0.0, 'fixed notch frequency (0: the encounter '
        'frequency of wave_filter_peak_period and wave_filter_direction_deg at '
        "the vessel's speed and heading)", lo=0.0, hi=10.0, unit='rad/s', read_only=True),
    Param.of('wave_filter_peak_period', 0.0, "the sea's peak period (the notch "
        'follows its encounter frequency)', lo=0.0, hi=30.0, unit='s', read_only=True),
    Param.of('wave_filter_direction_deg', 0.0, 'direction the waves travel '
        'towards, clockwise from north (as waves_direction_deg)', lo=-360.0, hi=360.0, unit='deg', read_only=True),
    Param.of('wave_filter_zeta', 0.1, 'notch gain at its frequency (depth/width)', lo=0.01, hi=0.99, read_only=True),
    Param.of('wave_filter_lowpass', 0.0, 'low-pass corner (0: the notch '
        'frequency)', lo=0.0, hi=10.0, unit='rad/s', read_only=True),
    readers_param('rudder_cmd'),
))

SCHEMAS = {AUTOPILOT_NODE.node: AUTOPILOT_NODE}
