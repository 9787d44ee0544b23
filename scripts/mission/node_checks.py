"""A scenario's node sections checked by the nodes' own rules before anything starts.

mission.launcher.check_scenario calls ``check_node_sections``: a value a node would refuse at
its start (after the whole graph and the run folder exist) is refused here, in one line naming
the file and the key. The rules are the nodes' own, not copies:

- every section: the value's type is that of the parameter's default in the package's config
  list (config/<node>.yaml, the file node_parameter_names reads), as rclpy's
  static parameter types require (rclpy refuses ``900`` for a float parameter: write
  ``900.0``);
- colav: ``method`` one of ship_guidance.colav_methods.METHODS; every scalar within the bounds
  colav_node declares (colav_node.SCALARS); the lists and the cross checks of
  ship_guidance.colav_params.ColavParams and own_ship_prediction.OwnShipModel, built from the
  section as colav_node builds them;
- guidance: ``law`` one of ship_guidance.guidance.LAWS; autopilot: ``vessel_model`` one of
  ship_sim.models.MODEL_NAMES.

The check goes through ship_sim.ros.params.check_value, the test NodeParameters applies.
"""
from mission.fields import ScenarioError


def config_file(package, executable):
    """The config list of a node: config/<name>.yaml (``vessel_node`` -> ``vessel.yaml``) as
    installed in share/<package>/config, else the source tree's (before a build); None if the
    package has none."""
    from mission.processes import INSTALL, REPO
    name = executable.removesuffix('_node') + '.yaml'
    for folder in (INSTALL / package / 'share' / package / 'config',
                   REPO / 'ros_ws' / 'src' / package / 'config'):
        if (folder / name).is_file():
            return folder / name
    return None


def _config_defaults(package, executable):
    """{parameter: default} of a node's config list (empty if the package has none)."""
    from ship_sim.safe_load import load_yaml_file
    path = config_file(package, executable)
    out = {}
    for section in ((load_yaml_file(path) or {}).values() if path else ()):
        out.update((section or {}).get('ros__parameters') or {})
    return out


def _type_problem(key, value, default):
    if default is None or isinstance(default, list) or type(value) is type(default):
        return None
    if isinstance(default, float) and isinstance(value, int) and not isinstance(value, bool):
        return (f'parameter {key!r} = {value!r} is not allowed: the node\'s parameter is a '
                f'float, write {float(value)!r} (ROS parameter types are static)')
    from ship_sim.ros.params import check_value
    return check_value(key, value, default)


def colav_problems(params):
    """[(key, one-line refusal)] of a colav section (colav_node's start parameters)."""
    from ship_guidance.colav_methods import METHODS
    from ship_guidance.colav_node import LISTS, OWN_SHIP_KEYS, SCALARS
    from ship_guidance.colav_params import ColavParams
    from ship_guidance.own_ship_prediction import OwnShipModel
    from ship_sim.ros.params import check_value
    out = []
    if 'method' in params:
        bad = check_value('method', params['method'], 'sbmpc', choices=tuple(METHODS))
        if bad:
            out.append(('method', bad))
    values = {}
    for name, default, _, lo, hi, _ in SCALARS:
        values[name] = params.get(name, default)
        bad = check_value(name, values[name], default, lo=lo, hi=hi)
        if bad:
            out.append((name, bad))
    for name, default, _ in LISTS:
        v = params.get(name, default)
        kind = type(default[0])
        if not (isinstance(v, list) and v and all(isinstance(x, kind) or (
                kind is float and isinstance(x, int) and not isinstance(x, bool)) for x in v)):
            out.append((name, f'parameter {name!r} = {v!r} is not allowed: a non-empty list of '
                              f'{"numbers" if kind is float else "strings"}'))
        values[name] = v
    if out:
        return out
    lists = {n: [float(x) for x in values[n]] for n, _, _ in LISTS if n != 'target_topics'}
    scalars = {n: float(values[n]) for n, *_ in SCALARS}
    try:
        ColavParams.from_dict({k: v for k, v in {**scalars, **lists}.items()
                               if k not in OWN_SHIP_KEYS})
        OwnShipModel.from_dict({k: scalars[k] for k in OWN_SHIP_KEYS})
    except (TypeError, ValueError) as exc:
        out.append((None, f'colav parameters: {exc}'))
    return out


def _choice_problems(params, rules):
    from ship_sim.ros.params import check_value
    out = []
    for key, (default, choices) in rules.items():
        if key in params:
            bad = check_value(key, params[key], default, choices=tuple(choices))
            if bad:
                out.append((key, bad))
    return out


NODES = {'vessel': ('ship_sim', 'vessel_node'), 'guidance': ('ship_guidance', 'guidance_node'),
         'autopilot': ('ship_autopilot', 'autopilot_node'),
         'colav': ('ship_guidance', 'colav_node')}


def check_vessel_sections(spec, where):
    """ScenarioError (one line) for the first value of a vessel's node sections its node would
    refuse at start; ``where``: the key prefix in messages (``<file>: vessels.<ns>.``)."""
    from ship_guidance.guidance import LAWS
    from ship_guidance.node_defaults import GUIDANCE_DEFAULTS
    from ship_sim.models import MODEL_NAMES
    blocks = {'vessel': spec.vessel_params, 'guidance': spec.guidance_params,
              'autopilot': spec.autopilot_params, 'colav': spec.colav_params}
    for block, params in blocks.items():
        if not params:
            continue
        defaults = _config_defaults(*NODES[block])
        problems = [(k, _type_problem(k, v, defaults.get(k))) for k, v in params.items()]
        problems = [(k, p) for k, p in problems if p]
        if not problems and block == 'colav':
            problems = colav_problems(params)
        elif not problems and block == 'guidance':
            problems = _choice_problems(params, {'law': (GUIDANCE_DEFAULTS['law'], LAWS)})
        elif not problems and block == 'autopilot':
            problems = _choice_problems(params, {'vessel_model': ('mariner', MODEL_NAMES)})
        if problems:
            key, bad = problems[0]
            raise ScenarioError(f'{where}{block}' + (f'.{key}' if key else '') + f': {bad}')


#: Parameters rclpy (Jazzy) declares on every node itself (see ship_sim.ros.params.check_overrides).
RCLPY_PARAMETERS = ('use_sim_time', 'start_type_description_service')


def node_parameter_names(package, executable):
    """The parameters ``executable`` of ``package`` declares, from the package's own list:
    config/<name>.yaml (``vessel_node`` -> ``vessel.yaml``), which lists every parameter of
    its node, as installed in share/<package>/config (the source tree's before a build), plus
    those rclpy declares on every node (RCLPY_PARAMETERS). A list parameter without a default
    (an empty list has no type in a ROS parameter file, e.g. guidance_node's
    course_schedule_deg) is listed in a comment as ``<name>: [...]``."""
    import re
    from ship_sim.safe_load import load_yaml, read_regular_file
    name = executable.removesuffix('_node') + '.yaml'
    path = config_file(package, executable)
    if path is not None:
        text = read_regular_file(path)
        names = set(RCLPY_PARAMETERS)
        for section in (load_yaml(text, path) or {}).values():
            names |= set((section or {}).get('ros__parameters') or {})
        for line in text.splitlines():
            if line.lstrip().startswith('#'):
                names |= set(re.findall(r'\b([a-z][a-z0-9_]*): \[', line))
        return names
    raise ScenarioError(f'{executable}: no parameter list config/{name} in package {package}')
