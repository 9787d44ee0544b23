"""One Imazu case on an MSS plant, closed loop in one process (no ROS), as the node graph runs it.

``case_scenario`` writes the case as a scenario (own ship on a straight route through its Imazu
track, `colav:` with the ship's own-ship model, every target a `traffic:` light target holding
course and speed); ``run_scenario`` runs a scenario's first vessel with the objects the nodes
build from it, in the order lockstep runs them, each step:

    vessel_node  VesselSimulator.nav_state -> Odometry (fill_odometry)
    guidance     odometry_to_ned -> Guidance.update -> heading_cmd (ENU yaw)
    traffic_node LightTraffic.state at the /clock time -> each target's Odometry
    colav_node   at its decision period: colav_io.ship_state / target_state ->
                 CollisionAvoidance.decide; colav_io.command_yaw -> heading_cmd
    autopilot    HeadingSteering.decode / update -> rudder_cmd
    vessel_node  VesselSimulator.step(rudder, shaft): with colav, the shaft at the decided speed
                 factor x its command (ship_sim.speed_factor.scaled_shaft, as vessel_node's
                 speed_factor_input; colav's has_shaft from the model, as the launcher sets it)

with the messages' own arithmetic (the odometry round trip, the stamps in nanoseconds), so the
graph in lockstep computes the same numbers (tests/integration/test_imazu_graph.py).

By default targets never avoid (light targets, behaviour ``straight``): where a case's target
should give way to the own ship, it does not, the own ship stands on until Rule 17(a)(ii) / (b)
and then acts; targets may pass through each other (only own ship - target distances are
judged). ``run_scenario(..., behaviours={name: behaviour})`` gives targets another behaviour
(ship_guidance.reacting_traffic: reciprocal, turns_to_port, no_alteration); a reacting target
is stepped after the own ship's decision at each step, on the states of that step, and a
reciprocal one decides with the own ship's colav (method, parameters, model, period). The node
graph has no reacting targets (traffic_node refuses them), so such a run is this runner's only.

``run_scenario(..., land=chart)`` gives the own ship's colav a coast: ``chart`` is a chart raster
in the case's NED frame (ship_planner.chart.Chart: ``water``, ``north0``, ``east0``,
``resolution_m``), and colav gets the LandMask that colav_node builds from the /map occupancy
grid: its land cells widened by the colav parameter ``grounding_clearance_m`` (``land_mask``).
SB-MPC scores grounding against it; VO has no grounding term and ignores it. Without land (the
default) the run is the one it always was. Reacting targets do not see land.
"""
import dataclasses
import functools
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import yaml

from ship_guidance.colav_methods import METHODS as _REGISTERED
from ship_sim.models import model_names

#: Longest sim time of a run (s). The nominal meeting is at 1200 s, but a ship that has given
#: way or stood on meets some targets later (closest approaches up to 1800 s) and then needs
#: time to regain its route, so a run ends at the first moment ``RunEnd`` is satisfied and
#: this generous limit only stops a run that never gets there (reported as ``limit``).
LIMIT_S = 4000.0
#: The benchmark's own ships: the MSS ship models (vessel cards labelled 'mss').
SHIPS = model_names('mss')
#: Every registered collision-avoidance method (ship_guidance.colav_methods), by name.
METHODS = tuple(_REGISTERED)
#: Guidance of every run: LOS (no integral: a cross-track integral winds up against the
#: avoidance offset), the look-ahead a few ship lengths.
GUIDANCE = {'law': 'los', 'lookahead_m': 1000.0}
ROUTE_LENGTH_M = 40000.0


class RunEnd:
    """The end of a run: every target has passed (TCPA < 0 against the own ship's current
    velocity, i.e. the range opening) and the own ship has stayed within ``band_m`` of its
    straight route through (north0, east0) on ``course`` (rad) for ``dwell_s`` since then. The
    band and dwell are the evaluator's return-to-route measure (EvaluationParams), so a run
    that ends here has returned by the evaluator's own reading."""

    def __init__(self, north0, east0, course, band_m, dwell_s):
        self.p0 = np.array([north0, east0], dtype=float)
        self.normal = np.array([-math.sin(course), math.cos(course)])
        self.band_m, self.dwell_s = float(band_m), float(dwell_s)
        self._since = None

    @classmethod
    def of_case(cls, case, params=None):
        from ship_guidance.colav_evaluation import EvaluationParams
        p = params or EvaluationParams()
        own = case['own']
        return cls(own['north_m'], own['east_m'], math.radians(own['course_deg']),
                   p.route_band_m, p.route_dwell_s)

    def cross_track(self, north, east):
        return float((np.array([north, east]) - self.p0) @ self.normal)

    def done(self, t, own, targets):
        """True once the end is reached at time ``t`` (own: colav ShipState; targets: colav
        Targets); call it at every sample, in time order."""
        from ship_guidance.cpa import cpa, velocity
        p_t = np.array([[tg.north, tg.east] for tg in targets])
        v_t = velocity(np.array([tg.course for tg in targets]),
                       np.array([tg.speed for tg in targets]))
        tcpa, _ = cpa(np.array([own.north, own.east]), velocity(own.course, own.speed), p_t, v_t)
        if not (np.all(tcpa < 0.0) and abs(self.cross_track(own.north, own.east)) <= self.band_m):
            self._since = None
            return False
        if self._since is None:
            self._since = t
        return t - self._since >= self.dwell_s


