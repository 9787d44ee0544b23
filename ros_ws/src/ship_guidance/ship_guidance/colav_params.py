"""Parameters of the collision-avoidance decision (both methods), with documented defaults.

The same keys, with a comment each, are in config/colav.yaml for the node. Distances suit the
project's Imazu scale (own ship 12 kn, every ship at one point 4 NM ahead after 20 min): the safe
distance is the reference set's risk-of-collision DCPA, 0.5 NM (926 m); near miss half of it;
collision 0.1 NM, about one length of the mariner (161 m) plus margin; a threat within 1 NM.
Cost weights are dimensionless; their ordering is the design: any intrusion into d_safe (at
least ``w_collision`` times the squared relative-speed floor) outweighs every COLREGs penalty,
which outweighs every deviation.
"""
from dataclasses import dataclass, field, fields

import numpy as np


def _deg(*values):
    return tuple(float(np.deg2rad(v)) for v in values)


@dataclass(frozen=True)
class ColavParams:
    # --- distances (m) ---
    d_safe_m: float = 926.0                # safe passing distance r_min (Woerner et al. 2018)
    near_miss_m: float = 463.0             # near miss r_nm (evaluation only, not a cost)
    collision_m: float = 185.2             # collision r_col: below it in every scenario -> last resort
    threat_m: float = 1852.0               # a target is a threat if the nominal prediction comes closer
    d_close_m: float = 1852.0              # COLREGs side rules apply to passes closer than this
    # --- prediction ---
    horizon_s: float = 600.0
    dt_s: float = 5.0
    course_offsets: tuple = field(default_factory=lambda: _deg(*range(-90, 91, 15)))  # rad, + starboard
    speed_factors: tuple = (1.0, 0.5, 0.0)  # multiply the nominal speed factor; only 1 without shaft
    # --- collision risk (Johansen et al. 2016: C R with R = (1 / t^p) (d_safe / d)^q) ---
    w_collision: float = 100.0             # K_coll, per (relative speed / reference speed)^2
    relative_speed_floor: float = 0.5      # relative speed floor, fraction of the reference speed
    risk_time_exponent: float = 1.0        # p: sooner intrusions cost more
    risk_distance_exponent: float = 2.0    # q: deeper intrusions cost more
    # --- COLREGs penalties ---
    w_wrong_side: float = 10.0             # Rule 14 starboard-to-starboard / Rule 15 crossing ahead
    w_port_turn: float = 5.0               # course offset to port in head-on or crossing (14, 15, 17(c))
    # Grounding (a chart given): the first predicted step within the clearance of land costs
    # what a collision-distance intrusion costs at that time, w_collision (d_safe / r_col)^q,
    # at relative speed U: running aground is no better than a collision.
    w_grounding: float = 2500.0
    grounding_clearance_m: float = 185.2   # distance kept from land (r_col)
    w_not_apparent: float = 3.0            # give-way alteration not readily apparent (Rule 8(b))
    apparent_course_change: float = float(np.deg2rad(30.0))   # rad; or the speed below:
    apparent_speed_ratio: float = 0.5      # predicted speed at the closest point, x nominal
    # --- deviation from the nominal and change from the previous decision ---
    w_course_starboard: float = 1.0        # per rad^2 of course offset to starboard
    w_course_port: float = 2.0             # per rad^2 of course offset to port
    w_speed: float = 2.5                   # per unit of speed reduction (1 - P)
    w_change_course_starboard: float = 1.0  # per rad^2 of offset change to starboard
    w_change_course_port: float = 1.5      # per rad^2 of offset change to port
    w_change_speed: float = 2.0            # per unit of speed factor change
    # --- stand-on (Rule 17) ---
    stand_on_dcpa_m: float = 926.0         # act (17(a)(ii)) when the nominal passes closer ...
    stand_on_act_time_s: float = 300.0     # ... with the closest point this near: the give-way
    #                                        ship is late (evaluator's early_s, Rule 16)
    # --- target uncertainty (issue 31 item 3) ---
    # A target's safe distance is d_safe_m + uncertainty_k x its position sigma (the square
    # root of the largest eigenvalue of its position covariance, Target.position_sigma_m):
    # k = 2 keeps d_safe from about 95 % of the positions the target may be at along the
    # worst axis. Targets without a covariance (sigma 0) keep d_safe_m exactly.
    uncertainty_k: float = 2.0

    def __post_init__(self):
        if not 0.0 < self.collision_m < self.near_miss_m < self.d_safe_m <= self.threat_m:
            raise ValueError('need 0 < collision_m < near_miss_m < d_safe_m <= threat_m')
        if not (self.uncertainty_k >= 0.0 and np.isfinite(self.uncertainty_k)):
            raise ValueError('uncertainty_k must be a finite number >= 0')
        if not (self.dt_s > 0.0 and self.horizon_s >= self.dt_s):
            raise ValueError('need 0 < dt_s <= horizon_s')
        if 0.0 not in self.course_offsets or 1.0 not in self.speed_factors:
            raise ValueError('course_offsets must hold 0 and speed_factors 1 (the nominal command)')
        if not 0.0 <= self.apparent_speed_ratio < 1.0:
            raise ValueError('apparent_speed_ratio must lie in [0, 1)')
        if any(not 0.0 <= p <= 1.0 for p in self.speed_factors):
            raise ValueError('speed_factors must lie in [0, 1]')

    def safe_distance(self, position_sigma_m):
        """A target's safe distance (m) for its position sigma (m; arrays work too)."""
        return self.d_safe_m + self.uncertainty_k * position_sigma_m

    @classmethod
    def from_dict(cls, values):
        """From a flat mapping (e.g. the node's parameters); ``*_deg`` keys are converted."""
        names = {f.name for f in fields(cls)}
        out = {}
        for key, value in values.items():
            if key == 'course_offsets_deg':
                out['course_offsets'] = _deg(*value)
            elif key == 'apparent_course_change_deg':
                out['apparent_course_change'] = float(np.deg2rad(value))
            elif key in names:
                out[key] = tuple(value) if isinstance(value, list) else value
            else:
                raise ValueError(f'unknown collision-avoidance parameter {key!r}')
        return cls(**out)
