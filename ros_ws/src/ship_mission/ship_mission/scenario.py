"""Scenario files: one YAML describes a run (vessels, routes, guidance, autopilot, timing).

    name: flagship_mariner                  # run folder prefix: a plain name (no '/', '\\', '..')
    source: "..."                            # citation of the experiment reproduced
    description: "..."
    duration_s: 1000.0                       # sim time limit (the run also ends when every
                                             # vessel has completed its route); at most
                                             # MAX_STEPS steps of dt_s
    stepping: lockstep                       # lockstep | realtime
    compose: none                            # none | vessel | all: nodes per process
                                             # (ship_mission.composition)
    speedup: 1.0                             # realtime only: sim seconds per wall second
    dt_s: 0.1                                # control period = simulator publish period
    settle_s: 100.0                          # metrics ignore the first settle_s seconds
    vessels:
      vessel_0:                              # namespace
        model: mariner                       # ship_sim model
        route: routes/flagship_mariner.yaml  # route file, relative to this scenario file
        start:                               # relative to the route's start (default 0/0/0)
          along_m: 0.0                       #   along the route, within [0, its length)
          cross_m: 200.0                     #   to starboard of the path (+)
          heading_deg: 0.0                   #   relative to the path direction (+ = starboard)
        # or absolute ENU: start: {x_m: 0, y_m: 0, yaw_deg: 90}
        speed_mps: 7.7175                    # optional initial speed (model default if absent)
        current: {speed_mps: 0.5, direction_deg: 90.0}   # towards, clockwise from north
        waves: {hs_m: 3.0, direction_deg: 45.0}          # towards (ship_mission.waves)
        wind: {speed_mps: 10.0, direction_deg: 270.0}   # optional, replaces the scenario's
        vessel: {...}                        # any further vessel_node parameters
        guidance: {law: ilos, lookahead_m: 800.0}         # guidance_node parameters
        autopilot: {controller: pd}                       # autopilot_node parameters
        colav: {method: sbmpc}               # optional: run colav_node (its parameters) between
                                             # guidance and autopilot, the other vessels as targets
    wind: {speed_mps: 10.0, direction_deg: 270.0}   # optional: every vessel's wind (FROM,
                                             # clockwise from north; ship_mission.wind_block)
    traffic:                                 # optional: target vessels (same keys but `colav`):
      target_0: {model: mariner, route: routes/..., speed_mps: 7.7}   # full vessels, no avoidance
      target_1:                              # a light target: the one key `light`, either
        light: {x_m: 3000.0, y_m: -3000.0, course_deg: 0.0, speed_mps: 7.7}
                                             #   constant course (clockwise from north) and
                                             #   speed from (x_m, y_m) ENU at t = 0 (default 0/0)
      target_2:                              #   or timed waypoints [t_s, x_m, y_m] (ENU, times
        light: {waypoints: [[0, 0, 0], [600, 0, 4000]]}   # strictly increasing), straight legs
                                             # either may add `behaviour: no_alteration`
                                             # (ship_sim.light_traffic.behaviour_problem)
    ais:                                     # optional: AIS targets from a replay file
      file: ais/head_on_target.nmea          #   NMEA replay (ship_guidance.ais.parse_replay),
                                             #   relative to this file, fed on sim time
      origin_lat_deg: 63.4                   #   geodetic origin of the scenario's ENU frame
      origin_lon_deg: 10.4
      stale_after_s: 360.0                   #   any other ais_node parameter (config/ais.yaml)
    aivdm_out: {udp: 127.0.0.1:10110}        # optional: AIVDM/AIVDO out (ship_mission.aivdm_block)
    display:                                 # optional: nav_display_node of every vessel (fix,
      origin: {lat_deg: 59.9, lon_deg: 10.7} #   nav_markers); origin of the NavSatFix (default:
      display_rate_hz: 2.0                   #   the first route's origin, else the ais origin,
      trail_length_s: 600.0                  #   else 66 N 2 E, open sea); rate and trail in sim
                                             #   time. `display: false`: no display
    bag_compression: zstd                    # the bag's MCAP chunks: zstd (default, as rosbag2
                                             # writes them), lz4 or none (run_mission.py
                                             # --bag-compression overrides it)

A matrix file (the one key `matrix`, ship_mission.matrix) holds many scenarios that differ in a few
keys: load_scenarios gives them all, load_scenario the one named.

Node parameters under `vessel`, `guidance`, `autopilot` are passed to the nodes verbatim, so
every parameter a node declares can be set from a scenario; the launcher adds the ones that tie
the graph together (model, start pose, stepping mode, pairing, rates). The launcher's check
(ship_mission.scenario_checks.check_scenario) refuses keys a node does not declare, naming the closest one.
Errors name the file and the key. The file is read by ship_sim.safe_load (the bounded reader of
every input file): a regular UTF-8 file, bounded in size, nesting, aliases and number length,
no key given twice; numbers may be written ``1e9`` (read as YAML 1.2 does).

Collision avoidance: a vessel with a `colav` block runs colav_node in its namespace; guidance's
heading_cmd is remapped to heading_ref (colav_node's nominal input) and colav_node publishes the
heading_cmd the autopilot follows; every other vessel's odom is one of its `target_topics`.
`traffic` vessels are the same full vessels (model, route, guidance, autopilot) listed apart:
they never avoid, and in lockstep each keeps within lockstep_follower_window steps of every
colav vessel's odom (the platoon gate), so the record stays lossless.
Light targets (`light:` entries, ship_sim.light_traffic) are no vessels: one traffic_node moves
them all in closed form and publishes `/<name>/odom` at every /clock step, stamped at the step;
their odom topics join every colav vessel's `target_topics` and the clock master's record
acknowledgement. They are in `Scenario.light` (the traffic_node's target list), not in
`Scenario.vessels`.
AIS targets (`ais:`): the launcher starts one ais_node (graph-wide: `/targets`) replaying `file`
on sim time in the ENU frame of the origin; every colav vessel takes `/targets` as its
targets_topic. In lockstep ais_node publishes at every /clock step followed by `/targets_sync`,
which colav_node waits for (deterministic) and the clock master's record acknowledgement covers
(lossless). `Scenario.ais` holds the ais_node parameters (file made absolute).

A platoon (a string of vessels, each steering at its predecessor) is written as a `platoon:`
section instead of `vessels:`; its schema and checks are in ship_mission.platoon. Its vessels come out
as the same VesselSpec list (with `predecessor` and `spacing` set for the followers), so the
rest of the launcher and the analysis treat both alike.
"""
import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import yaml

