"""The `wind:` block of a scenario: checked here, passed to vessel_node as its wind_* parameters.

    wind:                           # top level: the wind of every vessel (platoon, traffic too)
      speed_mps: 10.0               # mean speed
      direction_deg: 270.0          # where it blows FROM, clockwise from north (meteorological)
      gust_sd_mps: 1.5              # optional gusts: stationary sd of the speed (Gauss-Markov)
      time_constant_s: 60.0         # their time constant
      seed: 7                       # their random seed
      coefficients: blendermann94   # or isherwood72
    vessels:
      vessel_0: {..., wind: {speed_mps: 0.0}}   # a vessel's own block replaces the scenario's

The bag records each vessel's wind in its metadata (custom_data key ``mission.wind/<vessel>``,
the block as JSON), beside the run folder's params/ files (``wind_*`` of vessel_node).
"""
import json

from ship_mission.fields import need, number, unknown

#: scenario key -> (vessel_node parameter, lower bound, upper bound) for the numbers
NUMBERS = {
    'speed_mps': ('wind_speed', 0.0, 60.0),
    'direction_deg': ('wind_direction_deg', -360.0, 360.0),
    'gust_sd_mps': ('wind_gust_sd', 0.0, 30.0),
    'time_constant_s': ('wind_time_constant', 0.1, 1e6),
}
COEFFICIENTS = ('blendermann94', 'isherwood72')
KEYS = set(NUMBERS) | {'seed', 'coefficients'}


def check_wind(block, path, where):
    """The checked wind mapping ({} for none); ScenarioError names the file and the key."""
    block = {} if block is None else block
    need(isinstance(block, dict), path, where, 'a mapping (speed_mps, direction_deg, ...)')
    unknown(block, KEYS, path, where + '.')
    for key, (_, lo, hi) in NUMBERS.items():
        if key in block:
            number(block, key, path, None, lo=lo, hi=hi, where=where + '.')
    if 'seed' in block:
        seed = block['seed']
        need(isinstance(seed, int) and not isinstance(seed, bool) and 0 <= seed < 2 ** 31,
             path, where + '.seed', f'an integer in [0, 2**31), got {seed!r}')
    if 'coefficients' in block:
        need(block['coefficients'] in COEFFICIENTS, path, where + '.coefficients',
             f"one of {', '.join(COEFFICIENTS)}, got {block['coefficients']!r}")
    return dict(block)


def check_wind_model(spec, path):
    """ScenarioError if a VesselSpec has a wind (speed or gusts) but its model no wind loads."""
    from ship_sim.models import model_names
    windy = spec.wind.get('speed_mps', 0.0) > 0.0 or spec.wind.get('gust_sd_mps', 0.0) > 0.0
    need(not windy or spec.model in model_names('wind'), path, f'{spec.namespace}.wind',
         f"model {spec.model!r} has no wind loads (only {', '.join(model_names('wind'))}); give "
         'this vessel wind: {speed_mps: 0.0}')


def wind_parameters(block):
    """vessel_node parameters of a checked wind block."""
    params = {NUMBERS[k][0]: float(v) for k, v in block.items() if k in NUMBERS}
    if 'seed' in block:
        params['wind_seed'] = block['seed']
    if 'coefficients' in block:
        params['wind_coefficients'] = block['coefficients']
    return params


def wind_meta(specs):
    """Recorder --meta arguments: each windy vessel's block as JSON in the bag's custom_data."""
    out = []
    for spec in specs:
        if spec.wind:
            out += ['--meta', f'mission.wind/{spec.namespace}={json.dumps(spec.wind, sort_keys=True)}']
    return out
