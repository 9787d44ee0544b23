"""Platoon scenarios: the `platoon:` section of a scenario file, its checks, and the node parameters
that tie a string of vessels together.

Source of the law: Angelopoulos 2011 ("String stability of multiple surface marine vessels",
NPS thesis), Sec. II.E.2, Figure 8, eqs. 31-41: the leader follows the route with LOS, every other
vessel steers at its predecessor (ship_guidance.follower, follower_node). Units SI; angles in
degrees only in the *_deg keys.

    platoon:
      route: routes/platoon_curve.yaml   # one route for the whole string (relative to the file)
      spacing_m: 400.0                   # default set gap of every follower (m, > 0)
      current: {speed_mps: 0.5, direction_deg: 90.0}   # default current of every vessel
      waves: {hs_m: 3.0, direction_deg: 45.0}          # default waves of every vessel
      stability_margin: 1.5              # look-aheads must exceed margin x U / (2 zeta omega_n)
      allow_unstable: false              # true: skip that refusal (and tell the nodes so)
      predecessor_wait_s: 2.0            # lockstep: longest wall wait of a first follower for
                                         # its predecessor's sample; k x that at depth k
                                         # (default lockstep_timeout_s / (2 x deepest depth))
      vessels:                           # a list, leader first
        - namespace: vessel_0            # required, unique
          model: mariner
          start: {along_m: 1600.0, cross_m: 0.0}  # relative to the route, or {x_m, y_m, yaw_deg}
          speed_mps: 7.7175              # optional, as for single vessels
          current: {...}                 # optional, replaces the platoon's current
          waves: {...}                   # optional, replaces the platoon's waves
          vessel: {...}                  # vessel_node parameters, verbatim
          guidance: {law: ilos, lookahead_m: 250.0}   # leader: guidance_node parameters
          autopilot: {controller: pd, omega_n: 0.12}  # autopilot_node parameters
        - namespace: vessel_1
          model: tanker
          predecessor: vessel_0          # default: the previous vessel in the list; null: a
                                         # leader of its own (it follows the route)
          spacing_m: 500.0               # default: platoon.spacing_m
          guidance: {min_lookahead_m: 400.0, lookahead_m: 400.0}  # follower_node parameters

A vessel with a predecessor is a follower: it runs follower_node instead of guidance_node, and its
`guidance` block holds follower_node parameters (look-aheads min_lookahead_m, max_lookahead_m,
the fallback LOS lookahead_m, predecessor_timeout_s, spacing gains, shaft control, ...). The
launcher sets predecessor_odom_topic (/<predecessor>/odom), spacing_m and stepping_mode itself,
so the block must not. Repeated blocks are best shared with YAML anchors (&name / *name).

Choices:
- Route: every vessel runs its own route_node on the platoon's route file (rather than one
  shared route topic), so each namespace is a complete vessel (its own latched `route`, recorded
  with it), the per-vessel analysis and plots work unchanged, and a vessel can be started, run
  or replayed alone. The cost is one idle process per vessel.
- Lockstep: every vessel_node steps on its own rudder_cmd. A follower's guidance waits (at most
  predecessor_wait_s of wall time) for the predecessor's sample at its own sim time, so the
  string stays deterministic whatever the processes' relative speed. The wait grows with the
  depth in the string (k x predecessor_wait_s for the k-th follower of a leader), so that a
  follower outwaits its predecessor, which may itself be waiting for a stalled (or dead)
  vessel ahead; the deepest wait must be shorter than the simulator's lockstep_timeout_s, or
  the simulator would give up first. Each vessel_node
  waits before step 0 for all subscribers of its odom: guidance (or follower), autopilot, the
  recorder, and the follower of every vessel that has it as predecessor (as
  ship_mission.graph counts them).
  The leaders run ahead of their followers in sim time, up to the whole run (``check_lead``:
  a follower keeps a bounded number of predecessor samples).
  The launcher starts the simulators after every other node, predecessors first, each follower's
  once its predecessor's has published step 0 (``start_order``, STEP0_LINE in its log): a
  follower's first wait can then not run out because its predecessor has not begun (under load
  DDS discovery alone can take longer than predecessor_wait_s). /clock is the first vessel's;
  the followers' nodes go by their own odometry stamps.
  A dead predecessor costs its follower one wait, then the follower runs on without waiting.
- Stability (Angelopoulos 2011 eqs. 34, 41): the string is stable iff every vessel is, so every
  look-ahead a vessel can use is checked with string_stability.check_platoon against
  U / (2 zeta omega_n) of its own autopilot design, times ``stability_margin``. The packages give
  what is checked, so the launcher and the nodes check the same: the design from
  ship_autopilot.gains.heading_loop_design (the autopilot node's own), the look-aheads and
  their limits from string_stability.los_loop / follower_loops (the follower's own: its
  min_lookahead_m, the floor of the look-ahead it takes from the gap, and its fallback
  lookahead_m; for (I)LOS the limit (U + 4 zeta^2 sigma) / (2 zeta omega_n) of
  ship_guidance.los), the defaults of keys a block leaves out from ship_guidance.node_defaults.
  The margin exists because the thesis's Nomoto-level limit is not sufficient for a real hull:
  a sampled loop with sway dynamics needs a multiple of it (scripts/platoon_time_domain.py
  measures it).
- Amplification: stable is not enough; cross-track errors grow from vessel to vessel unless the
  follower's look-ahead at its set gap, clip(spacing, min, max), is at least the
  no-amplification look-ahead 4 zeta U / omega_n (ship_guidance.follower, zeta >= 1/sqrt 2).
  Below margin x that, the launcher warns (it does not refuse: a close string can be wanted).
"""
from dataclasses import dataclass, field