def own_ship_model(ship, speed_mps):
    """colav_node's own-ship model keys for ``ship`` at ``speed_mps``: the identified Nomoto
    model (ship_autopilot/data/nomoto_gains.yaml, nondimensional K', T') scaled to this speed
    (K = K' U / L, T = T' L / U), the turn rate capped at K times the rudder limit, the design
    (omega_n, zeta) that the autopilot's PD gains (the gain table, as the runs use it) place
    on the Nomoto model at this speed (ship_guidance.heading_loop.pd_design); for a ship
    with a shaft also the speed at factor 1 (the route speed) and the surge time constant
    identified on the plant (``speed_time_constant``); for every ship the speed it loses in a
    turn (``turn_speed_loss``)."""
    from ship_autopilot.gains import heading_loop_design, nomoto_gains
    from ship_guidance.heading_loop import pd_design
    from ship_guidance.own_ship_prediction import OwnShipModel
    from ship_sim.models import make_model
    g = nomoto_gains(ship)
    K = g['K_nd'] * speed_mps / g['length_m']
    T = g['T_nd'] * g['length_m'] / speed_mps
    pd = heading_loop_design(ship).gains['pd']
    zeta, omega_n = pd_design(-1.0 / T, -K / T, k1=pd['k1'], k2=pd['k2'])
    out = {'course_time_constant_s': float(T),
           'max_turn_rate': float(K * math.radians(g['rudder_max_deg'])),
           'heading_loop_omega_n': float(omega_n), 'heading_loop_zeta': float(zeta)}
    if make_model(ship).has_shaft:
        out['speed_at_factor_one_mps'] = float(speed_mps)
        out['speed_time_constant_s'] = speed_time_constant(ship, float(speed_mps))
        out['stop_turn_authority'] = stop_turn_authority(ship, float(speed_mps))
    t_u = out.get('speed_time_constant_s', OwnShipModel.speed_time_constant_s)
    out['turn_speed_loss_s'] = turn_speed_loss(ship, float(speed_mps), t_u, float(T),
                                               out['max_turn_rate'])
    return out


def _plant(ship, speed_mps, dt_s):
    """(model, VesselSimulator) of ``ship`` trimmed straight at ``speed_mps`` (the unpropelled
    mariner built to run straight at that speed, as the Imazu scenarios build it)."""
    from ship_sim.models import make_model
    from ship_sim.simulator import VesselSimulator
    model = make_model(ship, **({} if make_model(ship).has_shaft else {'U0': speed_mps}))
    return model, VesselSimulator(model, dt=dt_s, speed=speed_mps)


@functools.lru_cache(maxsize=None)
def turn_speed_loss(ship, speed_mps, speed_time_constant_s, course_time_constant_s,
                    max_turn_rate, dt_s=1.0, window_s=300.0):
    """k (s) of colav's speed model u_dot = (u_c - u) / T_u - k u r^2 for ``ship``'s plant: from
    the trim at ``speed_mps``, full rudder held for ``window_s`` (an avoidance turn's length) at
    the trim's shaft, least squares of the plant's per-second speed change less the lag term
    (u_c - u) / T_u, against -u r^2 with u the plant's speed and r the turn rate the course
    model predicts for full rudder, max_turn_rate (1 - exp(-t / T)) (T the Nomoto time
    constant): the model's own turn rate is what k multiplies in a prediction (the mariner's
    course model turns up to 4 times faster than its plant, so the plant's rate gave it 27 s
    and a predicted speed collapse; the tanker's and the container's build up like their
    plants')."""
    model, sim = _plant(ship, speed_mps, dt_s)
    shaft = sim.shaft_command
    u = []
    for _ in range(int(round(window_s / dt_s)) + 1):
        _, _, _, _, uu, vv, _ = sim.nav_state()
        u.append(math.hypot(uu, vv))
        sim.step(model.rudder_max, shaft)
    u = np.array(u)
    t_m = (np.arange(u.size - 1) + 0.5) * dt_s
    u_m = 0.5 * (u[1:] + u[:-1])
    r_m = max_turn_rate * -np.expm1(-t_m / course_time_constant_s)
    y = np.diff(u) / dt_s + (u_m - speed_mps) / speed_time_constant_s
    x = u_m * r_m ** 2
    return float(max(-(x @ y) / (x @ x), 0.0))