from ship_mission.fields import ScenarioError, need, number, unknown
from ship_mission.matrix import expand, is_matrix
from ship_mission.platoon import parse_platoon
from ship_mission.recorder import COMPRESSIONS, DEFAULT_COMPRESSION
from ship_mission.vessel_spec import parse_vessel
from ship_mission.wind_block import check_wind, check_wind_model

from ship_sim.frames import psi_to_yaw
from ship_sim.safe_load import InputError, load_yaml_file, ros_name_problem

TOP_KEYS = {'name', 'source', 'description', 'duration_s', 'stepping', 'speedup', 'dt_s',
            'settle_s', 'vessels', 'platoon', 'record', 'lockstep_timeout_s', 'traffic', 'ais',
            'wind', 'display', 'bag_compression', 'aivdm_out', 'compose'}
#: ais_node parameters the launcher sets itself (not allowed in a scenario's `ais:`).
AIS_LAUNCHER_KEYS = {'use_sim_time', 'publish_on_clock'}
DISPLAY_KEYS = {'origin', 'display_rate_hz', 'trail_length_s'}
VESSEL_KEYS = {'model', 'route', 'start', 'speed_mps', 'current', 'vessel', 'guidance',
               'autopilot', 'model_params', 'colav', 'waves', 'wind'}