from ship_mission.fields import ScenarioError, need, number, unknown
from ship_mission.vessel_spec import parse_vessel
from ship_sim.safe_load import ros_name_problem

PLATOON_KEYS = {'route', 'spacing_m', 'current', 'stability_margin', 'allow_unstable',
                'predecessor_wait_s', 'vessels', 'waves'}
VESSEL_KEYS = {'namespace', 'model', 'predecessor', 'spacing_m', 'start', 'speed_mps', 'current',
               'vessel', 'guidance', 'autopilot', 'waves', 'wind'}
#: follower_node parameters the launcher sets from the platoon (a scenario must not).
LAUNCHER_FOLLOWER_KEYS = {'predecessor_odom_topic': 'predecessor',
                          'spacing_m': 'spacing_m', 'stepping_mode': 'the scenario\'s stepping'}
#: Default deepest predecessor wait as a fraction of lockstep_timeout_s.
WAIT_FRACTION = 0.5
#: vessel_node's log line when it publishes its first lockstep step.
STEP0_LINE = 'lockstep: publishing step 0'


@dataclass
class Platoon:
    """The string's structure and settings (vessel specs are in Scenario.vessels)."""
    route_file: object
    spacing_m: float
    stability_margin: float
    allow_unstable: bool
    predecessor_wait_s: float                # of a first follower; k x that at depth k
    predecessors: dict                       # namespace -> predecessor namespace or None
    warnings: list = field(default_factory=list)
    loops: dict = field(default_factory=dict)  # namespace -> SteeringDesign (check_stability)

    def followers_of(self, namespace):
        """Namespaces of the vessels that steer at ``namespace``."""
        return [ns for ns, p in self.predecessors.items() if p == namespace]

    def depth(self, namespace):
        """0 for a leader, k for the k-th vessel behind one."""
        k = 0
        while self.predecessors[namespace] is not None:
            namespace = self.predecessors[namespace]
            k += 1
        return k

    def wait_s(self, namespace):
        """The lockstep wait (wall s) of a follower for its predecessor's sample."""
        return self.depth(namespace) * self.predecessor_wait_s


def start_order(platoon):
    """The namespaces with every predecessor before its followers (else in list order)."""
    order, placed = [], set()
    while len(order) < len(platoon.predecessors):
        for ns, pred in platoon.predecessors.items():
            if ns not in placed and (pred is None or pred in placed):
                order.append(ns)
                placed.add(ns)
    return order


@dataclass(frozen=True)
class SteeringDesign:
    """A vessel's heading loop as the checks see it: autopilot design zeta, omega_n (rad/s),
    speed U (m/s), and where the design came from."""
    zeta: float
    omega_n: float
    speed: float
    source: str


