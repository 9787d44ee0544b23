"""COLREGs encounter situation of each target, seen from the own ship (pure, vectorised).

Relative bearings run clockwise from the bow, in [0, 360) deg. The tests, in this order (the
thresholds of the project's Imazu reference set; Rules 13-17 of COLREGs 1972):

1. opening (TCPA <= 0): ``none``, nothing to do;
2. ``overtaking`` (Rule 13, own ship gives way): the own ship lies in the target's stern sector,
   more than 22.5 deg abaft its beam: the bearing of the own ship from the target, relative to the
   target's heading, strictly between 112.5 and 247.5 deg;
3. ``being-overtaken`` (Rule 13 seen from the other ship, own ship stands on): the target lies in
   the own ship's stern sector, strictly between 112.5 and 247.5 deg;
4. ``head-on`` (Rule 14, both give way to starboard): the target within +-6 deg of the own bow
   and the own ship within +-6 deg of the target's bow (nearly reciprocal courses);
5. otherwise crossing (Rule 15): ``crossing-give-way`` when the target bears [0, 180) deg (on
   the own starboard side), ``crossing-stand-on`` when it bears [180, 360) (Rule 17).

Rule 13's "more than 22.5 degrees abaft her beam" makes the stern sector open; Rule 14's
"ahead or nearly ahead" is taken as the closed +-6 deg sector. ``role`` maps a situation to what
the own ship must do: give way in overtaking, head-on and crossing-give-way, stand on in
being-overtaken and crossing-stand-on.
"""
import numpy as np

from ship_guidance.cpa import cpa, range_and_bearing

NONE, OVERTAKING, BEING_OVERTAKEN, HEAD_ON, CROSSING_GIVE_WAY, CROSSING_STAND_ON = range(6)
#: Situation names by code (the codes index this tuple).
SITUATIONS = ('none', 'overtaking', 'being-overtaken', 'head-on', 'crossing-give-way',
              'crossing-stand-on')
GIVE_WAY, STAND_ON = 'give-way', 'stand-on'
ROLES = {NONE: 'none', OVERTAKING: GIVE_WAY, BEING_OVERTAKEN: STAND_ON, HEAD_ON: GIVE_WAY,
         CROSSING_GIVE_WAY: GIVE_WAY, CROSSING_STAND_ON: STAND_ON}

STERN_SECTOR_DEG = (112.5, 247.5)   # more than 22.5 deg abaft the beam (Rule 13)
HEAD_ON_HALF_SECTOR_DEG = 6.0       # "ahead or nearly ahead" (Rule 14)

_TWO_PI = 2.0 * np.pi


def relative_bearing(p_from, heading_from, p_to):
    """Bearing (rad, [0, 2 pi), clockwise from the bow) of ``p_to`` seen from a ship at ``p_from``
    with ``heading_from`` (rad, clockwise from north)."""
    _, bearing = range_and_bearing(p_from, p_to)
    return np.mod(bearing - np.asarray(heading_from, dtype=float), _TWO_PI)


def _in_stern_sector(beta):
    lo, hi = np.radians(STERN_SECTOR_DEG)
    return (beta > lo) & (beta < hi)


def _ahead(beta):
    half = np.radians(HEAD_ON_HALF_SECTOR_DEG)
    return (beta <= half) | (beta >= _TWO_PI - half)


def classify(p_own, heading_own, v_own, p_target, heading_target, v_target):
    """Situation codes (int array, index into SITUATIONS) of targets seen from the own ship.

    Positions (..., 2) NED m; headings rad clockwise from north (the bow's direction, which
    fixes the sectors); velocities (..., 2) NED m/s (over ground; they give TCPA)."""
    tcpa, _ = cpa(p_own, v_own, p_target, v_target)
    beta = relative_bearing(p_own, heading_own, p_target)            # target from own bow
    beta_t = relative_bearing(p_target, heading_target, p_own)       # own ship from target's bow
    crossing = np.where(beta < np.pi, CROSSING_GIVE_WAY, CROSSING_STAND_ON)
    code = np.where(_ahead(beta) & _ahead(beta_t), HEAD_ON, crossing)
    code = np.where(_in_stern_sector(beta), BEING_OVERTAKEN, code)
    code = np.where(_in_stern_sector(beta_t), OVERTAKING, code)
    return np.where(tcpa > 0.0, code, NONE).astype(int)


def role(code):
    """'give-way', 'stand-on' or 'none' for one situation code."""
    return ROLES[int(code)]