TRAFFIC_KEYS = VESSEL_KEYS - {'colav'}
STEPPING = ('lockstep', 'realtime')
#: `compose:` several nodes per process (ship_mission.composition): none, per vessel, or all.
COMPOSE = ('none', 'vessel', 'all')
#: Most simulator steps a run may ask for (duration_s / dt_s): vessel_node's max_steps upper
#: bound (ros_ws/src/ship_sim/ship_sim/vessel_node.py, 10**12), so the launcher's check refuses
#: what the node would refuse after the graph has started.
MAX_STEPS = 10**12
#: Shortest run (duration_s, s): a run shorter than one control period or so records nothing.
MIN_DURATION_S = 0.1


@dataclass
class Scenario:
    file: Path
    name: str
    source: str
    description: str
    duration_s: float
    stepping: str
    speedup: float
    dt_s: float
    settle_s: float
    record: bool
    lockstep_timeout_s: float
    vessels: list
    platoon: object = None   # ship_mission.platoon.Platoon for a `platoon:` scenario
    #: light targets of `traffic:` as traffic_node's `targets` list (name + the `light` mapping)
    light: list = field(default_factory=list)
    #: ais_node parameters of the `ais:` section (file absolute), None without one
    ais: dict = None
    #: route file -> its parsed RoutePlan, filled once by ship_mission.scenario_checks.check_scenario and
    #: passed on to the nodes' parameters (a route file is parsed once per run by the launcher)
    routes: dict = field(default_factory=dict)
    #: nav_display_node parameters of every vessel (`display:`), None for `display: false`
    display: dict = field(default_factory=dict)
    #: --live: the port of the live view (mission.live_view), None without (not a YAML key)
    live_port: int = None
    live_nice: int = 10     #: --live-nice: the live view's CPU niceness once serving
    #: the scenario's own mapping when it comes from a matrix file (ship_mission.matrix), else None
    expanded: dict = None
    bag_compression: str = DEFAULT_COMPRESSION   #: the recorder's --compression
    compose: str = 'none'   #: `compose:` / --compose (ship_mission.composition)
    #: the `aivdm_out:` block as written (ship_mission.aivdm_block checks it), None without one
    aivdm_out: dict = None
    #: {namespace: 'full' | 'light'} of the `traffic:` entries, in file order: full vessels
    #: (their own graph, analysed as vessels) or light targets (traffic_node). AIS targets are
    #: named by their data: ``ais`` says whether the run has any.
    targets: dict = field(default_factory=dict)


#: The bag's custom_data key under which the launcher records a run's targets by kind
#: (``target_record``), so that the analysis reads them (ship_mission.report.recorded_targets).
TARGETS_KEY = 'mission.targets'


def target_record(scenario):
    """The text stored under TARGETS_KEY: JSON {'light': [namespace, ...], 'full': [...],
    'ais': whether ais_node publishes targets}; namespaces with a leading '/' as in the bag."""
    kinds = {kind: [f'/{ns}' for ns, k in scenario.targets.items() if k == kind]
             for kind in ('light', 'full')}
    return json.dumps({**kinds, 'ais': scenario.ais is not None}, sort_keys=True)


def check_name(name, file):
    """A scenario name makes the run folder's name: non-empty text that is a single path
    component (no '/', '\\', NUL, not '.' or '..', no '..' in it), so a run stays in --runs."""
    need(isinstance(name, str) and name.strip(), file, 'name', f'a non-empty string, got {name!r}')
    need(not any(c in name for c in '/\\\0') and '..' not in name and name != '.', file, 'name',
          f"a plain name without '/', '\\' or '..' (it names the run folder), got {name!r}")