def parse_platoon(section, path, lockstep_timeout_s):
    """Check the `platoon:` section of scenario file ``path`` -> (Platoon, [VesselSpec]).

    Everything that needs no package: keys, namespaces (unique), predecessors (existing, no
    cycle), spacings, the route file's existence, the lockstep wait. ScenarioError names the
    file, the key and the vessel."""
    need(isinstance(section, dict), path, 'platoon', 'a mapping (route, vessels, ...)')
    unknown(section, PLATOON_KEYS, path, 'platoon.')
    need(isinstance(section.get('route'), str), path, 'platoon.route', 'a route file')
    route = (path.parent / section['route']).resolve()
    need(route.exists(), path, 'platoon.route', f'{route} does not exist')
    spacing = section.get('spacing_m')
    if spacing is not None:
        spacing = number(section, 'spacing_m', path, None, lo=1e-3, hi=1e6, where='platoon.')
    margin = number(section, 'stability_margin', path, 1.0, lo=1.0, hi=100.0, where='platoon.')
    allow = section.get('allow_unstable', False)
    need(isinstance(allow, bool), path, 'platoon.allow_unstable', f'true or false, got {allow!r}')
    current = section.get('current', {}) or {}
    need(isinstance(current, dict), path, 'platoon.current', 'a mapping')
    waves = section.get('waves', {}) or {}
    need(isinstance(waves, dict), path, 'platoon.waves', 'a mapping')
    vessels = section.get('vessels')
    need(isinstance(vessels, list) and vessels, path, 'platoon.vessels',
          'a list of vessels, leader first')

    names, where_of = [], {}
    for i, v in enumerate(vessels):
        where = f'platoon.vessels[{i}]'
        need(isinstance(v, dict), path, where, 'a mapping with namespace, model, ...')
        ns = v.get('namespace')
        need(not ros_name_problem(ns), path, where + '.namespace', f'{ros_name_problem(ns)}')
        if ns in where_of:
            raise ScenarioError(f'{path}: {where}.namespace: {ns} is already the namespace of '
                                f'{where_of[ns]}: two vessels in one namespace')
        where_of[ns] = where
        names.append(ns)

    predecessors, specs = {}, []
    for i, (ns, v) in enumerate(zip(names, vessels)):
        where = f'platoon.vessels[{i}] ({ns}).'
        extra = sorted(set(v) - VESSEL_KEYS)
        if 'route' in extra:
            raise ScenarioError(f'{path}: {where}route: the vessels of a platoon share '
                                'platoon.route')
        unknown(v, VESSEL_KEYS, path, where)
        pred = v['predecessor'] if 'predecessor' in v else (names[i - 1] if i else None)
        if pred is not None:
            need(isinstance(pred, str) and pred in where_of, path, where + 'predecessor',
                  f'no vessel {pred!r} in the platoon (namespaces: {", ".join(names)})')
            need(pred != ns, path, where + 'predecessor', f'{ns} cannot follow itself')
        predecessors[ns] = pred
        spec = parse_vessel(ns, {**v, 'current': v.get('current', current),
                                 'waves': v.get('waves', waves)}, route, path, where)
        if pred is None:
            need('spacing_m' not in v, path, where + 'spacing_m',
                  'only a follower (a vessel with a predecessor) keeps a spacing')
        else:
            gap = v.get('spacing_m', spacing)
            need(gap is not None, path, where + 'spacing_m',
                  'a follower needs a spacing: give it here or as platoon.spacing_m')
            spec.spacing = number({'spacing_m': gap}, 'spacing_m', path, None, lo=1e-3,
                                   hi=1e6, where=where)
            spec.predecessor = pred
            for key, instead in LAUNCHER_FOLLOWER_KEYS.items():
                need(key not in spec.guidance_params, path, f'{where}guidance.{key}',
                      f'set by the launcher (from {instead}); remove it here')
        specs.append(spec)

    for ns in names:   # every chain of predecessors must end at a leader
        chain = [ns]
        while predecessors[chain[-1]] is not None:
            nxt = predecessors[chain[-1]]
            if nxt in chain:
                loop = chain[chain.index(nxt):] + [nxt]
                raise ScenarioError(
                    f'{path}: {where_of[ns]} ({ns}).predecessor: the predecessors form a cycle '
                    f'{" -> ".join(loop)}; a string needs a leader (predecessor: null)')
            chain.append(nxt)
    platoon = Platoon(route, spacing, margin, allow, 0.0, predecessors)
    deepest = max(platoon.depth(ns) for ns in names)
    platoon.predecessor_wait_s = number(
        section, 'predecessor_wait_s', path,
        WAIT_FRACTION * lockstep_timeout_s / max(deepest, 1), lo=0.0, where='platoon.')
    need(deepest * platoon.predecessor_wait_s < lockstep_timeout_s, path,
          'platoon.predecessor_wait_s',
          f'{deepest} x {platoon.predecessor_wait_s:g} s (the wait of the deepest follower) must '
          f'be below lockstep_timeout_s ({lockstep_timeout_s:g} s): a simulator must not give '
          'up on a step while its guidance still waits for the predecessor')
    return platoon, specs