@functools.lru_cache(maxsize=None)
def stop_turn_authority(ship, speed_mps, dt_s=1.0, window_s=120.0):
    """Turn authority of ``ship``'s plant with the shaft stopped, for colav's course model: from
    the trim at ``speed_mps``, full rudder for ``window_s`` (the first part of an avoidance
    turn) with the shaft stopped and with it kept, the ratio of the mean turn rates."""
    rates = []
    for factor in (0.0, 1.0):
        model, sim = _plant(ship, speed_mps, dt_s)
        shaft = factor * sim.shaft_command
        total = 0.0
        for _ in range(int(round(window_s / dt_s))):
            total += abs(sim.step(model.rudder_max, shaft).nav_state()[6])
        rates.append(total)
    return float(min(rates[0] / rates[1], 1.0))


@functools.lru_cache(maxsize=None)
def speed_time_constant(ship, speed_mps, dt_s=1.0, limit_s=6000.0):
    """Surge time constant (s) of ``ship``'s plant for colav's first-order speed model: trimmed
    at ``speed_mps``, the shaft command is halved (speed factor 0.5, as vessel_node applies it)
    and the time to cover 1 - 1/e of the way to the steady speed at the half shaft is taken,
    rounded to whole seconds. The response is not first order (resistance and thrust are
    quadratic), so this is the half-step's constant; a stop (factor 0) coasts down slower."""
    from ship_sim.models import make_model
    from ship_sim.simulator import VesselSimulator
    model = make_model(ship)
    sim = VesselSimulator(model, dt=dt_s, speed=speed_mps)
    u0, half = sim.speed_water(), 0.5 * sim.shaft_command
    u_end = VesselSimulator(model, dt=dt_s, shaft=half).speed_water()
    goal = u0 + (1.0 - math.exp(-1.0)) * (u_end - u0)
    for k in range(1, int(limit_s / dt_s) + 1):
        if sim.step(0.0, half).speed_water() <= goal:
            return float(round(k * dt_s))
    raise ValueError(f'{ship}: no half-shaft speed response within {limit_s:g} s')


def case_scenario(number, case, ship, method=None, duration_s=LIMIT_S, colav=None):
    """(scenario dict, route dict) of Imazu case ``number`` with ``ship`` as own ship; method
    None: no colav and no traffic (the reference run)."""
    own = case['own']
    c = math.radians(own['course_deg'])
    x0, y0 = own['east_m'], own['north_m']
    route = {'name': 'imazu_own_route', 'frame': 'enu',
             'source': 'Straight route through the Imazu own-ship track (scripts/imazu)',
             'waypoints': [{'x_m': x0, 'y_m': y0, 'name': 'start'},
                           {'x_m': x0 + ROUTE_LENGTH_M * math.sin(c),
                            'y_m': y0 + ROUTE_LENGTH_M * math.cos(c), 'name': 'end'}]}
    vessel = {'model': ship, 'route': 'route.yaml', 'speed_mps': own['speed_mps'],
              'guidance': dict(GUIDANCE), 'autopilot': {'controller': 'pd'}}
    if ship == 'mariner':   # no propeller: it runs straight only at its nominal speed U0
        vessel['vessel'] = {'nominal_speed_mps': own['speed_mps']}
    name = f'imazu{number:02d}_{ship}_{method or "none"}'
    scenario = {'name': name,
                'source': 'Imazu (1987) encounter set, geometry after Sawada et al. 2021 (scaled '
                          '2/3: 12 kn, every ship at one point 4 NM ahead after 20 min)',
                'description': f'Imazu case {number}, own ship {ship}, '
                               f'{"colav " + method if method else "no traffic (reference)"}',
                'duration_s': float(duration_s), 'stepping': 'lockstep', 'dt_s': 0.1,
                'vessels': {'vessel_0': vessel}}
    if method is not None:
        vessel['colav'] = {'method': method, **own_ship_model(ship, own['speed_mps']),
                           **(colav or {})}
        scenario['traffic'] = {t['name']: {'light': {
            'x_m': t['east_m'], 'y_m': t['north_m'], 'course_deg': t['course_deg'],
            'speed_mps': t['speed_mps']}} for t in case['targets']}
    return scenario, route


