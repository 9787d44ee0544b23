"""Plausibility gate of incoming odometry (guidance_node, follower_node): one outlier sample
must not steer the guidance, nor complete its route.

A sample is refused when a number is not finite, when its position lies beyond
ship_guidance.path.MAX_COORDINATE_M from the origin, or when it jumped from the last accepted
sample farther than ``max_speed * dt + JUMP_MARGIN_M`` (dt the sim time between the two). A
sample whose time went back (a restarted simulator) starts the track again. A vessel that did
move that far (a simulator reset to another place) is followed again after CONFIRM_SAMPLES
refused samples in a row that agree with each other (``re_anchored``): the node then starts its
guidance afresh. ``consistent`` tells whether the accepted sample was checked against a
previous one: a route is completed only on such a sample, never on a first or re-anchored one.

Pure (no ROS): ``check(t, north, east, *others)`` -> None if accepted, else the reason
(``others``: the sample's other numbers, heading and velocities, which must be finite too).
"""
import math

from ..path import MAX_COORDINATE_M

#: Allowance (m) on top of max_speed * dt: position noise, and stamps rounded to the ns.
JUMP_MARGIN_M = 10.0
#: Refused samples in a row, consistent with each other, after which the track moves there.
CONFIRM_SAMPLES = 3


class OdomGate:
    """See the module docstring. ``n_refused`` counts refused samples."""

    def __init__(self, max_speed):
        if not (math.isfinite(max_speed) and max_speed > 0.0):
            raise ValueError(f'max_speed must be a finite number > 0 m/s, got {max_speed}')
        self.max_speed = float(max_speed)
        self.last = None          # (t, north, east) of the last accepted sample
        self._candidate = None    # (t, north, east, count) of refused samples agreeing
        self.n_refused = 0
        self.consistent = False
        self.re_anchored = False

    def _plausible(self, ref, t, north, east):
        dt = t - ref[0]
        return math.hypot(north - ref[1], east - ref[2]) <= self.max_speed * dt + JUMP_MARGIN_M

    def check(self, t, north, east, *others):
        """None if the sample is accepted (and becomes the reference), else why not."""
        self.consistent = self.re_anchored = False
        if not all(math.isfinite(v) for v in (t, north, east, *others)):
            return self._refuse(f'non-finite odometry (t, north, east, ...) = '
                                f'{(t, north, east, *others)}')
        if max(abs(north), abs(east)) > MAX_COORDINATE_M:
            return self._refuse(f'position ({north:.3g}, {east:.3g}) m is beyond '
                                f'{MAX_COORDINATE_M:.0e} m from the origin')
        last = self.last
        if last is None or t < last[0]:
            return self._accept(t, north, east, consistent=False)
        if self._plausible(last, t, north, east):
            return self._accept(t, north, east, consistent=True)
        reason = (f'jump of {math.hypot(north - last[1], east - last[2]):.3g} m in '
                  f'{t - last[0]:.3g} s (more than {self.max_speed:g} m/s + {JUMP_MARGIN_M:g} m)')
        c = self._candidate
        if c is not None and t >= c[0] and self._plausible(c, t, north, east):
            count = c[3] + 1
        else:
            count = 1
        if count >= CONFIRM_SAMPLES:
            self.re_anchored = True
            return self._accept(t, north, east, consistent=False)
        self._candidate = (t, north, east, count)
        return self._refuse(reason)

    def _accept(self, t, north, east, consistent):
        self.last = (t, north, east)
        self._candidate = None
        self.consistent = consistent
        return None

    def _refuse(self, reason):
        self.n_refused += 1
        return reason