# ---------------------------------------------------------------- checks that need the packages

def autopilot_design(model, autopilot_params):
    """(zeta, omega_n in rad/s, source) of the heading loop autopilot_node builds from this block:
    ship_autopilot.gains.heading_loop_design, the function the node calls."""
    from ship_autopilot.gains import heading_loop_design
    keys = ('controller', 'k1', 'k2', 'omega_n', 'zeta')
    design = heading_loop_design(model, **{k: autopilot_params[k] for k in keys
                                           if k in autopilot_params})
    if design.zeta is None:
        raise ValueError(f'k1 = {autopilot_params["k1"]}, k2 = {autopilot_params["k2"]} give no '
                         f'oscillatory design for {model}')
    return design.zeta, design.omega_n, design.source


def vessel_speed(spec):
    """Speed (m/s) of the stability check: speed_mps, else the vessel block's
    nominal_speed_mps (U0 before), else the model's straight-running trim."""
    from ship_sim.schema import VESSEL_NODE
    if spec.speed:
        return float(spec.speed)
    nominal = VESSEL_NODE.current_names(spec.vessel_params).get('nominal_speed_mps')
    if nominal:
        return float(nominal)
    from ship_sim.models import make_model
    m = make_model(spec.model)
    return float(m.surge_speed(m.initial_state()))


def _lookahead_loops(spec, design):
    """[(parameter name, LookaheadLoop)] of every look-ahead a vessel can steer with, as its
    node checks them (string_stability.los_loop, follower_loops)."""
    from ship_guidance.node_defaults import FOLLOWER_DEFAULTS, GUIDANCE_DEFAULTS
    from ship_guidance.string_stability import follower_loops, los_loop
    g, ns = spec.guidance_params, spec.namespace
    z, w, u = design.zeta, design.omega_n, design.speed
    if spec.predecessor is None:
        law = g.get('law', GUIDANCE_DEFAULTS['law'])
        if law not in ('los', 'ilos'):
            return []   # the course law steers by schedule, not by look-ahead
        if g.get('lookahead_ship_lengths'):
            if not g.get('ship_length_m'):
                raise ValueError('lookahead_ship_lengths needs ship_length_m')
            name = 'lookahead_ship_lengths'
            d = float(g['lookahead_ship_lengths']) * float(g['ship_length_m'])
        else:
            name, d = 'lookahead_m', float(g.get('lookahead_m', GUIDANCE_DEFAULTS['lookahead_m']))
        sigma = (float(g.get('integral_gain', GUIDANCE_DEFAULTS['integral_gain']))
                 if law == 'ilos' else 0.0)
        return [(name, los_loop(z, w, u, d, sigma, ns))]
    f = {**FOLLOWER_DEFAULTS, **g}
    loops = follower_loops(z, w, u, float(f['min_lookahead_m']), float(f['lookahead_m']),
                           float(f['integral_gain']), names=(ns, ns))
    return list(zip(('min_lookahead_m', 'lookahead_m'), loops))


def follow_lookahead(spec):
    """The look-ahead a follower steers with at its set gap: clip(spacing, min, max) (m)."""
    from ship_guidance.node_defaults import FOLLOWER_DEFAULTS
    g = spec.guidance_params
    d = max(spec.spacing, float(g.get('min_lookahead_m', FOLLOWER_DEFAULTS['min_lookahead_m'])))
    cap = float(g.get('max_lookahead_m', FOLLOWER_DEFAULTS['max_lookahead_m']))
    return min(d, cap) if cap > 0.0 else d