def load_scenario(path, name=None):
    """Read and check a scenario file; ScenarioError names the file and the offending key.

    A matrix file needs ``name``, the scenario of it to load; a plain file's name must be
    ``name`` if given."""
    path = Path(path)
    scenarios = load_scenarios(path)
    names = [s.name for s in scenarios]
    if name is None:
        need(len(scenarios) == 1, path, 'matrix', f'holds {len(names)} scenarios '
             f'({names[0]} ... {names[-1]}); name the one to load (run_mission.py --name)')
        return scenarios[0]
    need(name in names, path, 'name', f'no scenario {name!r} here (it holds '
         + (f'{names[0]}' if len(names) == 1 else f'{len(names)}: {names[0]} ... {names[-1]}') + ')')
    return scenarios[names.index(name)]


def load_scenarios(path):
    """Every scenario of a file, checked: the one of a plain file, or a matrix file's (in its
    order). ScenarioError names the file (and for a matrix, the combination) and the key."""
    path = Path(path)
    try:
        data = load_yaml_file(path)
    except InputError as exc:
        raise ScenarioError(str(exc)) from None
    if not is_matrix(data):
        return [_parse_scenario(data, path)]
    scenarios = []
    for entry in expand(data, path):
        try:
            scenario = _parse_scenario(entry, path)
        except ScenarioError as exc:   # name the scenario: the keys are those of its mapping
            prefix = f'{path}: '
            text = str(exc).removeprefix(prefix)
            raise ScenarioError(f'{prefix}scenario {entry.get("name")!r} of the matrix: {text}') from None
        scenario.expanded = entry
        scenarios.append(scenario)
    return scenarios


def route_plan(scenario, spec):
    """The parsed route file of ``spec``, parsed once per file and run: kept in
    ``scenario.routes`` (ship_mission.scenario_checks.check_scenario fills it,
    ship_mission.graph reads it from there). RouteError if the file is not a valid route."""
    plan = scenario.routes.get(spec.route_file)
    if plan is None:
        from ship_planner.route_loader import load_route
        plan = scenario.routes[spec.route_file] = load_route(spec.route_file)
    return plan


def scenario_origin(scenario):
    """(lat, lon) of the scenario's geodetic origin, the one place that picks it: `display:
    origin`, else the first route file's origin, else the `ais:` block's; None when none gives
    one (then nav_display_node and AIVDM out use the default sea area,
    ship_guidance.nav_display.DEFAULT_ORIGIN_DEG, and the launcher says so)."""
    if 'origin_lat_deg' in (scenario.display or {}):
        return scenario.display['origin_lat_deg'], scenario.display['origin_lon_deg']
    for s in scenario.vessels:
        plan = route_plan(scenario, s)
        if plan.origin_lat_deg is not None:
            return plan.origin_lat_deg, plan.origin_lon_deg
    if scenario.ais is not None:
        return scenario.ais['origin_lat_deg'], scenario.ais['origin_lon_deg']
    return None


def scenario_text(scenario):
    """The YAML text of one scenario: its file's, or for a matrix scenario its own mapping (the
    file holds the whole matrix), headed by a comment naming the matrix."""
    if scenario.expanded is None:
        return scenario.file.read_text()
    return (f'# {scenario.name}: one scenario of the matrix {scenario.file}\n'
            + yaml.safe_dump(scenario.expanded, sort_keys=False, allow_unicode=True, width=100))