def write_scenario(scenario, route, directory):
    """Write ``<name>.yaml`` and its route (route.yaml) into ``directory``; the scenario path."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    (directory / 'route.yaml').write_text(yaml.safe_dump(route, sort_keys=False))
    path = directory / f'{scenario["name"]}.yaml'
    path.write_text('# Imazu benchmark case, written by scripts/imazu_benchmark.py\n'
                    + yaml.safe_dump(scenario, sort_keys=False))
    return path


@dataclass
class RunResult:
    """Tracks (own and per target: t, north, east, course, speed over ground, NED) and the
    colav decisions [t, mode, course_offset, speed_multiplier] of one run."""
    t: np.ndarray
    own: np.ndarray                          # (N, 4): north, east, course, speed
    targets: dict = field(default_factory=dict)   # name -> (N, 4)
    decisions: list = field(default_factory=list)
    heading: np.ndarray = None               # (N,) own heading (rad NED)
    decision_wall_s: float = 0.0
    end: str = 'duration'                    # 'clear' (RunEnd reached) or 'limit' / 'duration'
    sensing: dict = None                     # SensedTargets.stats() of a run with sensing


COLAV_NODE_KEYS = {'method', 'decision_period_s', 'targets_topic', 'target_stale_s',
                   'lockstep_target_timeout_s', 'pairing', 'target_topics', 'has_shaft',
                   'max_targets'}


def build_colav(colav_params, has_shaft):
    """(CollisionAvoidance, decision period s) as colav_node builds them from its parameters
    (the launcher sets has_shaft from the vessel's model: vessel_node executes the speed factor
    on a shaft)."""
    from ship_guidance.colav_methods import make_colav
    from ship_guidance.colav_params import ColavParams
    from ship_guidance.own_ship_prediction import OwnShipModel
    ship_keys = {f.name for f in dataclasses.fields(OwnShipModel)} - {'has_shaft'}
    values = dict(colav_params)
    method = values.pop('method', 'sbmpc')
    period = float(values.pop('decision_period_s', 1.0))
    params = ColavParams.from_dict({k: v for k, v in values.items()
                                    if k not in ship_keys | COLAV_NODE_KEYS})
    ship = OwnShipModel.from_dict({**{k: float(values[k]) for k in ship_keys if k in values},
                                   'has_shaft': has_shaft})
    return make_colav(method, params, ship), period


def sensed_targets(sensing, names):
    """The SensedTargets of ``sensing`` (a level name of ship_guidance.sensor_levels, or
    (name, seed); seed 0 if not given) for targets ``names``; None at 'perfect' (or None)."""
    from ship_guidance.sensed_targets import SensedTargets
    from ship_guidance.sensor_levels import level
    name, seed = (sensing, 0) if isinstance(sensing, str) else (sensing or ('perfect', 0))
    chosen = level(name)
    return None if chosen.perfect else SensedTargets(chosen, names, seed)


def land_mask(chart, clearance_m):
    """The LandMask colav_node builds from a chart's occupancy grid: the chart's land cells (its
    cell [i, j] has its centre at north0 + i res, east0 + j res; a LandMask row starts at its
    lower edge) widened by ``clearance_m``."""
    from ship_guidance.land_mask import LandMask
    r = float(chart.resolution_m)
    return LandMask(~chart.water, chart.north0 - 0.5 * r, chart.east0 - 0.5 * r, r,
                    clearance_m=clearance_m)


def run_scenario(path, progress=None, end=None, behaviours=None, sensing=None, land=None):
    """RunResult of the scenario's first vessel (see the module docstring); with ``end`` (a
    RunEnd) the run stops at the first sample where ``end.done``, else after the scenario's
    duration (end 'limit' with ``end``, 'duration' without); ``behaviours``: {target name:
    behaviour} (ship_guidance.reacting_traffic; absent or all straight: light targets as
    given, the same numbers as without). ``sensing`` (``sensed_targets``): colav decides on
    the targets a sensor level's sensors and tracker give it, fed the true states at every
    step (ship_guidance.sensed_targets); the tracks recorded, the end of the run and the
    scoring stay the true ones. None or 'perfect': the true states. ``land``: a chart raster
    in the case's frame whose land colav's grounding cost sees (module docstring); None: none."""
    import time

    from benchmarks.closed_loop_inprocess import build_vessel
    from ship_mission.scenario import load_scenario

    from ship_autopilot.steering import HeadingSteering
    from ship_guidance import colav_io
    from ship_sim.frames import psi_to_yaw, yaw_to_psi
    from ship_sim.light_traffic import make_traffic
    from ship_sim.speed_factor import scaled_shaft
    from ship_sim.ros.conversions import make_odometry, odometry_to_ned

    scenario = load_scenario(path)
    spec = scenario.vessels[0]
    sim, guidance, controller, dt = build_vessel(scenario, spec)
    steer = HeadingSteering(controller)
    colav, schedule = None, None
    if spec.colav_params is not None:
        colav, period = build_colav(spec.colav_params, bool(sim.model.has_shaft))
        schedule = colav_io.DecisionSchedule(period)
        if land is not None:
            colav.land = land_mask(land, colav.params.grounding_clearance_m)
    # vessel_node with speed_factor_input: the shaft at factor x its command, which stays at the
    # trim's shaft speed (no node publishes shaft_cmd); None without a shaft (the Mariner).
    shaft_cmd = sim.shaft_command
    traffic = make_traffic(scenario.light) if scenario.light else None
    reacting = traffic is not None and any(b != 'straight' for b in (behaviours or {}).values())
    if reacting:
        from ship_guidance.reacting_traffic import ReactingTraffic
        if colav is None:
            raise ValueError('reacting targets need an own ship with colav (their model and method)')
        traffic = ReactingTraffic(
            traffic, behaviours, colav.ship, decision_period_s=period,
            colav_factory=lambda: build_colav(spec.colav_params, bool(sim.model.has_shaft))[0],
            lookahead_m=float(spec.guidance_params.get('lookahead_m', GUIDANCE['lookahead_m'])))
    names = sorted(traffic.names) if traffic else []
    sensed = sensed_targets(sensing, names) if colav is not None else None
    order = [traffic.names.index(n) for n in names] if traffic else []
    steps = int(round(scenario.duration_s / dt)) + 1
    t_out = np.empty(steps)
    own = np.empty((steps, 4))
    heading = np.empty(steps)
    tgt = {n: np.empty((steps, 4)) for n in names}
    decisions, decision = [], None
    t_prev, wall = None, 0.0
    reason = 'duration' if end is None else 'limit'
    child = f'{spec.namespace}/base_link'
    for k in range(steps):
        o = odometry_to_ned(make_odometry(*sim.nav_state(), child))
        state = colav_io.ship_state(o.north, o.east, o.psi, o.u, o.v, o.r)
        t_out[k] = o.t
        own[k] = state.north, state.east, state.course, state.speed
        heading[k] = o.psi
        dt_g = 0.0 if t_prev is None else o.t - t_prev
        out = guidance.update(o.north, o.east, o.psi, max(dt_g, 0.0), t=o.t)
        t_prev = o.t
        ref = float(psi_to_yaw(out.heading_cmd))
        cmd = ref
        if traffic is not None:
            t_ns = colav_io.to_ns(o.t)
            north, east, course, speed = traffic.state(t_ns / colav_io.NS_PER_S)
            targets = []
            for n, i in zip(names, order):
                m = odometry_to_ned(make_odometry(t_ns / colav_io.NS_PER_S, north[i], east[i],
                                                  course[i], speed[i], 0.0, 0.0, n))
                tg = colav_io.target_state(n, m.north, m.east, m.psi, m.u, m.v)
                targets.append(tg)
                tgt[n][k] = tg.north, tg.east, tg.course, tg.speed
            if colav is not None:
                if sensed is not None:
                    sensed.observe(o.t, state.north, state.east, targets)
                if schedule.due(t_ns):
                    schedule.decided(t_ns)
                    seen = targets if sensed is None else sensed.targets(o.t, targets)
                    c0 = time.perf_counter()
                    decision = colav.decide(o.t, state, seen, float(yaw_to_psi(ref)), 1.0)
                    wall += time.perf_counter() - c0
                    decisions.append((o.t, decision.mode, decision.course_offset,
                                      decision.speed_multiplier))
                cmd = colav_io.command_yaw(ref, decision)
            if end is not None and targets and end.done(o.t, state, targets):
                steps, reason = k + 1, 'clear'
                break
            if reacting and k + 1 < steps:
                traffic.step(t_ns / colav_io.NS_PER_S, state, dt)
        rudder = steer.update(o.t, o.psi, o.r, steer.decode(cmd))
        if progress is not None and k % 5000 == 0:
            progress(k, steps)
        if k + 1 < steps:
            sim.step(rudder, scaled_shaft(shaft_cmd, colav_io.speed_factor(1.0, decision)))
    return RunResult(t_out[:steps], own[:steps], {n: v[:steps] for n, v in tgt.items()},
                     decisions, heading[:steps], wall, reason,
                     None if sensed is None else sensed.stats())