def check_stability(scenario):
    """Refuse look-aheads below the stability limit (unless allow_unstable); warn about
    spacings that amplify errors down the string. Fills ``platoon.loops`` and
    ``platoon.warnings``; returns the warnings. ScenarioError names the vessel and the key."""
    from ship_guidance.follower import no_amplification_spacing
    from ship_guidance.string_stability import check_platoon
    platoon = scenario.platoon
    file = scenario.file
    index = {spec.namespace: i for i, spec in enumerate(scenario.vessels)}
    loops, entries = {}, []
    for spec in scenario.vessels:
        where = f'{file}: platoon.vessels[{index[spec.namespace]}] ({spec.namespace}).'
        try:
            zeta, omega_n, source = autopilot_design(spec.model, spec.autopilot_params)
            design = SteeringDesign(zeta, omega_n, vessel_speed(spec), source)
            checks = _lookahead_loops(spec, design)
        except (ValueError, KeyError, OSError) as exc:
            raise ScenarioError(f'{where}autopilot: cannot tell the steering design: '
                                f'{exc}') from None
        loops[spec.namespace] = design
        entries += [(spec, key, loop) for key, loop in checks]
    platoon.loops = loops
    results = check_platoon([e[2] for e in entries], margin=platoon.stability_margin)
    for (spec, key, _), res in zip(entries, results):
        unchecked = platoon.allow_unstable or spec.guidance_params.get('allow_unstable')
        if not res.ok and not unchecked:
            design = loops[spec.namespace]
            raise ScenarioError(
                f'{file}: platoon.vessels[{index[spec.namespace]}] ({spec.namespace}).guidance.'
                f'{key}: look-ahead {res.lookahead:.1f} m is not above {platoon.stability_margin:g}'
                f' x the stability limit {res.critical:.1f} m (ratio {res.ratio:.2f}; zeta '
                f'{design.zeta:.3g}, omega_n {design.omega_n:.4g} rad/s from the '
                f'{design.source}, U {design.speed:.4g} m/s; Angelopoulos 2011 eqs. 34, 41). '
                'Increase it or set platoon.allow_unstable: true')
    warnings = []
    for spec in scenario.vessels:
        if spec.predecessor is None:
            continue
        design = loops[spec.namespace]
        d_need = platoon.stability_margin * no_amplification_spacing(design.zeta, design.omega_n,
                                                                     design.speed)
        d = follow_lookahead(spec)
        if d < d_need:
            warnings.append(
                f'{spec.namespace}: look-ahead at the set gap {d:.1f} m is below '
                f'{platoon.stability_margin:g} x 4 zeta U / omega_n = {d_need:.1f} m: cross-track '
                f'errors can grow from {spec.predecessor} to {spec.namespace} before they decay')
    platoon.warnings = warnings
    return warnings


def check_lead(scenario):
    """In lockstep a leader runs ahead of its followers as fast as it can, at most the whole run
    (its simulator stops at duration_s); a follower keeps ship_guidance.follower's
    TRACK_MAX_SAMPLES predecessor samples, so a longer run could lose the ones it still needs.
    ScenarioError if the run has more steps than that."""
    from ship_guidance.follower import TRACK_MAX_SAMPLES
    steps = int(round(scenario.duration_s / scenario.dt_s)) + 1
    if scenario.stepping == 'lockstep' and steps > TRACK_MAX_SAMPLES:
        raise ScenarioError(
            f'{scenario.file}: duration_s: {steps} steps of {scenario.dt_s:g} s is more than the '
            f'{TRACK_MAX_SAMPLES} predecessor samples a follower keeps; in lockstep a predecessor '
            'can run that far ahead of its follower. Shorten the run or lengthen dt_s')


def follower_parameters(scenario, spec):
    """follower_node parameters of follower ``spec``: the glue first, then its guidance block
    (which cannot override the glue, see parse_platoon). The autopilot design goes in for the
    node's own stability check unless the block gives it."""
    platoon = scenario.platoon
    params = {'use_sim_time': True,
              'predecessor_odom_topic': f'/{spec.predecessor}/odom',
              'spacing_m': float(spec.spacing),
              'stepping_mode': scenario.stepping,
              'predecessor_wait_s': float(platoon.wait_s(spec.namespace))}
    if platoon.allow_unstable:
        params['allow_unstable'] = True
    design = platoon.loops.get(spec.namespace)
    if design is None:   # check_stability has not run (a caller that skipped check_scenario)
        try:
            design = SteeringDesign(*autopilot_design(spec.model, spec.autopilot_params)[:2],
                                  vessel_speed(spec), '')
        except (ValueError, KeyError, OSError):
            design = None   # the node then runs without its own check
    keys = ('autopilot_zeta', 'autopilot_omega_n', 'speed')
    if design is not None and not any(k in spec.guidance_params for k in keys):
        params.update(autopilot_zeta=design.zeta, autopilot_omega_n=design.omega_n,
                      speed=design.speed)
    params.update(spec.guidance_params)
    return params