def _parse_scenario(data, path):
    """The Scenario of one scenario mapping ``data`` (relative paths from ``path``'s folder)."""
    need(isinstance(data, dict), path, '(top)', 'must be a mapping')
    unknown(data, TOP_KEYS, path, '')
    check_name(data.get('name'), path)
    stepping = data.get('stepping', 'lockstep')
    need(stepping in STEPPING, path, 'stepping', f"one of {', '.join(STEPPING)}, got {stepping!r}")
    lockstep_timeout = number(data, 'lockstep_timeout_s', path, 10.0, lo=0.1)
    need(not ('vessels' in data and 'platoon' in data), path, 'platoon',
          "give either 'vessels' (independent vessels) or 'platoon' (a string), not both")
    need(not ('ais' in data and 'platoon' in data), path, 'ais',
          'AIS targets are not supported beside a platoon')
    platoon = None
    light, targets = [], {}
    if 'platoon' in data:
        platoon, specs = parse_platoon(data['platoon'], path, lockstep_timeout)
    else:
        vessels = data.get('vessels')
        need(isinstance(vessels, dict) and vessels, path, 'vessels',
              'a mapping namespace -> vessel')
        specs = _parse_vessels(vessels, 'vessels', VESSEL_KEYS, path)
        traffic = data.get('traffic')
        if traffic is not None:
            need(isinstance(traffic, dict), path, 'traffic', 'a mapping namespace -> vessel')
            for ns in traffic:
                need(ns not in vessels, path, f'traffic.{ns}',
                      'namespace already used in vessels')
            full = {ns: v for ns, v in traffic.items()
                    if not (isinstance(v, dict) and 'light' in v)}
            light = _parse_light({ns: v for ns, v in traffic.items() if ns not in full}, path)
            specs += _parse_vessels(full, 'traffic', TRAFFIC_KEYS, path, traffic=True)
            targets = {ns: 'full' if ns in full else 'light' for ns in traffic}
    need(not ('traffic' in data and 'platoon' in data), path, 'traffic',
          'traffic is not supported beside a platoon')
    ais = _parse_ais(data['ais'], path) if 'ais' in data else None
    compression = data.get('bag_compression', DEFAULT_COMPRESSION)
    need(compression in COMPRESSIONS, path, 'bag_compression',
         f"one of {', '.join(COMPRESSIONS)}, got {compression!r}")
    compose = data.get('compose', 'none')
    need(compose in COMPOSE, path, 'compose', f"one of {', '.join(COMPOSE)}, got {compose!r}")
    _apply_scenario_wind(data, specs, path)
    return Scenario(
        file=path, name=data['name'], source=str(data.get('source', '')),
        description=str(data.get('description', '')),
        duration_s=number(data, 'duration_s', path, 1000.0, lo=MIN_DURATION_S),
        stepping=stepping, speedup=number(data, 'speedup', path, 1.0, lo=0.01, hi=1e4),
        dt_s=number(data, 'dt_s', path, 0.1, lo=1e-3, hi=10.0),
        settle_s=number(data, 'settle_s', path, 0.0, lo=0.0),
        record=bool(data.get('record', True)),
        lockstep_timeout_s=lockstep_timeout, vessels=specs, platoon=platoon, light=light,
        ais=ais, display=_parse_display(data.get('display', {}), path),
        bag_compression=compression, aivdm_out=data.get('aivdm_out'), targets=targets,
        compose=compose)


def _parse_ais(ais, path):
    """ais_node parameters of the `ais:` section: a replay file (relative to the scenario, made
    absolute) and the geodetic origin are required; other keys are ais_node parameters, checked
    by name in ship_mission.scenario_checks.check_scenario."""
    need(isinstance(ais, dict), path, 'ais', 'a mapping (file, origin_lat_deg, origin_lon_deg, '
         'other ais_node parameters)')
    for key in sorted(set(ais) & AIS_LAUNCHER_KEYS):
        need(False, path, f'ais.{key}', 'set by the launcher, not in a scenario')
    need(isinstance(ais.get('file'), str) and ais['file'].strip(), path, 'ais.file',
         'an AIS replay file (NMEA, relative to the scenario)')
    file = (path.parent / ais['file']).resolve()
    need(file.is_file(), path, 'ais.file', f'{file} is not a file')
    out = dict(ais, file=str(file))
    out['origin_lat_deg'] = number(ais, 'origin_lat_deg', path, None, lo=-89.0, hi=89.0,
                                   where='ais.')
    out['origin_lon_deg'] = number(ais, 'origin_lon_deg', path, None, lo=-180.0, hi=180.0,
                                   where='ais.')
    return out


def _apply_scenario_wind(data, specs, path):
    """The top-level `wind:` block becomes the wind of every vessel without its own; a wind on a
    model without wind loads is refused here, before anything starts."""
    wind = check_wind(data.get('wind'), path, 'wind')
    for spec in specs:
        if not spec.wind and wind:
            spec.wind = dict(wind)
        check_wind_model(spec, path)


