"""Guidance parameters tuned by the genetic algorithm (Lee 2004, Ch. 4), in process.

Lee 2004 derives the straight-line guidance as a function of the ship's speed and its
perpendicular position error, and regulates the guidance parameters with its genetic
algorithm: under a position-tracking cost in coastal navigation with an unknown current
(0.75 m/s), under a propulsive-energy cost in oceanic navigation, on a linear ship
(Nomoto's first-order model, Table 4.1: the Mariner class, K = 0.185 1/s, T = 107.3 s), and
compares the result against conventional guidance (a constant look-ahead). The OCR keeps the
idea, the current, the ship and the GA's settings but not the law's formula or the costs, so
both are ours:

- Look-ahead law (``LookaheadLaw``): a look-ahead TIME that shrinks with the cross-track
  error, scaled by the speed through the water U,
      d(U, e) = U (t_min + (t_max - t_min) exp(-(e / e_s)^2)),
  long on the path (smooth, little rudder), short far from it (returns quickly); the form of
  Lekkas and Fossen's time-varying look-ahead, with the speed factor Lee 2004 asks for. It is
  stable with the paired PD (Angelopoulos 2011 eq. 34, ship_guidance.los.critical_lookahead)
  at every error iff min(t_min, t_max) > 1 / (2 zeta omega_n): the GA's box keeps both times
  above that, with a margin.
- Coastal cost: RMS cross-track error (m) + ``rudder_weight_m_per_deg`` x RMS rudder (deg),
  over the run from the start to route completion.
- Oceanic (energy) cost: a propulsive-energy proxy, the distance sailed through the water
  times (1 + c delta^2) averaged over the run (c = ``drag_per_rad2``, the rudder's induced
  drag relative to the hull's), divided by the route length; plus a penalty when the
  cross-track error exceeds ``max_cross_track_m`` (the route must still be followed).

The closed loop is the one the nodes run (ship_sim VesselSimulator -> ship_guidance Guidance
(law 'los') -> ship_autopilot PD with the model's rudder limits), stepping in process; the law
sets the guidance's look-ahead each step from the previous cross-track error. The GA is the
route planner's (ship_planner.ga is not importable from here by the dependency order, so the
caller passes its ``minimize_box``). Units SI, angles rad, NED.
"""
import math
from dataclasses import dataclass, field

import numpy as np

from ship_guidance.guidance import Guidance
from ship_guidance.los import critical_lookahead
from ship_sim.current import OceanCurrent
from ship_sim.simulator import VesselSimulator

from .gains import build_autopilot

COST_KINDS = ('coastal', 'oceanic')
STABILITY_MARGIN = 1.1        # GA box: look-ahead times >= this x the critical time


@dataclass(frozen=True)
class LookaheadLaw:
    """d(U, e) = U (t_min + (t_max - t_min) exp(-(e / e_scale)^2)); times s, e_scale m."""
    t_min: float
    t_max: float
    e_scale: float

    def __call__(self, speed, cross_track):
        w = math.exp(-(cross_track / self.e_scale) ** 2)
        return speed * (self.t_min + (self.t_max - self.t_min) * w)

    def minimum(self, speed):
        """The smallest look-ahead (m) the law gives at this speed, over all errors."""
        return speed * min(self.t_min, self.t_max)


@dataclass(frozen=True)
class ConstantLookahead:
    """Conventional guidance: d = lookahead_m whatever the speed and error."""
    lookahead_m: float

    def __call__(self, speed, cross_track):
        return self.lookahead_m

    def minimum(self, speed):
        return self.lookahead_m


@dataclass
class Case:
    """One tuning case: a route followed from a start offset, in a current, with a cost.

    route: ship_guidance.path.Route (NED); model: a ship_sim model (constant-speed, e.g.
    nomoto1); pd: {'k1', 'k2'} gains and their design zeta, omega_n (rad/s); cost: 'coastal' |
    'oceanic'; current speed (m/s) and direction (rad, flowing towards); start_cross_m: start
    offset to starboard of the route (m); dt (s); t_max (s, cap if the route is not finished).
    """
    name: str
    route: object
    model: object
    pd: dict
    zeta: float
    omega_n: float
    cost: str = 'coastal'
    current_speed: float = 0.0
    current_direction: float = 0.0
    start_cross_m: float = 0.0
    dt: float = 1.0
    t_max: float = 4000.0
    rudder_weight_m_per_deg: float = 1.0
    drag_per_rad2: float = 1.0
    max_cross_track_m: float = 500.0
    extras: dict = field(default_factory=dict)

    def __post_init__(self):
        if self.cost not in COST_KINDS:
            raise ValueError(f'cost must be one of {COST_KINDS}, got {self.cost!r}')

    @property
    def speed(self):
        return float(self.model.U)

    def critical_time(self):
        """Look-ahead time (s) at the stability limit: 1 / (2 zeta omega_n)."""
        return critical_lookahead(self.zeta, self.omega_n, self.speed) / self.speed


