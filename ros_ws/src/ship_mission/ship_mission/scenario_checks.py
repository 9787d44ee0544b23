"""The checks of a loaded scenario that need the packages (ship_mission.scenario checks the
file's own shape): model names, routes, start points, the number of steps, every node
parameter name and value, the `ais:` and `aivdm_out:` blocks, a platoon's stability. They run
before anything starts, so a mistake is one line naming the file and the key."""
import difflib
import math
from pathlib import Path

from ship_mission.graph import AIS_NODE, COLAV_NODE, NODES, vessel_nodes
from ship_mission.node_checks import node_parameter_names
from ship_mission.scenario import ScenarioError, route_plan


def check_scenario(scenario):
    """What load_scenario cannot check without the packages: model names, route files, start
    points within their route, the number of steps (ship_mission.scenario.MAX_STEPS), node
    parameter names (node_parameter_names; an unknown one is named with the closest valid
    one), and for a platoon the stability of every look-ahead (ship_mission.platoon.check_stability;
    its warnings go to scenario.platoon.warnings).

    Raises ScenarioError (one line naming the file and the key) before anything starts."""
    from ship_mission.node_checks import check_vessel_sections
    from ship_mission.scenario import MAX_STEPS
    from ship_planner.route_loader import RouteError
    from ship_sim.models import MODEL_NAMES
    platoon = scenario.platoon
    for key, v in (('duration_s', scenario.duration_s), ('dt_s', scenario.dt_s)):
        if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0.0):
            raise ScenarioError(f'{scenario.file}: {key}: must be a positive number, got {v!r}')
    if not scenario.duration_s / scenario.dt_s <= MAX_STEPS:
        raise ScenarioError(f'{scenario.file}: duration_s: {scenario.duration_s:g} s is '
                            f'{scenario.duration_s / scenario.dt_s:.3g} steps of dt_s '
                            f'{scenario.dt_s:g} s; at most {MAX_STEPS:.0e} steps '
                            f'({MAX_STEPS * scenario.dt_s:.3g} s)')
    for i, spec in enumerate(scenario.vessels):
        section = 'traffic' if spec.traffic else 'vessels'
        where = (f'{scenario.file}: {section}.{spec.namespace}.' if platoon is None
                 else f'{scenario.file}: platoon.vessels[{i}] ({spec.namespace}).')
        if spec.model not in MODEL_NAMES:
            raise ScenarioError(f'{where}model: unknown model {spec.model!r}; one of '
                                f'{", ".join(MODEL_NAMES)}')
        try:
            plan = route_plan(scenario, spec)
        except RouteError as exc:
            key = f'{where}route' if platoon is None else f'{scenario.file}: platoon.route'
            raise ScenarioError(f'{key}: {exc}') from None
        along = spec.start.get('along_m')
        if along is not None and not 0.0 <= along < plan.route.length:
            raise ScenarioError(f'{where}start.along_m: {along:g} m is not on the route '
                                f'({spec.route_file}, {plan.route.length:.1f} m long); give '
                                f'0 <= along_m < {plan.route.length:.1f}')
        guidance = vessel_nodes(spec)[1]
        blocks = [('vessel', spec.vessel_params, ('vessel_node', 'ship_sim')),
                  ('guidance', spec.guidance_params, guidance),
                  ('autopilot', spec.autopilot_params, NODES[2])]
        if spec.colav_params is not None:
            blocks.append(('colav', spec.colav_params, COLAV_NODE))
        for block, params, (exe, pkg) in blocks:
            names = node_parameter_names(pkg, exe)
            for key in params:
                if key not in names:
                    near = difflib.get_close_matches(str(key), sorted(names), n=1)
                    hint = f' (did you mean "{near[0]}"?)' if near else ''
                    raise ScenarioError(f'{where}{block}.{key}: {exe} has no parameter '
                                        f'{key!r}{hint}')
        check_vessel_sections(spec, where, guidance[::-1])   # values, by the nodes' own rules
    if scenario.ais is not None:
        names = node_parameter_names(*reversed(AIS_NODE))
        for key in scenario.ais:
            if key not in names:
                near = difflib.get_close_matches(str(key), sorted(names), n=1)
                hint = f' (did you mean "{near[0]}"?)' if near else ''
                raise ScenarioError(f'{scenario.file}: ais.{key}: ais_node has no parameter '
                                    f'{key!r}{hint}')
    if scenario.aivdm_out is not None:
        from ship_mission.aivdm_block import aivdm_parameters
        aivdm_parameters(scenario, Path('.'))
    if platoon is not None:
        from ship_mission.platoon import check_lead, check_stability
        check_lead(scenario)
        check_stability(scenario)