def _parse_display(d, path):
    """nav_display_node parameters from `display:` (None for `display: false`)."""
    if d is False:
        return None
    d = {} if d is True else d
    need(isinstance(d, dict), path, 'display', f'false or a mapping, got {d!r}')
    unknown(d, DISPLAY_KEYS, path, 'display.')
    out = {key: number(d, key, path, None, lo=lo, where='display.')
           for key, lo in (('display_rate_hz', 0.01), ('trail_length_s', 0.0)) if key in d}
    if 'origin' in d:
        o = d['origin']
        need(isinstance(o, dict), path, 'display.origin', 'a mapping {lat_deg, lon_deg}')
        unknown(o, {'lat_deg', 'lon_deg'}, path, 'display.origin.')
        out['origin_lat_deg'] = number(o, 'lat_deg', path, None, lo=-89.0, hi=89.0,
                                       where='display.origin.')
        out['origin_lon_deg'] = number(o, 'lon_deg', path, None, lo=-180.0, hi=360.0,
                                       where='display.origin.')
    return out


def _parse_light(entries, path):
    """traffic_node's target list from the light `traffic:` entries (namespace -> {light:
    ...}); each is checked by ship_sim.light_traffic, its refusal named by the key."""
    from ship_sim.light_traffic import make_traffic
    out = []
    for ns, v in entries.items():
        where = f'traffic.{ns}'
        need(not ros_name_problem(ns), path, where, f'namespace {ros_name_problem(ns)}')
        unknown(v, {'light'}, path, where + '.')
        light = v['light']
        need(isinstance(light, dict), path, where + '.light', 'a mapping')
        unknown(light, {'x_m', 'y_m', 'course_deg', 'speed_mps', 'waypoints', 'behaviour'},
                path, where + '.light.')
        target = {'name': ns, **light}
        try:
            make_traffic([target])
        except ValueError as exc:
            detail = str(exc).removeprefix(f'light target {ns}: ')
            raise ScenarioError(f'{path}: {where}.light: {detail}') from None
        out.append(target)
    return out


def _parse_vessels(vessels, section, keys, path, traffic=False):
    """VesselSpecs of one `vessels:` or `traffic:` mapping (namespace -> vessel)."""
    specs = []
    for ns, v in vessels.items():
        where = f'{section}.{ns}.'
        need(not ros_name_problem(ns), path, f'{section}.{ns}', f'namespace {ros_name_problem(ns)}')
        need(isinstance(v, dict), path, where[:-1], 'must be a mapping')
        unknown(v, keys, path, where)
        need(isinstance(v.get('model'), str), path, where + 'model', 'a model name')
        need(isinstance(v.get('route'), str), path, where + 'route', 'a route file')
        route = (path.parent / v['route']).resolve()
        need(route.exists(), path, where + 'route', f'{route} does not exist')
        spec = parse_vessel(ns, v, route, path, where)
        spec.traffic = traffic
        specs.append(spec)
    return specs


def start_pose(spec, route):
    """Absolute ENU start (x, y, yaw) of a vessel from its spec and its route (NED Route)."""
    s = spec.start
    if 'x_m' in s or 'y_m' in s or 'yaw_deg' in s:
        return s.get('x_m', 0.0), s.get('y_m', 0.0), math.radians(s.get('yaw_deg', 0.0))
    north, east, alpha = route.point_at(float(s.get('along_m', 0.0)))
    cross = float(s.get('cross_m', 0.0))
    # Starboard of a path heading alpha (NED) is the direction alpha + 90 deg.
    north += cross * math.cos(alpha + math.pi / 2)
    east += cross * math.sin(alpha + math.pi / 2)
    psi = alpha + math.radians(s.get('heading_deg', 0.0))
    return float(east), float(north), float(psi_to_yaw(psi))
