"""A scenario's node sections checked by the nodes' own rules before anything starts.

ship_mission.scenario_checks.check_scenario calls ``check_vessel_sections``: a value a node would refuse at
its start (after the whole graph and the run folder exist) is refused here, in one line naming
the file and the key. The rules are the nodes' own, not copies: each node's parameter schema
(ship_sim.param_schema; ``<package>/schema.py``), which the node declares from, checked by
ship_sim.param_schema.check_param without ROS:

- the value's type is the parameter's (rclpy's static parameter types: a float parameter
  refuses ``900``, write ``900.0``), within its range and among its choices, and passes the
  schema's pure named checks;
- colav: in addition the lists and the cross checks of ship_guidance.colav_params.ColavParams
  and own_ship_prediction.OwnShipModel, built from the section as colav_node builds them.
"""
from ship_mission.fields import ScenarioError
from ship_sim.param_schema import RCLPY_PARAMETERS

NODES = {'vessel': ('ship_sim', 'vessel_node'), 'guidance': ('ship_guidance', 'guidance_node'),
         'autopilot': ('ship_autopilot', 'autopilot_node'),
         'colav': ('ship_guidance', 'colav_node')}


def section_problems(package, executable, params):
    """[(key, one-line refusal)] of the values in ``params`` (a node section) that node would
    refuse at start, by its schema; keys it does not declare are left to the name check."""
    from ship_sim.param_schema import check_param, node_schema
    schema = node_schema(package, executable)
    renamed = schema.renamed()
    names = set(schema.names())
    out = []
    for key, value in params.items():
        name = renamed.get(key, key)
        if name in names:
            bad = check_param(schema, name, value)
            if bad:
                out.append((key, bad))
    return out


def colav_problems(params):
    """[(key, one-line refusal)] of a colav section (colav_node's start parameters): each value
    by the schema, then the cross checks colav_node makes when it builds its models."""
    from ship_guidance.colav_params import ColavParams
    from ship_guidance.own_ship_prediction import OwnShipModel
    from ship_guidance.schema import COLAV_NODE, LISTS, OWN_SHIP_KEYS, SCALARS
    out = section_problems(COLAV_NODE.package, COLAV_NODE.node, params)
    if out:
        return out
    values = {name: params.get(name, COLAV_NODE[name].default) for name, *_ in SCALARS + LISTS}
    lists = {n: [float(x) for x in values[n]] for n, _, _ in LISTS if n != 'target_topics'}
    scalars = {n: float(values[n]) for n, *_ in SCALARS}
    try:
        ColavParams.from_dict({k: v for k, v in {**scalars, **lists}.items()
                               if k not in OWN_SHIP_KEYS})
        OwnShipModel.from_dict({k: scalars[k] for k in OWN_SHIP_KEYS})
    except (TypeError, ValueError) as exc:
        out.append((None, f'colav parameters: {exc}'))
    return out


def check_vessel_sections(spec, where, guidance=NODES['guidance']):
    """ScenarioError (one line) for the first value of a vessel's node sections its node would
    refuse at start; ``where``: the key prefix in messages (``<file>: vessels.<ns>.``);
    ``guidance``: (package, executable) of the node that reads the guidance section (a platoon
    follower's is follower_node, whose ranges differ)."""
    nodes = {**NODES, 'guidance': guidance}
    blocks = {'vessel': spec.vessel_params, 'guidance': spec.guidance_params,
              'autopilot': spec.autopilot_params, 'colav': spec.colav_params}
    for block, params in blocks.items():
        if not params:
            continue
        if block == 'colav':
            problems = colav_problems(params)
        else:
            problems = section_problems(*nodes[block], params)
        if problems:
            key, bad = problems[0]
            raise ScenarioError(f'{where}{block}' + (f'.{key}' if key else '') + f': {bad}')


def node_parameter_names(package, executable):
    """The parameters ``executable`` of ``package`` declares: the names in its parameter schema
    (ship_sim.param_schema.node_schema; the node declares from it), their deprecated names,
    and those rclpy declares on every node (RCLPY_PARAMETERS). Reads no file, starts no ROS."""
    from ship_sim.param_schema import node_schema
    try:
        schema = node_schema(package, executable)
    except KeyError as exc:
        raise ScenarioError(str(exc.args[0])) from None
    return set(schema.names()) | set(schema.renamed()) | set(RCLPY_PARAMETERS)