def simulate(case, law):
    """Run the closed loop with a look-ahead law. Returns a dict of arrays (t, north, east,
    cross_track, rudder, lookahead) and scalars (finished, distance_water_m)."""
    route = case.route
    alpha = float(route.start_angles[0])
    n0, e0 = route.legs[0].start.tolist()
    # start offset to starboard of the first leg, heading along it
    north = n0 - case.start_cross_m * math.sin(alpha)
    east = e0 + case.start_cross_m * math.cos(alpha)
    current = (OceanCurrent(case.current_speed, case.current_direction)
               if case.current_speed > 0.0 else None)
    sim = VesselSimulator(case.model, dt=case.dt, north=north, east=east, psi=alpha,
                          current=current)
    u = case.speed
    guidance = Guidance(route, law='los', lookahead=law(u, 0.0), allow_unstable=True)
    guidance.reset(s=0.0)
    m = case.model
    autopilot = build_autopilot('pd', case.pd, m.rudder_max, m.rudder_rate_max)
    n_steps = int(math.ceil(case.t_max / case.dt))
    out = np.empty((n_steps, 6))
    e_prev, finished, k = case.start_cross_m, False, 0
    for k in range(n_steps):
        t, n, e, psi, _u, _v, r = sim.nav_state()
        guidance.lookahead = law(u, e_prev)
        g = guidance.update(n, e, psi, case.dt if k else 0.0)
        delta = autopilot.update(psi, r, g.heading_cmd, case.dt)
        out[k] = (t, n, e, g.cross_track, sim.rudder(), guidance.lookahead)
        e_prev = g.cross_track
        if g.finished:
            finished = True
            break
        sim.step(delta)
    out = out[:k + 1]
    return {'t': out[:, 0], 'north': out[:, 1], 'east': out[:, 2], 'cross_track': out[:, 3],
            'rudder': out[:, 4], 'lookahead': out[:, 5], 'finished': finished,
            'distance_water_m': u * float(out[-1, 0] - out[0, 0])}


def metrics(case, run):
    """Cross-track, rudder use and the energy proxy of a run (SI; rudder also in deg)."""
    e, d = run['cross_track'], run['rudder']
    dd = np.diff(d) / case.dt if len(d) > 1 else np.zeros(1)
    mean_d2 = float(np.mean(d ** 2))
    return {'finished': bool(run['finished']), 'time_s': float(run['t'][-1] - run['t'][0]),
            'xte_rms_m': float(np.sqrt(np.mean(e ** 2))), 'xte_max_abs_m': float(np.max(np.abs(e))),
            'rudder_rms_deg': math.degrees(math.sqrt(mean_d2)),
            'rudder_rate_mean_abs_deg_s': math.degrees(float(np.mean(np.abs(dd)))),
            'distance_water_m': run['distance_water_m'],
            'energy_proxy': run['distance_water_m'] * (1.0 + case.drag_per_rad2 * mean_d2)
            / float(case.route.length),
            'lookahead_min_m': float(np.min(run['lookahead']))}


def cost(case, law):
    """The case's cost of a law (lower is better); an unfinished route costs extra."""
    mt = metrics(case, simulate(case, law))
    if case.cost == 'coastal':
        j = mt['xte_rms_m'] + case.rudder_weight_m_per_deg * mt['rudder_rms_deg']
    else:
        j = mt['energy_proxy'] + max(0.0, mt['xte_max_abs_m'] / case.max_cross_track_m - 1.0)
    return j if mt['finished'] else j + 1e3


def gene_box(case, t_hi=None, e_hi=None):
    """(lower, upper) of the genes (t_min s, t_max s, e_scale m): both times from
    STABILITY_MARGIN x the critical time up to t_hi (default 10x it), e_scale 10 m to e_hi
    (default 1000 m)."""
    tc = STABILITY_MARGIN * case.critical_time()
    t_hi = 10.0 * case.critical_time() if t_hi is None else float(t_hi)
    e_hi = 1000.0 if e_hi is None else float(e_hi)
    return np.array([tc, tc, 10.0]), np.array([t_hi, t_hi, e_hi])


def tune(case, minimize_box, *, population=30, generations=30, seed=0, progress=None, **ga):
    """Tune the look-ahead law for a case with a box-bounded real-coded GA.

    minimize_box(cost, lower, upper, population=, generations=, seed=, progress=, ...) is the
    planner's GA (ship_planner.ga.minimize_box). progress(generation, best) is called every
    generation. Returns (LookaheadLaw, GAResult)."""
    lower, upper = gene_box(case)

    def batch_cost(genes):
        return np.array([cost(case, LookaheadLaw(*g)) for g in genes])

    res = minimize_box(batch_cost, lower, upper, population=population, generations=generations,
                       seed=seed, progress=progress, progress_every=1,
                       stall_generations=generations + 1, **ga)
    return LookaheadLaw(*(float(v) for v in res.x)), res
